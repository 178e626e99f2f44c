#include "mneedle/fe/tissue_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <unordered_map>

#include "fe/tet_bisection.h"
#include "mneedle/base/error.h"
#include "mneedle/base/text.h"

namespace mneedle::fe {

namespace {

constexpr int kEdgeNodes[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};

// The tetrahedron cap bounds the work and memory of a bad override (a TET10 mesh of 4 million
// tetrahedra is about 5.5 million nodes).
constexpr std::size_t kMaxRefinedTets = 4'000'000;

[[noreturn]] void bad_spec(const std::string& field, const std::string& problem) {
  throw InputError("tissue block: " + field + ": " + problem);
}

void validate(const TissueBlockSpec& spec) {
  if (!(spec.size_x > 0.0) || !(spec.size_y > 0.0) || !std::isfinite(spec.size_x) ||
      !std::isfinite(spec.size_y))
    bad_spec("size", "block size must be positive and finite");
  if (spec.layers.empty()) bad_spec("layers", "at least one layer is required");
  for (const TissueLayer& layer : spec.layers)
    if (!(layer.thickness > 0.0) || !std::isfinite(layer.thickness))
      bad_spec("layers." + layer.name + ".thickness", "must be positive and finite");
  if (spec.order != 1 && spec.order != 2) bad_spec("order", "must be 1 or 2");
  if (!(spec.insertion_depth >= 0.0)) bad_spec("insertion_depth", "must be >= 0");
  if (!(spec.criterion_length >= 0.0) || !std::isfinite(spec.criterion_length))
    bad_spec("criterion_length", "must be >= 0 and finite");
  if (spec.overrides.refinement_levels &&
      (*spec.overrides.refinement_levels < 0 ||
       *spec.overrides.refinement_levels > kMaxRefinementLevels))
    bad_spec("overrides.refinement_levels", "must be 0 to " + std::to_string(kMaxRefinementLevels));
  if (spec.overrides.contact_zone_size_m && (!(*spec.overrides.contact_zone_size_m >= 0.0) ||
                                             !std::isfinite(*spec.overrides.contact_zone_size_m)))
    bad_spec("overrides.contact_zone_size_m", "must be positive (or 0: no zone) and finite");
  if (spec.overrides.contact_zone_reach && (!(*spec.overrides.contact_zone_reach > 0.0) ||
                                            !(*spec.overrides.contact_zone_reach <= 100.0)))
    bad_spec("overrides.contact_zone_reach", "must be in (0, 100]");
  if (spec.overrides.contact_zone_tip_size_m &&
      (!(*spec.overrides.contact_zone_tip_size_m > 0.0) ||
       !std::isfinite(*spec.overrides.contact_zone_tip_size_m)))
    bad_spec("overrides.contact_zone_tip_size_m", "must be positive and finite");
  if (!spec.overrides.contact_zone_size_m &&
      (spec.overrides.contact_zone_reach || spec.overrides.contact_zone_tip_size_m))
    bad_spec(spec.overrides.contact_zone_reach ? "overrides.contact_zone_reach"
                                               : "overrides.contact_zone_tip_size_m",
             "shapes the contact zone: give contact_zone_size_m too");
  for (const NeedleSite& site : spec.sites) {
    if (!(site.radius > 0.0)) bad_spec("needle radius", "must be positive");
    if (std::abs(site.x) >= spec.size_x / 2 || std::abs(site.y) >= spec.size_y / 2)
      bad_spec("needle position", "site lies outside the block");
  }
}

// Element size as a function of the distance from the nearest fine zone: constant inside it,
// then growing by `growth` per element (h' = (growth - 1) gives geometric grading).
double graded_size(double distance_outside, const MeshSizing& sizing) {
  const double size = sizing.fine_size + (sizing.growth - 1.0) * std::max(0.0, distance_outside);
  return std::min(size, sizing.max_size);
}

// Distance (m) from q to a convex counter-clockwise outline: 0 inside, to the point or segment
// for one or two vertices.
double distance_to_outline(const Eigen::Vector2d& q, const std::vector<Eigen::Vector2d>& outline) {
  const std::size_t n = outline.size();
  if (n == 1) return (q - outline[0]).norm();
  bool inside = n >= 3;
  double nearest = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = outline[i];
    const Eigen::Vector2d& b = outline[(i + 1) % n];
    const Eigen::Vector2d edge = b - a;
    if (edge.x() * (q - a).y() - edge.y() * (q - a).x() < 0.0) inside = false;
    const double t = std::clamp((q - a).dot(edge) / std::max(edge.squaredNorm(), 1e-300), 0.0, 1.0);
    nearest = std::min(nearest, (a + t * edge - q).norm());
  }
  return inside ? 0.0 : nearest;
}

// An interval of one axis where the starting grid is made finer than the sites' law asks: the
// contact zone's footprint, so that the boxes bisection starts from there are no flatter than
// kZoneBoxAspect (zone_windows). Sizes grow by `growth` per element outside [lo, hi].
struct AxisWindow {
  double lo = 0.0, hi = 0.0, fine = 0.0, growth = 2.0;
};

// The top layer around each needle's first contact (its outline, or its whole end face when
// the outline is unknown), with elements of at most `size` (m; 0: no zone):
// FidelityOverrides::contact_zone_size_m.
struct ContactZone {
  double size = 0.0;
  std::vector<char> around;  ///< per site: the zone refines there (every level's zone over a
                             ///< flat covers only the flats that get one)
  double tip_size = 0.0;     ///< m, at a pointed first contact (0: no grading toward it)
  double radius = 0.0;  ///< m, lateral reach beyond the outline (or beyond the needle's radius)
  double depth = 0.0;   ///< m, below the surface
};

// The fine level's own contact zone under one pointed tip with a criterion length L: cells of
// 1.2 L graded down to 0.12 L at the tip. Fine otherwise refines the ball under the tip but not
// the tip's contact, and read paper A's sharp bevel in skin 8-9 % deep where standard reads it
// 3-4 % deep; with this zone it reads 62.7 um against the study's converged 63.4-63.8 um, and a
// zone of 0.6 L or a tip of 0.06 L read the same to 0.1 % (docs/validation.md, "The 3-D model
// under a point load, resolved"). One needle only: an array would carry one per needle. Only
// where the level's mesh resolves L (kTipElementsPerCriterionLength within standard's spacings
// per radius, as in skin): an L far below the needle (the silicone scenes' 0.15 um) would ask
// for a zone of nanometres.
constexpr double kFineZonePerLength = 1.2;
constexpr double kFineTipPerLength = 0.12;
// The most node spacings per radius a criterion length can ask for: standard's (TET10).
constexpr double kMostSpacingsForLength = 5.5;

// True when a criterion length L can be resolved under a needle of this radius: at most
// kMostSpacingsForLength node spacings per radius at kTipElementsPerCriterionLength per L.
bool length_resolvable(const TissueBlockSpec& spec, double radius) {
  if (!(spec.criterion_length > 0.0) || spec.order != 2) return false;
  return 2.0 * radius / (kTipElementsPerCriterionLength * spec.criterion_length) <=
         kMostSpacingsForLength;
}

bool fine_resolves_the_tip(const TissueBlockSpec& spec) {
  return spec.fidelity == Fidelity::Fine && spec.sites.size() == 1 &&
         spec.sites.front().first_contact.size() == 1 &&
         length_resolvable(spec, spec.sites.front().radius);
}

// Every level's own zone over a flat first contact (a blunt bevel's flat, a cylinder's end):
// cells of 2 L over the flat and 2 L beyond its outline. Without it the flat's rim, where the
// stress criterion fires, lies in cells of about a needle radius, and paper A's blunt bevel in
// skin read 100 / 102 / 104.5 um at fast / standard / fine; with it 85.8 / 85.5 / 85.7 um, and
// a 3-D cylinder at fine 139.9 um against the axisymmetric model's 140.6 um (docs/validation.md,
// "How fine the flat must be"). Cells of L read 2 % shallower at fine (84.0 um), 4-6 % at fast
// and standard, whose far field is too stiff to gain from them, at 2-3 times the cost.
constexpr double kFlatZonePerLength = 2.0;

// A site the flat zone is for: a flat first contact (two or more lowest points) under a
// criterion length, TET10, no wider than kMostFlatRadiusPerLength L (the zone's cells grow as
// (R / L)^2: a wider flat would cost more than the rest of the mesh; the silicone scenes' 0.15 um
// against a 115 um needle is far beyond). Each site on its own, so that in an array a flat needle
// gets its zone whatever its neighbours' tips.
bool flat_wants_zone(const TissueBlockSpec& spec, const NeedleSite& site) {
  return site.first_contact.size() >= 2 && spec.criterion_length > 0.0 && spec.order == 2;
}
bool flat_gets_zone(const TissueBlockSpec& spec, const NeedleSite& site, int levels) {
  return levels > 0 && flat_wants_zone(spec, site) &&
         site.radius <= kMostFlatRadiusPerLength * spec.criterion_length;
}

bool flat_zone_applies(const TissueBlockSpec& spec, int levels) {
  for (const NeedleSite& site : spec.sites)
    if (flat_gets_zone(spec, site, levels)) return true;
  return false;
}

ContactZone contact_zone(const TissueBlockSpec& spec, int levels) {
  ContactZone zone;
  if (spec.layers.empty()) return zone;
  if (spec.overrides.contact_zone_size_m) {
    // 0: no zone at all, not even the level's own (a scene's "none").
    if (*spec.overrides.contact_zone_size_m == 0.0) return zone;
    zone.size = *spec.overrides.contact_zone_size_m;
    // At fine a zone given without a tip size keeps fine's own grading toward a pointed tip.
    const double fine_tip =
        fine_resolves_the_tip(spec) ? kFineTipPerLength * spec.criterion_length : 0.0;
    zone.tip_size = std::min(zone.size, spec.overrides.contact_zone_tip_size_m.value_or(fine_tip));
  } else if (fine_resolves_the_tip(spec)) {
    zone.size = kFineZonePerLength * spec.criterion_length;
    zone.tip_size = kFineTipPerLength * spec.criterion_length;
  } else if (flat_zone_applies(spec, levels)) {
    zone.size = kFlatZonePerLength * spec.criterion_length;
    for (const NeedleSite& site : spec.sites)
      zone.around.push_back(flat_gets_zone(spec, site, levels) ? 1 : 0);
  } else {
    return zone;
  }
  if (zone.around.empty()) zone.around.assign(spec.sites.size(), 1);
  zone.radius = spec.overrides.contact_zone_reach.value_or(kContactZoneReach) *
                std::max(zone.size, spec.criterion_length);
  zone.depth = std::min(spec.layers.front().thickness, 2.0 * zone.radius);
  return zone;
}

// Element size over distance to a contact zone's pointed first contact: each element about as
// wide as half its distance from the tip.
constexpr double kTipGrading = 0.5;

// Element size wanted at p (m) when the grid is refined along the needles' paths: the fine size
// within fine_half_width of a needle's axis and above the insertion depth, growing by `growth`
// per element with the distance from that cylinder (the tensor grid's grading, made radial).
double refinement_target(const Eigen::Vector3d& p, const std::vector<NeedleSite>& sites,
                         const MeshSizing& sizing, double insertion_depth,
                         const ContactZone& zone) {
  const double below = -p.z() - insertion_depth;
  auto from_axis = [&](double x, double y) {
    const double lateral = std::hypot(p.x() - x, p.y() - y) - sizing.fine_half_width;
    return graded_size(std::max(lateral, below), sizing);
  };
  if (sites.empty()) return from_axis(0.0, 0.0);
  double size = sizing.max_size;
  for (const NeedleSite& site : sites) size = std::min(size, from_axis(site.x, site.y));
  if (zone.size > 0.0) {
    // Distance outside the zone, graded from the zone's size at the sizing's growth.
    MeshSizing graded = sizing;
    graded.fine_size = zone.size;
    const double under = -p.z() - zone.depth;
    for (std::size_t i = 0; i < sites.size(); ++i) {
      const NeedleSite& site = sites[i];
      if (!zone.around[i]) continue;
      const double lateral =
          (site.first_contact.empty() ? std::hypot(p.x() - site.x, p.y() - site.y) - site.radius
                                      : distance_to_outline(p.head<2>(), site.first_contact)) -
          zone.radius;
      size = std::min(size, graded_size(std::max(lateral, under), graded));
      // Toward a pointed first contact the contact patch is far smaller than the ball: the size
      // halves with the distance down to the tip size (a geometric grading, about 2 000 nodes
      // per halving in paper A's skin), wherever that is finer than the zone's own law (beyond
      // the zone too: to about 17 um from a 6 um zone's tip at growth 1.35, 80 um at 1.8;
      // docs/model.md, "Tissue block and mesh").
      if (zone.tip_size > 0.0 && site.first_contact.size() == 1) {
        const double d = std::hypot((p.head<2>() - site.first_contact.front()).norm(), p.z());
        size = std::min(size, std::max(zone.tip_size, kTipGrading * d));
      }
    }
  }
  return size;
}

// Bisection keeps the shape of the box it starts from, so a zone bisected out of the starting
// grid's flat top-layer boxes (a needle radius or more wide, the layer's thickness high) ends in
// cells as flat, many more than the zone's size asks (measured: 4-8 um wide, 0.25-0.5 um high
// for a 6 um zone in paper A's skin). Over the zone's footprint the starting grid is therefore made
// at most kZoneBoxAspect times wider than its top cell is high, graded back at the sizing's growth;
// those lines cross the whole block, where the cells stay within the grid's aspect cap.
constexpr double kZoneBoxAspect = 2.0;

// The windows' lines run down the whole block, so under the zone the starting grid's boxes are
// the windows' spacing wide and as tall as the z axis makes them (at fast 40 um wide and 350 um
// tall under paper A's blunt bevel in skin). Bisected down to the size wanted there such a box
// keeps its shape and ends in cells several times narrower than anything asks for. At fast the
// z axis therefore takes no cell taller than kColumnPerWindow times the windows' spacing down to
// the zone's depth, growing at the sizing's growth below it. Standard's z axis has such a line
// already; fine keeps its column, which holds its force within 1 % of its reference (what each
// measured: docs/model.md, "Tissue block and mesh").
constexpr double kColumnPerWindow = 2.0;

std::array<std::vector<AxisWindow>, 2> zone_windows(const TissueBlockSpec& spec,
                                                    const ContactZone& zone,
                                                    const std::vector<double>& z,
                                                    const MeshSizing& lateral) {
  std::array<std::vector<AxisWindow>, 2> windows;
  if (zone.size <= 0.0 || z.size() < 2) return windows;
  const double top_cell = z[z.size() - 1] - z[z.size() - 2];
  const double fine = kZoneBoxAspect * top_cell;
  if (fine >= lateral.fine_size) return windows;
  for (std::size_t i = 0; i < spec.sites.size(); ++i) {
    const NeedleSite& site = spec.sites[i];
    if (!zone.around[i]) continue;
    Eigen::Vector2d lo(site.x - site.radius, site.y - site.radius),
        hi(site.x + site.radius, site.y + site.radius);
    if (!site.first_contact.empty()) {
      lo = hi = site.first_contact.front();
      for (const Eigen::Vector2d& q : site.first_contact) {
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
    }
    for (int a = 0; a < 2; ++a)
      windows[static_cast<std::size_t>(a)].push_back(
          {lo[a] - zone.radius, hi[a] + zone.radius, fine, lateral.growth});
  }
  return windows;
}

// Places nodes on [lo, hi] so that each interval spans about one local element size, by
// inverting the cumulative integral of 1 / size(x); min_cells forces a minimum count.
template <typename SizeAt>
std::vector<double> graded_coordinates(double lo, double hi, SizeAt size_at, int min_cells) {
  constexpr int kSamples = 4000;
  std::vector<double> cumulative(kSamples + 1, 0.0);
  const double dx = (hi - lo) / kSamples;
  for (int s = 0; s < kSamples; ++s) {
    const double x0 = lo + s * dx;
    cumulative[s + 1] = cumulative[s] + 0.5 * dx * (1.0 / size_at(x0) + 1.0 / size_at(x0 + dx));
  }
  const double total = cumulative.back();
  const int cells = std::max(min_cells, static_cast<int>(std::ceil(total - 1e-6)));
  std::vector<double> coordinates(static_cast<std::size_t>(cells) + 1);
  coordinates.front() = lo;
  coordinates.back() = hi;
  int s = 0;
  for (int m = 1; m < cells; ++m) {
    const double target = total * m / cells;
    while (cumulative[s + 1] < target) ++s;
    const double t = (target - cumulative[s]) / (cumulative[s + 1] - cumulative[s]);
    coordinates[static_cast<std::size_t>(m)] = lo + (s + t) * dx;
  }
  return coordinates;
}

// Nodes marched outward from `from` toward `to` (either direction), each interval the local
// element size, so the cells near `from` do not depend on where the block ends: cutting the
// block (the planner's domain cut) leaves the mesh at the needle unchanged. A remainder of at
// least half a size is a cell of its own; a smaller one is spread over the last few cells (far
// from `from`). A piece that is all one size is divided evenly.
template <typename SizeAt>
std::vector<double> marched_coordinates(double from, double to, SizeAt size_at) {
  constexpr int kSpreadCells = 4;
  const double direction = to > from ? 1.0 : -1.0;
  const double length = std::abs(to - from);
  std::vector<double> offsets{0.0};
  bool uniform = true;
  const double first_size = size_at(from);
  while (true) {
    const double size = size_at(from + direction * offsets.back());
    uniform = uniform && std::abs(size - first_size) <= 1e-9 * first_size;
    const double remainder = length - offsets.back();
    if (remainder <= size) {
      if (remainder < 0.5 * size && offsets.size() > 1) {
        // Re-space the last cells evenly with the remainder as one more cell: all shrink a
        // little, none grows (the lateral size cap keeps the aspect floor).
        const std::size_t cells = offsets.size() - 1;
        const std::size_t spread = std::min<std::size_t>(cells, kSpreadCells);
        const double start = offsets[cells - spread];
        for (std::size_t k = 1; k <= spread; ++k)
          offsets[cells - spread + k] =
              start + (length - start) * static_cast<double>(k) / static_cast<double>(spread + 1);
      }
      break;
    }
    offsets.push_back(offsets.back() + size);
  }
  offsets.push_back(length);
  if (uniform) {
    const auto cells =
        static_cast<std::size_t>(std::max(1.0, std::ceil(length / first_size - 1e-9)));
    offsets.resize(cells + 1);
    for (std::size_t k = 0; k <= cells; ++k)
      offsets[k] = length * static_cast<double>(k) / static_cast<double>(cells);
  }
  std::vector<double> coordinates;
  for (double o : offsets) coordinates.push_back(from + direction * o);
  if (direction < 0.0) std::reverse(coordinates.begin(), coordinates.end());
  coordinates.front() = std::min(from, to);
  coordinates.back() = std::max(from, to);
  return coordinates;
}

// Grid pieces between consecutive breaks: a piece between two needles is graded; an outer piece
// marches out from its needle side, so the cells at a needle do not depend on where the block
// ends. With march_from_lo false the axis starts on a mirror plane: its first piece is an inner
// one, and the last piece marches out even when it is also the first.
template <typename SizeAt>
std::vector<double> axis_through(const std::vector<double>& breaks, bool march_from_lo,
                                 SizeAt size_at) {
  std::vector<double> coordinates{breaks.front()};
  for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
    const bool first = b == 0, last = b + 2 == breaks.size();
    const std::vector<double> piece =
        first && !last && march_from_lo ? marched_coordinates(breaks[b + 1], breaks[b], size_at)
        : last && (!first || !march_from_lo)
            ? marched_coordinates(breaks[b], breaks[b + 1], size_at)
            : graded_coordinates(breaks[b], breaks[b + 1], size_at, 1);
    coordinates.insert(coordinates.end(), piece.begin() + 1, piece.end());
  }
  return coordinates;
}

// True when the set of points maps onto itself under p -> -p.
bool symmetric_about_zero(std::vector<double> points, double tolerance) {
  std::sort(points.begin(), points.end());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (std::abs(points[i] + points[points.size() - 1 - i]) > tolerance) return false;
  return true;
}

// Off-axis tips (a bevel's) that get a grid line of their own: tips yield to the sites (a half
// model needs its line on the mirror plane), to the block's sides and to each other.
std::vector<double> tips_clear_of(const std::vector<double>& sites, const std::vector<double>& tips,
                                  double half, double clearance) {
  std::vector<double> taken = sites;
  taken.push_back(-half);
  taken.push_back(half);
  std::vector<double> clear;
  for (double t : tips) {
    const bool free = std::all_of(taken.begin(), taken.end(),
                                  [&](double b) { return std::abs(t - b) > clearance; });
    if (!free) continue;
    clear.push_back(t);
    taken.push_back(t);
  }
  return clear;
}

// Grid lines along one axis of [-half, half], through every site and every clear tip. When sites
// and tips are symmetric about 0 the axis is built on [0, half] and reflected, with a line on 0:
// the half >= 0 is then exactly a half model's axis.
std::vector<double> lateral_coordinates(double half, const std::vector<double>& centres,
                                        const std::vector<double>& tips, const MeshSizing& sizing,
                                        double clearance, const std::vector<AxisWindow>& windows,
                                        bool* symmetric) {
  auto size_at = [&](double x) {
    double size = sizing.max_size;
    for (double c : centres)
      size = std::min(size, graded_size(std::abs(x - c) - sizing.fine_half_width, sizing));
    // Built on [0, half] and reflected when symmetric: a window then counts on both sides.
    for (const AxisWindow& w : windows)
      for (double at : {x, *symmetric ? -x : x})
        size = std::min(size, w.fine + (w.growth - 1.0) * std::max({0.0, w.lo - at, at - w.hi}));
    return size;
  };
  std::vector<double> sorted = centres;
  std::sort(sorted.begin(), sorted.end());
  const std::vector<double> clear = tips_clear_of(sorted, tips, half, clearance);
  std::vector<double> lines = sorted;
  lines.insert(lines.end(), clear.begin(), clear.end());
  *symmetric = symmetric_about_zero(lines, 1e-12 * half);
  std::vector<double> breaks{*symmetric ? 0.0 : -half};
  for (double c : sorted)
    if (c - breaks.back() > clearance && half - c > clearance) breaks.push_back(c);
  breaks.push_back(half);
  for (double t : clear)
    if (!*symmetric || t > clearance)
      breaks.insert(std::upper_bound(breaks.begin(), breaks.end(), t), t);
  if (!*symmetric) return axis_through(breaks, true, size_at);
  const std::vector<double> upper = axis_through(breaks, false, size_at);
  std::vector<double> coordinates;
  for (auto it = upper.rbegin(); it + 1 != upper.rend(); ++it) coordinates.push_back(-*it);
  coordinates.insert(coordinates.end(), upper.begin(), upper.end());
  return coordinates;
}

// A cap on the z axis's cell height under a zone (kColumnPerWindow): `size` (m) down to `depth`
// (m below the surface), growing by `growth` per element below it.
struct ColumnGrading {
  double depth = 0.0, size = 0.0, growth = 2.0;
};

// z coordinates from the bottom (-total) to the top surface (0), conforming to every layer
// interface; element size grows with the distance below the fine depth, and stays within a
// column's cap when one is given.
std::vector<double> vertical_coordinates(const std::vector<TissueLayer>& layers,
                                         const MeshSizing& sizing, double fine_depth,
                                         const ColumnGrading* column = nullptr) {
  auto size_at = [&](double z) {
    const double size = graded_size(-z - fine_depth, sizing);
    if (!column) return size;
    return std::min(size,
                    column->size + (column->growth - 1.0) * std::max(0.0, -z - column->depth));
  };
  std::vector<double> z_top_down{0.0};
  double top = 0.0;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const double bottom = top - layers[i].thickness;
    const int min_cells = i == 0 ? sizing.elements_through_top : 1;
    std::vector<double> layer_z = graded_coordinates(bottom, top, size_at, min_cells);
    for (auto it = layer_z.rbegin() + 1; it != layer_z.rend(); ++it) z_top_down.push_back(*it);
    top = bottom;
  }
  z_top_down.back() = top;
  return {z_top_down.rbegin(), z_top_down.rend()};
}

double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b));
  const auto hi = static_cast<std::uint64_t>(std::max(a, b));
  return (lo << 32) | hi;
}

std::uint64_t face_key(std::array<int, 3> f) {
  std::sort(f.begin(), f.end());
  return (static_cast<std::uint64_t>(f[0]) << 42) | (static_cast<std::uint64_t>(f[1]) << 21) |
         static_cast<std::uint64_t>(f[2]);
}

std::array<int, 3> face_corners(const std::array<int, 10>& element, int opposite) {
  std::array<int, 3> corners{};
  int n = 0;
  for (int i = 0; i < 4; ++i)
    if (i != opposite)
      corners[static_cast<std::size_t>(n++)] = element[static_cast<std::size_t>(i)];
  return corners;
}

int local_edge(int a, int b) {
  for (int e = 0; e < 6; ++e)
    if ((kEdgeNodes[e][0] == a && kEdgeNodes[e][1] == b) ||
        (kEdgeNodes[e][0] == b && kEdgeNodes[e][1] == a))
      return e;
  return -1;
}

// True for the cells left of (below) their nearest site along one axis: those cells take the
// mirrored split, so the mesh is mirror-symmetric about every site and a symmetric needle feels
// no lateral force from the mesh itself.
std::vector<char> mirrored_cells(const std::vector<double>& axis,
                                 const std::vector<double>& sites) {
  std::vector<char> mirrored(axis.size() - 1, 0);
  for (std::size_t i = 0; i + 1 < axis.size(); ++i) {
    const double centre = 0.5 * (axis[i] + axis[i + 1]);
    double nearest = sites.front();
    for (double s : sites)
      if (std::abs(centre - s) < std::abs(centre - nearest)) nearest = s;
    mirrored[i] = centre < nearest ? 1 : 0;
  }
  return mirrored;
}

// Six tetrahedra per hexahedron, all sharing one main diagonal of the cell (Kuhn/Freudenthal).
// The diagonal may be mirrored in x per column and in y per row: a face between two cells then
// still gets the same diagonal from both sides, so the mesh stays conforming. Each tetrahedron
// goes to emit(path, layer) with its corners along the path corner 0 -> corner 7 (the order
// bisection needs, docs/model.md "Tissue block and mesh").
template <typename Emit>
void split_cells(const std::array<std::vector<double>, 3>& axes, const std::vector<int>& cell_layer,
                 const std::vector<char>& mirror_x, const std::vector<char>& mirror_y, Emit emit) {
  const int nx = static_cast<int>(axes[0].size()) - 1;
  const int ny = static_cast<int>(axes[1].size()) - 1;
  const int nz = static_cast<int>(axes[2].size()) - 1;
  auto node = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                       {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int flip = (mirror_x[static_cast<std::size_t>(i)] ? 1 : 0) |
                         (mirror_y[static_cast<std::size_t>(j)] ? 2 : 0);
        std::array<int, 8> corner{};
        for (int b = 0; b < 8; ++b) {
          const int c = b ^ flip;
          corner[static_cast<std::size_t>(b)] = node(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
        }
        for (const auto& perm : kPermutations) {
          const int v1 = 1 << perm[0];
          const int v2 = v1 | (1 << perm[1]);
          emit(std::array<int, 4>{corner[0], corner[static_cast<std::size_t>(v1)],
                                  corner[static_cast<std::size_t>(v2)], corner[7]},
               cell_layer[static_cast<std::size_t>(k)]);
        }
      }
}

// Appends a tetrahedron to the mesh, positively oriented.
void add_element(TetMesh& mesh, const std::array<int, 4>& corners, int layer) {
  std::array<int, 10> tet{};
  tet.fill(-1);
  std::copy(corners.begin(), corners.end(), tet.begin());
  const auto& x = mesh.nodes;
  if (signed_tet_volume(x[tet[0]], x[tet[1]], x[tet[2]], x[tet[3]]) < 0.0)
    std::swap(tet[1], tet[2]);
  mesh.elements.push_back(tet);
  mesh.element_layer.push_back(layer);
}

void add_midside_nodes(TetMesh& mesh) {
  std::unordered_map<std::uint64_t, int> edge_node;
  edge_node.reserve(mesh.elements.size() * 2);
  for (auto& tet : mesh.elements)
    for (int e = 0; e < 6; ++e) {
      const int a = tet[static_cast<std::size_t>(kEdgeNodes[e][0])];
      const int b = tet[static_cast<std::size_t>(kEdgeNodes[e][1])];
      auto [it, inserted] =
          edge_node.try_emplace(edge_key(a, b), static_cast<int>(mesh.nodes.size()));
      if (inserted) mesh.nodes.push_back(0.5 * (mesh.nodes[a] + mesh.nodes[b]));
      tet[static_cast<std::size_t>(4 + e)] = it->second;
    }
}

void link_neighbours_and_top(TetMesh& mesh) {
  std::unordered_map<std::uint64_t, int> open_faces;
  open_faces.reserve(mesh.elements.size() * 2);
  mesh.neighbours.assign(mesh.elements.size(), {-1, -1, -1, -1});
  for (std::size_t t = 0; t < mesh.elements.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::uint64_t key = face_key(face_corners(mesh.elements[t], f));
      auto it = open_faces.find(key);
      if (it == open_faces.end()) {
        open_faces.emplace(key, static_cast<int>(t) * 4 + f);
        continue;
      }
      const int other = it->second / 4;
      mesh.neighbours[t][static_cast<std::size_t>(f)] = other;
      mesh.neighbours[static_cast<std::size_t>(other)][static_cast<std::size_t>(it->second % 4)] =
          static_cast<int>(t);
      open_faces.erase(it);
    }
  for (std::size_t t = 0; t < mesh.elements.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      if (mesh.neighbours[t][static_cast<std::size_t>(f)] >= 0) continue;
      const auto& tet = mesh.elements[t];
      std::array<int, 3> local{};
      int n = 0;
      for (int i = 0; i < 4; ++i)
        if (i != f) local[static_cast<std::size_t>(n++)] = i;
      const bool on_top = std::all_of(local.begin(), local.end(), [&](int i) {
        return mesh.nodes[tet[static_cast<std::size_t>(i)]].z() == 0.0;
      });
      if (!on_top) continue;
      std::array<int, 6> face{};
      face.fill(-1);
      for (int i = 0; i < 3; ++i) face[static_cast<std::size_t>(i)] = tet[local[i]];
      if (mesh.order == 2)
        for (int i = 0; i < 3; ++i)
          face[static_cast<std::size_t>(3 + i)] =
              tet[static_cast<std::size_t>(4 + local_edge(local[i], local[(i + 1) % 3]))];
      mesh.top_faces.push_back(face);
    }
}

// A mirror plane (x = lo.x = 0 or y = lo.y = 0 of a reduced model) is not a clamped side.
void mark_fixed_nodes(TetMesh& mesh, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                      bool mirror_lo_x, bool mirror_lo_y) {
  const double tolerance = 1e-9 * (hi - lo).norm();
  mesh.fixed.assign(mesh.nodes.size(), 0);
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const Eigen::Vector3d& p = mesh.nodes[n];
    const bool side = (!mirror_lo_x && std::abs(p.x() - lo.x()) < tolerance) ||
                      std::abs(p.x() - hi.x()) < tolerance ||
                      (!mirror_lo_y && std::abs(p.y() - lo.y()) < tolerance) ||
                      std::abs(p.y() - hi.y()) < tolerance;
    const bool bottom = std::abs(p.z() - lo.z()) < tolerance;
    mesh.fixed[n] = side || bottom ? 1 : 0;
  }
}

// One lateral axis and its cells' split flags; with `half` only the part >= 0 of the full axis
// (which is symmetric about 0 by construction when its sites and tips are), so a reduced model
// meshes exactly its share of the full mesh.
std::vector<double> half_axis(double half_size, const std::vector<double>& sites,
                              const std::vector<double>& tips, const MeshSizing& sizing,
                              double clearance, const std::vector<AxisWindow>& windows, bool half,
                              const std::string& name, std::vector<char>* mirrored) {
  bool symmetric = false;
  std::vector<double> axis =
      lateral_coordinates(half_size, sites, tips, sizing, clearance, windows, &symmetric);
  *mirrored = mirrored_cells(axis, sites);
  if (!half) return axis;
  if (!symmetric)
    bad_spec("mirror plane " + name + " = 0",
             "the needle sites and tips are not symmetric about it (use the full model)");
  const auto zero = std::find(axis.begin(), axis.end(), 0.0);
  if (zero == axis.end()) bad_spec("mirror plane " + name + " = 0", "no grid line on it");
  const auto skip = zero - axis.begin();
  axis.erase(axis.begin(), zero);
  mirrored->erase(mirrored->begin(), mirrored->begin() + skip);
  return axis;
}

}  // namespace

Fidelity parse_fidelity(const std::string& text, const std::string& field) {
  if (text == "fast") return Fidelity::Fast;
  if (text == "standard") return Fidelity::Standard;
  if (text == "fine") return Fidelity::Fine;
  throw InputError(field + ": unknown fidelity '" + text + "' (expected fast, standard or fine)");
}

std::string to_string(Fidelity fidelity) {
  switch (fidelity) {
    case Fidelity::Fast:
      return "fast";
    case Fidelity::Standard:
      return "standard";
    case Fidelity::Fine:
      break;
  }
  return "fine";
}

int default_refinement_levels(Fidelity fidelity, int order, double criterion_length) {
  // TET10 only: TET4 stiffens on the refined grid's coarser far field. Fast keeps the plain
  // grid: refined, its coarse far field put the bonded punch 12.6 % above Hayes, against 2.5 % on
  // the grid; but a criterion length needs the thin top layer cut four times through near the
  // needle, which only the refinement gives (docs/model.md, "Tissue block and mesh").
  if (order != 2) return 0;
  return fidelity == Fidelity::Fast && !(criterion_length > 0.0) ? 0 : 2;
}

MeshSizing mesh_sizing(Fidelity fidelity, int order, double needle_radius, double block_size,
                       const FidelityOverrides& overrides, double criterion_length) {
  // Node spacings per needle radius at the site (a TET10 element spans two, a TET4 one), growth
  // ratio and elements through the top layer. Grid lines march out from the needle's axis, so
  // a whole number of spacings per radius would put nodes exactly on a flat punch's rim or a
  // bevel's tip, where rounding decides whether the needle holds them: the counts are
  // half-integers, which puts the rim half-way between two nodes.
  struct Level {
    double spacings_per_radius;
    double growth;
    int through_top;
  };
  // TET10 standard resolves the tip as fine does (5.5 spacings, refined along the path): within
  // 1 % of fine's puncture depth across bevel angles, where 3.5 spacings on the tensor grid missed
  // by up to 18 %. The growth is set by a flat face in skin against the skin run's time: the
  // blunt bevel's force 6 % above fine at 1.8 (11 % at 2.0; 4 % at 1.6, which took 1.07 s against
  // the 1 s target); docs/model.md, "Tissue block and mesh". TET4 keeps its former level. Fine
  // grows at 1.6 (1.35 until 2026-12-07): paper A's sharp bevel in skin on 60 373 nodes instead
  // of 100 204, 63.1 um against 62.7 um at 1.35 (converged: 63.4-63.8 um).
  Level level = fidelity == Fidelity::Fast ? Level{2.5, 2.0, 1}
                : fidelity == Fidelity::Standard
                    ? (order == 2 ? Level{5.5, 1.8, 1} : Level{3.5, 1.6, 1})
                    : Level{5.5, 1.6, 2};
  // The stress criterion averages over L: a tip element wider than 5.5 L reads a stress field
  // the mesh has not resolved (fast's 9.2 L put a sharp bevel's puncture in skin 54 % from
  // fine's). The spacing stays a half-integer per radius, so the cap rounds up to the next one,
  // and no level goes finer than standard's 5.5 for it: an L far below the needle (silicone's
  // 0.15 um) would otherwise ask for millions of elements (docs/model.md, "Tissue block and
  // mesh").
  if (criterion_length > 0.0 && std::isfinite(criterion_length)) {
    const double needed = 2.0 * needle_radius / (kTipElementsPerCriterionLength * criterion_length);
    level.spacings_per_radius = std::max(
        level.spacings_per_radius, std::min(std::ceil(needed - 0.5) + 0.5, kMostSpacingsForLength));
  }
  const int refinement = order == 1 ? 2 : 1;
  MeshSizing sizing;
  sizing.fine_size = order * needle_radius / level.spacings_per_radius;
  sizing.fine_half_width = 1.25 * needle_radius;
  sizing.growth = level.growth;
  sizing.max_size = std::max(sizing.fine_size, block_size / 4.0);
  sizing.elements_through_top = level.through_top * refinement;
  if (overrides.tip_size_m) {
    if (!(*overrides.tip_size_m > 0.0) || !std::isfinite(*overrides.tip_size_m))
      bad_spec("overrides.tip_size_m", "must be positive and finite");
    sizing.fine_size = *overrides.tip_size_m;
  }
  if (overrides.growth) {
    if (!(*overrides.growth >= 1.0) || !std::isfinite(*overrides.growth))
      bad_spec("overrides.growth", "must be >= 1 and finite");
    sizing.growth = *overrides.growth;
  }
  if (overrides.elements_through_top) {
    if (*overrides.elements_through_top < 1)
      bad_spec("overrides.elements_through_top", "must be >= 1");
    sizing.elements_through_top = *overrides.elements_through_top;
  }
  sizing.max_size = std::max(sizing.fine_size, block_size / 4.0);
  return sizing;
}

TetMesh generate_tissue_mesh(const TissueBlockSpec& spec) {
  validate(spec);
  double radius = 0.0;
  for (const NeedleSite& site : spec.sites) radius = std::max(radius, site.radius);
  double total = 0.0;
  for (const TissueLayer& layer : spec.layers) total += layer.thickness;
  if (radius == 0.0) radius = std::min(spec.size_x, spec.size_y) / 20.0;
  const MeshSizing sizing =
      mesh_sizing(spec.fidelity, spec.order, radius, std::max({spec.size_x, spec.size_y, total}),
                  spec.overrides, spec.criterion_length);
  std::vector<double> cx, cy, tip_x, tip_y;
  for (const NeedleSite& site : spec.sites) {
    cx.push_back(site.x);
    cy.push_back(site.y);
    if (site.tip) {
      tip_x.push_back(site.tip->x());
      tip_y.push_back(site.tip->y());
    }
  }
  if (spec.sites.empty()) cx = cy = {0.0};
  // With refinement levels the grid is built 2^levels coarser at the sites and bisected back
  // down to the fine size along the needles' paths only.
  const int levels = spec.overrides.refinement_levels.value_or(
      default_refinement_levels(spec.fidelity, spec.order, spec.criterion_length));
  // The zone is bisected out of a refined grid: without levels it would be silently nothing.
  if (spec.overrides.contact_zone_size_m && *spec.overrides.contact_zone_size_m > 0.0 &&
      levels == 0)
    bad_spec("overrides.contact_zone_size_m",
             "needs refinement levels (mesh_refinement >= 1; fast without the stress criterion "
             "and TET4 elements have none by default)");
  MeshSizing base = sizing;
  if (levels > 0) {
    const std::vector<double> z_fine =
        vertical_coordinates(spec.layers, sizing, spec.insertion_depth);
    double thinnest_fine = z_fine.back() - z_fine.front();
    for (std::size_t k = 0; k + 1 < z_fine.size(); ++k)
      thinnest_fine = std::min(thinnest_fine, z_fine[k + 1] - z_fine[k]);
    base.fine_size = std::min({sizing.max_size, std::ldexp(sizing.fine_size, levels),
                               std::max(sizing.fine_size, kMaxRefinedCellAspect * thinnest_fine)});
  }
  std::vector<double> z = vertical_coordinates(spec.layers, base, spec.insertion_depth);
  // A tensor grid carries the thinnest layer's cell height everywhere in x and y: cap the
  // lateral size so those cells stay within kMaxCellAspect (the quality floor rests on it).
  double thinnest = z.back() - z.front();
  for (std::size_t k = 0; k + 1 < z.size(); ++k) thinnest = std::min(thinnest, z[k + 1] - z[k]);
  MeshSizing lateral = base;
  lateral.max_size = std::max(base.fine_size, std::min(base.max_size, kMaxCellAspect * thinnest));
  // A tip closer than this to a site or another line gets no line of its own. It scales with
  // the grid actually built: on a coarser base grid a tip line a quarter of the fine size from
  // a site line would leave a sliver cell that bisection cannot improve. But not beyond the two
  // levels' grid: from three levels on it dropped a bevel's tip line (R from the axis), so no node
  // lay under the tip and the needle touched nothing at its first step (paper A's bevel in skin
  // at fast, mesh_refinement 4: 0 N at 20 um and a puncture at 123 um against 65 um; in silicone
  // 3 levels: 712 against 618-647 um; docs/validation.md, "Refinement levels beyond two").
  const double clearance = 0.25 * std::min(base.fine_size, std::ldexp(sizing.fine_size, 2));
  const ContactZone zone = contact_zone(spec, levels);
  const std::array<std::vector<AxisWindow>, 2> windows =
      levels > 0 ? zone_windows(spec, zone, z, lateral) : std::array<std::vector<AxisWindow>, 2>{};
  if (spec.fidelity == Fidelity::Fast && !windows[0].empty()) {
    // Every window has the same spacing (2 x the top cell) and growth (zone_windows).
    const AxisWindow& window = windows[0].front();
    const ColumnGrading column{zone.depth, kColumnPerWindow * window.fine, lateral.growth};
    std::vector<double> graded =
        vertical_coordinates(spec.layers, base, spec.insertion_depth, &column);
    // The cap lies above the top cell's height, but every layer it touches is divided anew:
    // kept only if neither the top cell (the windows' spacing rests on it) nor the thinnest cell
    // (the lateral size cap rests on it) got thinner.
    auto thinnest_of = [](const std::vector<double>& axis) {
      double cell = axis.back() - axis.front();
      for (std::size_t k = 0; k + 1 < axis.size(); ++k)
        cell = std::min(cell, axis[k + 1] - axis[k]);
      return cell;
    };
    auto top_of = [](const std::vector<double>& axis) {
      return axis[axis.size() - 1] - axis[axis.size() - 2];
    };
    constexpr double kRoundOff = 1.0 - 1e-9;
    if (thinnest_of(graded) >= kRoundOff * thinnest && top_of(graded) >= kRoundOff * top_of(z))
      z = std::move(graded);
  }
  std::array<std::vector<char>, 2> mirrored;
  std::array<std::vector<double>, 3> axes = {
      half_axis(spec.size_x / 2, cx, tip_x, lateral, clearance, windows[0], spec.half_x, "x",
                &mirrored[0]),
      half_axis(spec.size_y / 2, cy, tip_y, lateral, clearance, windows[1], spec.half_y, "y",
                &mirrored[1]),
      std::move(z)};
  // Refused before a node is made: six tetrahedra per grid cell already past the cap took a
  // 1 m skin block to 14.6 GB before the refinement's own check (its 20 um top layer caps the
  // lateral cell size, so the cell count grows with the block's area).
  const double grid_tets = 6.0 * static_cast<double>(axes[0].size() - 1) *
                           static_cast<double>(axes[1].size() - 1) *
                           static_cast<double>(axes[2].size() - 1);
  if (grid_tets > static_cast<double>(kMaxRefinedTets)) {
    std::ostringstream why;
    why << "the block's grid alone is " << count_text(grid_tets) << " tetrahedra ("
        << axes[0].size() - 1 << " x " << axes[1].size() - 1 << " x " << axes[2].size() - 1
        << " cells), above the limit of " << kMaxRefinedTets
        << ": a smaller block, a coarser fidelity or a thicker top layer (its cell height caps "
           "the cells' width) needs fewer";
    bad_spec("size", why.str());
  }
  TetMesh mesh;
  mesh.order = spec.order;
  mesh.layers = spec.layers;
  mesh.contact_zone_m = zone.size;
  for (const NeedleSite& site : spec.sites)
    if (flat_wants_zone(spec, site) && !flat_gets_zone(spec, site, levels) &&
        !spec.overrides.contact_zone_size_m)
      ++mesh.unresolved_flats;
  for (int a = 0; a < 3; ++a)
    mesh.grid_cells[static_cast<std::size_t>(a)] =
        static_cast<int>(axes[static_cast<std::size_t>(a)].size()) - 1;
  for (double z : axes[2])
    for (double y : axes[1])
      for (double x : axes[0]) mesh.nodes.emplace_back(x, y, z);

  std::vector<int> cell_layer;
  for (std::size_t k = 0; k + 1 < axes[2].size(); ++k) {
    const double centre_depth = -0.5 * (axes[2][k] + axes[2][k + 1]);
    double top = 0.0;
    int layer = 0;
    for (std::size_t i = 0; i < spec.layers.size(); ++i) {
      layer = static_cast<int>(i);
      if (centre_depth < top + spec.layers[i].thickness) break;
      top += spec.layers[i].thickness;
    }
    cell_layer.push_back(layer);
  }
  if (levels == 0) {
    split_cells(axes, cell_layer, mirrored[0], mirrored[1],
                [&](const std::array<int, 4>& path, int layer) { add_element(mesh, path, layer); });
  } else {
    TetBisection bisection(std::move(mesh.nodes));
    split_cells(
        axes, cell_layer, mirrored[0], mirrored[1],
        [&](const std::array<int, 4>& path, int layer) { bisection.add_kuhn_tet(path, layer); });
    bisection.refine(
        [&](const Eigen::Vector3d& p) {
          return refinement_target(p, spec.sites, sizing, spec.insertion_depth, zone);
        },
        kMaxRefinedTets);
    mesh.nodes = bisection.nodes();
    for (std::size_t t = 0; t < bisection.tets().size(); ++t)
      add_element(mesh, bisection.tets()[t], bisection.layers()[t]);
  }
  if (mesh.order == 2) add_midside_nodes(mesh);
  link_neighbours_and_top(mesh);
  mark_fixed_nodes(mesh, {axes[0].front(), axes[1].front(), axes[2].front()},
                   {axes[0].back(), axes[1].back(), 0.0}, spec.half_x, spec.half_y);
  mesh.mirror_x0 = spec.half_x;
  mesh.mirror_y0 = spec.half_y;
  return mesh;
}

MeshQuality mesh_quality(const TetMesh& mesh) {
  MeshQuality quality{180.0, 0.0, std::numeric_limits<double>::max()};
  for (const auto& tet : mesh.elements) {
    std::array<Eigen::Vector3d, 4> p;
    for (int i = 0; i < 4; ++i)
      p[static_cast<std::size_t>(i)] = mesh.nodes[tet[static_cast<std::size_t>(i)]];
    const double volume = signed_tet_volume(p[0], p[1], p[2], p[3]);
    std::array<Eigen::Vector3d, 4> normal;  // outward unit normal of the face opposite corner i
    double area_sum = 0.0;
    for (int i = 0; i < 4; ++i) {
      const auto& a = p[static_cast<std::size_t>((i + 1) % 4)];
      const auto& b = p[static_cast<std::size_t>((i + 2) % 4)];
      const auto& c = p[static_cast<std::size_t>((i + 3) % 4)];
      Eigen::Vector3d n = (b - a).cross(c - a);
      area_sum += 0.5 * n.norm();
      if (n.dot(a - p[static_cast<std::size_t>(i)]) < 0.0) n = -n;
      normal[static_cast<std::size_t>(i)] = n.normalized();
    }
    double longest = 0.0;
    for (int e = 0; e < 6; ++e) {
      const int a = kEdgeNodes[e][0], b = kEdgeNodes[e][1];
      longest = std::max(longest,
                         (p[static_cast<std::size_t>(a)] - p[static_cast<std::size_t>(b)]).norm());
      // The edge ab is shared by the faces opposite the other two corners.
      int others[2], n = 0;
      for (int i = 0; i < 4; ++i)
        if (i != a && i != b) others[n++] = i;
      const double cosine = -normal[static_cast<std::size_t>(others[0])].dot(
          normal[static_cast<std::size_t>(others[1])]);
      const double angle = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
      quality.min_dihedral_deg = std::min(quality.min_dihedral_deg, angle);
    }
    const double inradius = 3.0 * volume / area_sum;
    quality.max_aspect_ratio =
        std::max(quality.max_aspect_ratio, longest / (2.0 * std::sqrt(6.0) * inradius));
    quality.min_volume = std::min(quality.min_volume, volume);
  }
  return quality;
}

}  // namespace mneedle::fe
