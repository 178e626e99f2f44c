#include "mneedle/design_source.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/geometry/cross_section.h"
#include "mneedle/geometry/holder.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/needle/mesh_validation.h"
#include "mneedle/needle/needle_frame.h"

namespace mneedle {
namespace {

// Widths of a needle outside which a mesh file is reported as a likely unit mistake.
constexpr double kSmallestWidth_m = 1e-6;
constexpr double kLargestWidth_m = 20e-3;

const PluginParameter& find_parameter(const PluginShapeInfo& shape, const std::string& name) {
  for (const auto& p : shape.parameters)
    if (p.name == name) return p;
  std::string known;
  for (const auto& p : shape.parameters) known += (known.empty() ? "" : ", ") + p.name;
  throw InputError("shape '" + shape.name + "' has no parameter '" + name + "' (known: " + known +
                   ")");
}

Dimension parameter_dimension(const PluginParameter& p) {
  if (p.unit == "m") return Dimension::Length;
  if (p.unit == "rad") return Dimension::Angle;
  return Dimension::Dimensionless;
}

}  // namespace

std::map<std::string, double> parse_parameter_settings(const PluginShapeInfo& shape,
                                                       const std::vector<std::string>& settings) {
  std::map<std::string, double> si;
  for (const auto& setting : settings) {
    const auto eq = setting.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--set '" + setting + "': expected key=value, e.g. diameter=230um");
    const std::string key = setting.substr(0, eq);
    const PluginParameter& p = find_parameter(shape, key);
    if (si.count(key) != 0) throw InputError("--set " + key + ": given twice");  // not the last
    try {
      si[key] = parse_quantity(setting.substr(eq + 1), parameter_dimension(p));
    } catch (const InputError& e) {
      throw InputError("--set " + key + ": " + e.what());
    }
  }
  return si;
}

std::map<std::string, double> scene_parameters(const PluginShapeInfo& shape,
                                               const std::map<std::string, Quantity>& given,
                                               const std::string& where) {
  std::map<std::string, double> si;
  for (const auto& [key, quantity] : given) {
    const PluginParameter& p = find_parameter(shape, key);
    si[key] = quantity_in(quantity, parameter_dimension(p), where + "." + key);
  }
  return si;
}

NeedleSource needle_from_file(const std::filesystem::path& file, double metres_per_unit,
                              const AxisChoice& axis, bool repair) {
  NeedleSource n;
  n.name = file.stem().string();
  n.mesh = load_mesh(file, metres_per_unit);
  std::string repaired;
  if (repair) {
    for (const std::string& change : repair_mesh(n.mesh).changes) {
      repaired += (repaired.empty() ? "repaired: " : ", ") + change;
    }
  }
  require_valid_mesh(n.mesh, file.string());
  const FrameInfo frame = place_in_needle_frame(n.mesh, axis);
  const bool input_z = std::abs(frame.axis[2] + 1.0) < 1e-9;
  n.frame_note = repaired;
  // A guessed axis is said even when the guess is the input z (a cube, a body as wide as long).
  if (!input_z || frame.fell_back_to_input_z)
    n.frame_note += (n.frame_note.empty() ? "" : "; ") + frame.note;
  if (const auto jump = find_holder_jump(n.mesh)) {
    // Cut a hair below the holder's face, so the cut never runs along it.
    const double cut = jump->height_m - 1e-6 * jump->total_height_m;
    n.mesh = cut_above(n.mesh, cut);
    place_in_needle_frame(n.mesh, std::optional<Vec3>(Vec3{0.0, 0.0, -1.0}));
    std::ostringstream note;
    note << (n.frame_note.empty() ? "" : n.frame_note + "; ") << "a holder begins "
         << format_quantity(jump->height_m, Dimension::Length) << " above the tip (its outline "
         << std::setprecision(3) << jump->holder_outline_m2 / jump->needle_outline_m2
         << "x the needle's): the needle is the part below it";
    n.frame_note = note.str();
  }
  // A width far outside what microneedles measure is usually a unit mistake (a file in um read
  // as mm is 1000x too wide; in mm read as um, 1000x too narrow): say so, do not guess.
  const BoundingBox box = bounding_box(n.mesh);
  const double width = std::max(box.max[0] - box.min[0], box.max[1] - box.min[1]);
  if (width < kSmallestWidth_m || width > kLargestWidth_m) {
    n.frame_note += std::string(n.frame_note.empty() ? "" : "; ") + "warning: the needle is " +
                    format_quantity(width, Dimension::Length) +
                    " wide: is the file's length unit right (--unit, or unit = in the scene)?";
  }
  return n;
}

NeedleSource needle_from_plugin(const PluginRegistry& registry, const std::string& shape,
                                const std::map<std::string, double>& params_si) {
  NeedleSource n;
  n.name = shape;
  n.plugin = shape;
  const auto& info = registry.shape(shape);
  const std::vector<double> values = registry.resolve_parameters(shape, params_si);
  for (std::size_t i = 0; i < info.parameters.size(); ++i)
    n.params[info.parameters[i].name] = values[i];
  n.mesh = registry.generate(shape, n.params);
  return n;
}

NeedleSource needle_from_scene(const PluginRegistry& registry, const NeedleSpec& spec,
                               const std::string& where) {
  // The scene parser cannot check a plugin's parameters or read a mesh (it knows no registry),
  // so their errors are raised here and carry the scene's file and line like the parser's.
  try {
    if (const auto* stl = std::get_if<StlGeometry>(&spec.geometry)) {
      NeedleSource n = needle_from_file(stl->path, stl->unit_scale, parse_axis_choice(stl->axis));
      n.name = spec.name;
      return n;
    }
    const auto& plugin = std::get<PluginGeometry>(spec.geometry);
    const auto& info = registry.shape(plugin.plugin);
    NeedleSource n = needle_from_plugin(registry, plugin.plugin,
                                        scene_parameters(info, plugin.parameters, "geometry"));
    n.name = spec.name;
    return n;
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
}

std::string scene_needle_where(const Scene& scene, const NeedleSpec& spec) {
  return scene.source_name + ":" + std::to_string(spec.line) + ": needle '" + spec.name + "'";
}

std::optional<fe::AxisymmetricNeedle> axisymmetric_profile(const PluginRegistry& registry,
                                                           const NeedleSource& needle,
                                                           const std::string& where) {
  if (!needle.plugin || (*needle.plugin != "cylinder" && *needle.plugin != "cone"))
    return std::nullopt;
  const std::map<std::string, double>& p = needle.params;
  const double radius = 0.5 * p.at("diameter");
  const double bore = p.count("bore") ? 0.5 * p.at("bore") : 0.0;
  if (*needle.plugin == "cylinder") {
    const double edge = p.count("edge_radius") ? p.at("edge_radius") : 0.0;
    if (!(edge > 0.0)) return fe::AxisymmetricNeedle::flat_punch(radius, bore);
    // A rounded rim: the flat out to R - rho, then the quarter circle, sampled densely towards
    // the flat where the radius grows as sqrt(2 rho h), from the plugin's own section.
    fe::AxisymmetricNeedle profile;
    profile.bore_radius_m = bore;
    constexpr int kRimSamples = 48;
    for (int k = 0; k <= kRimSamples; ++k) {
      const double f = static_cast<double>(k) / kRimSamples;
      const double h = edge * f * f;
      const std::optional<double> area = registry.section_area(*needle.plugin, p, h);
      if (!area) throw InputError(where + ": the cylinder plugin gives no section area");
      const double r = std::sqrt(std::max(*area / M_PI + bore * bore, 0.0));
      profile.heights_m.push_back(h);
      profile.radii_m.push_back(
          std::max({r, profile.radii_m.empty() ? 0.0 : profile.radii_m.back(), bore}));
    }
    return profile;
  }
  // Cone: sample the section so that a rounded tip (tip_radius) is followed too.
  const double length = p.at("length");
  const double taper = (radius - bore) / std::tan(p.at("half_angle"));
  const double top = std::min(length, 1.05 * taper);
  fe::AxisymmetricNeedle profile;
  profile.bore_radius_m = bore;
  constexpr int kSamples = 200;
  std::vector<double> heights;
  for (int i = 0; i <= kSamples; ++i) heights.push_back(top * i / kSamples);
  // A rounded point (tip_radius rho) is a cap rho (1 - sin a) tall, often below one sample
  // spacing (2.3 um for the default cone): 32 more samples, denser towards the point where the
  // radius grows as sqrt(2 rho h), follow it up to twice its height.
  const double cap = p.count("tip_radius") ? p.at("tip_radius") : 0.0;
  if (cap > 0.0) {
    const double cap_height = cap * (1.0 - std::sin(p.at("half_angle")));
    for (int k = 1; k <= 32; ++k) {
      const double f = k / 32.0;
      const double h = 2.0 * cap_height * f * f;
      if (h < top) heights.push_back(h);
    }
    std::sort(heights.begin(), heights.end());
    heights.erase(std::unique(heights.begin(), heights.end()), heights.end());
  }
  for (const double h : heights) {
    const std::optional<double> area = registry.section_area(*needle.plugin, p, h);
    if (!area) throw InputError(where + ": the cone plugin gives no section area");
    const double r = std::sqrt(std::max(*area / M_PI + bore * bore, 0.0));
    const double previous = profile.radii_m.empty() ? 0.0 : profile.radii_m.back();
    profile.heights_m.push_back(h);
    profile.radii_m.push_back(std::max({r, previous, bore}));
  }
  return profile;
}

namespace {

// True when the image of every vertex under `mirror` (componentwise sign) is a vertex.
bool maps_onto_itself(const TriangleMesh& mesh, const Vec3& mirror) {
  if (mesh.vertices.empty()) return false;
  const BoundingBox box = bounding_box(mesh);
  const double size =
      std::hypot(box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]);
  const double tol = 1e-6 * size;
  std::vector<Vec3> sorted = mesh.vertices;
  std::sort(sorted.begin(), sorted.end());
  for (const Vec3& v : mesh.vertices) {
    const Vec3 m{mirror[0] * v[0], mirror[1] * v[1], mirror[2] * v[2]};
    // Candidates share x within the tolerance: scan that slice of the sorted list.
    auto it = std::lower_bound(sorted.begin(), sorted.end(), Vec3{m[0] - tol, -1e300, -1e300});
    bool found = false;
    for (; it != sorted.end() && (*it)[0] <= m[0] + tol && !found; ++it)
      found = std::abs((*it)[1] - m[1]) <= tol && std::abs((*it)[2] - m[2]) <= tol;
    if (!found) return false;
  }
  return true;
}

}  // namespace

namespace {

// The largest angle between neighbouring directions (rad), all the way round; the sum of the
// sines of the angles between neighbours, which is 2 pi for a circle (the polygon's area is half
// of it times r^2).
struct Coverage {
  double gap = 2.0 * std::numbers::pi;
  double sine_sum = 0.0;
};

Coverage coverage(std::vector<double> angles) {
  Coverage c;
  if (angles.empty()) return c;
  std::sort(angles.begin(), angles.end());
  angles.push_back(angles.front() + 2.0 * std::numbers::pi);
  c.gap = 0.0;
  for (std::size_t i = 1; i < angles.size(); ++i) {
    c.gap = std::max(c.gap, angles[i] - angles[i - 1]);
    c.sine_sum += std::sin(angles[i] - angles[i - 1]);
  }
  return c;
}

// Twelve facets round give a gap of exactly pi / 6, which round-off puts on either side.
bool closes_round(const Coverage& c) {
  return c.gap <= kLargestRevolutionGap_rad * (1.0 + 1e-6);
}

}  // namespace

namespace {

struct Polar {
  double z, r, angle;
};

// One height's ring(s) of vertices off the axis: the outer radius (0 when none: a sharp point on
// the axis) and, for a hollow needle, the bore's, each the equal-area radius of its polygon.
struct Rings {
  double outer = 0.0;
  double bore = -1.0;  // < 0: no bore ring at this height
};

// The rings of the vertices [begin, end) (sorted by height), or nullopt when they are not one or
// two circles all the way round. Two circles are the bore and the outer ring (a hollow end).
std::optional<Rings> rings_of(const std::vector<Polar>& points, std::size_t begin, std::size_t end,
                              double tol) {
  std::vector<std::pair<double, std::vector<double>>> circles;  // radius, angles
  for (std::size_t i = begin; i < end; ++i) {
    if (points[i].r <= tol) continue;
    auto it = std::find_if(circles.begin(), circles.end(),
                           [&](const auto& c) { return std::abs(points[i].r - c.first) <= tol; });
    if (it == circles.end()) {
      if (circles.size() == 2) return std::nullopt;  // three radii: stepped
      circles.push_back({points[i].r, {}});
      it = circles.end() - 1;
    }
    it->second.push_back(points[i].angle);
  }
  std::sort(circles.begin(), circles.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<double> radii;
  for (const auto& [radius, angles] : circles) {
    const Coverage c = coverage(angles);
    if (!closes_round(c)) return std::nullopt;
    radii.push_back(radius * std::sqrt(c.sine_sum / (2.0 * std::numbers::pi)));
  }
  Rings r;
  if (radii.size() == 1) r.outer = radii[0];
  if (radii.size() == 2) r.bore = radii[0], r.outer = radii[1];
  return r;
}

}  // namespace

std::optional<fe::AxisymmetricNeedle> revolution_profile(const TriangleMesh& mesh) {
  if (mesh.vertices.empty() || mesh.triangles.empty()) return std::nullopt;
  const BoundingBox box = bounding_box(mesh);
  const double length = box.max[2] - box.min[2];
  double widest = 0.0;
  for (const Vec3& v : mesh.vertices) widest = std::max(widest, std::hypot(v[0], v[1]));
  if (!(length > 0.0) || !(widest > 0.0)) return std::nullopt;
  // 1e-4 of the needle's size: far above the single precision an STL was written in (even far
  // from its file's origin), far below any feature a design has. Heights closer than that are
  // one ring unless they hold two radii that lie further apart than kFineHeight of the size
  // (rings a rounded rim puts within 0.05 um of its flat): those are split at that finer scale,
  // above an STL's single precision near its origin (a needle written far from its origin may
  // then stay 3-D, as before).
  const double size = std::max(widest, length);
  const double tol = 1e-4 * size;
  constexpr double kFineHeight = 1e-6;
  std::vector<Polar> points;
  for (const Vec3& v : mesh.vertices)
    points.push_back({v[2] - box.min[2], std::hypot(v[0], v[1]), std::atan2(v[1], v[0])});
  std::sort(points.begin(), points.end(), [](const Polar& a, const Polar& b) { return a.z < b.z; });
  // Each height's vertices off the axis: one radius (or the bore's and the outer one), all the
  // way round. Its section is the polygon through them, of area (r^2 / 2) sum sin(angle between
  // neighbours).
  std::vector<double> heights;
  std::vector<Rings> rings;
  for (std::size_t begin = 0; begin < points.size();) {
    std::size_t end = begin + 1;
    while (end < points.size() && points[end].z - points[begin].z <= tol) ++end;
    std::optional<Rings> group = rings_of(points, begin, end, tol);
    if (!group || group->bore >= 0.0) {
      // Two radii: a bore beside the outer ring, or rings at distinct heights closer than tol.
      std::vector<std::size_t> cuts{begin};
      for (std::size_t i = begin + 1; i < end; ++i)
        if (points[i].z - points[i - 1].z > kFineHeight * size) cuts.push_back(i);
      cuts.push_back(end);
      if (cuts.size() > 2) {
        for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
          const std::optional<Rings> part = rings_of(points, cuts[k], cuts[k + 1], tol);
          if (!part) return std::nullopt;
          heights.push_back(points[cuts[k]].z);
          rings.push_back(*part);
        }
        begin = end;
        continue;
      }
      if (!group) return std::nullopt;
    }
    heights.push_back(points[begin].z);
    rings.push_back(*group);
    begin = end;
  }
  // One bore for the whole needle: the rings that hold two radii agree on the inner one, and a
  // single ring of that radius above the lowest height is the bore alone (the outer profile has
  // no vertex there).
  double bore = -1.0;
  for (const Rings& r : rings)
    if (r.bore >= 0.0) {
      if (bore >= 0.0 && std::abs(r.bore - bore) > tol) return std::nullopt;
      bore = bore < 0.0 ? r.bore : bore;
    }
  std::vector<double> outer_heights, outer_radii;
  for (std::size_t k = 0; k < rings.size(); ++k) {
    const bool bore_only =
        bore >= 0.0 && rings[k].bore < 0.0 && k > 0 && std::abs(rings[k].outer - bore) <= tol;
    if (bore_only) continue;
    outer_heights.push_back(heights[k]);
    outer_radii.push_back(rings[k].outer);
  }
  // Between two heights the faces must close round the axis too, in one loop (two with a bore,
  // one of them the bore's circle): a square pyramid on a round shaft has round rings and square
  // sections, a sealed cavity two loops.
  std::optional<CrossSectionSlicer> slicer;
  try {
    slicer.emplace(mesh);
  } catch (const InputError&) {
    return std::nullopt;  // not a closed surface: the 3-D path says why
  }
  // A slice's points lie on the facets, between a polygon's inscribed and circumscribed circles.
  const double on_circle =
      2.0 * tol + std::max(bore, 0.0) * (1.0 - std::cos(0.5 * kLargestRevolutionGap_rad));
  for (std::size_t k = 0; k + 1 < heights.size(); ++k) {
    const CrossSection section = slicer->slice(0.5 * (heights[k] + heights[k + 1]));
    if (section.polygons.size() != (bore >= 0.0 ? 2u : 1u)) return std::nullopt;
    int on_bore = 0;  // loops on the bore's circle
    for (const auto& polygon : section.polygons) {
      std::vector<double> angles;
      bool round_bore = bore >= 0.0;
      for (const auto& p : polygon) {
        angles.push_back(std::atan2(p[1], p[0]));
        round_bore = round_bore && std::abs(std::hypot(p[0], p[1]) - bore) <= on_circle;
      }
      if (!closes_round(coverage(angles))) return std::nullopt;
      on_bore += round_bore ? 1 : 0;
    }
    if (bore >= 0.0 && on_bore == 0) return std::nullopt;
  }
  // The profile through the rings (the faces are straight between them), heights from the tip,
  // kept non-decreasing (a narrower section above a wider one never meets the tissue first); a
  // flat end (the widest section already at the tip) is a flat punch.
  fe::AxisymmetricNeedle profile;
  profile.bore_radius_m = std::max(bore, 0.0);
  double running = 0.0;
  for (std::size_t k = 0; k < outer_heights.size(); ++k) {
    running = std::max(running, outer_radii[k]);
    profile.heights_m.push_back(k == 0 ? 0.0 : outer_heights[k]);
    profile.radii_m.push_back(running);
  }
  if (!(profile.max_radius() > profile.bore_radius_m)) return std::nullopt;
  if (profile.radii_m.front() >= profile.max_radius() * (1.0 - 1e-6))
    return fe::AxisymmetricNeedle::flat_punch(profile.max_radius(), profile.bore_radius_m);
  return profile;
}

bool mirror_symmetric_y0(const TriangleMesh& mesh) {
  return maps_onto_itself(mesh, {1.0, -1.0, 1.0});
}

bool mirror_symmetric_x0(const TriangleMesh& mesh) {
  return maps_onto_itself(mesh, {-1.0, 1.0, 1.0});
}

NeedleSymmetry needle_symmetry(const PluginRegistry& registry, const NeedleSource& needle,
                               const std::string& where) {
  NeedleSymmetry s;
  // A plugin's exact profile where it has one, else the mesh's when it is round: an STL that
  // `generate` wrote from a plugin then takes the plugin's model (docs/model.md, "Scene
  // planner", round meshes).
  s.axisymmetric = axisymmetric_profile(registry, needle, where);
  if (!s.axisymmetric) s.axisymmetric = revolution_profile(needle.mesh);
  s.mirror_y0 = s.axisymmetric.has_value() || mirror_symmetric_y0(needle.mesh);
  s.mirror_x0 = mirror_symmetric_x0(needle.mesh);
  return s;
}

void apply_symmetry(const NeedleSymmetry& symmetry, PreparedNeedle& needle) {
  needle.axisymmetric = symmetry.axisymmetric;
  needle.mirror_symmetric_y0 = symmetry.mirror_y0;
  needle.mirror_symmetric_x0 = symmetry.mirror_x0;
}

bool needs_plugins(const Scene& scene) {
  return std::any_of(scene.needles.begin(), scene.needles.end(), [](const NeedleSpec& n) {
    return std::holds_alternative<PluginGeometry>(n.geometry);
  });
}

std::vector<PreparedNeedle> prepare_needles(const PluginRegistry& registry, const Scene& scene,
                                            std::size_t max_needles) {
  if (scene.needles.size() > max_needles)
    throw InputError(scene.source_name + ": needles: " + std::to_string(scene.needles.size()) +
                     " needles, above the limit of " + std::to_string(max_needles) +
                     " (raise it with --max-needles)");
  std::vector<PreparedNeedle> prepared;
  for (const NeedleSpec& spec : scene.needles) {
    const std::string where = scene_needle_where(scene, spec);
    NeedleSource source = needle_from_scene(registry, spec, where);
    PreparedNeedle n;
    n.name = spec.name;
    n.x = spec.at[0];
    n.y = spec.at[1];
    // The scene checks a length it is given (geometry.length); a plugin's default length or an
    // STL's is known only now. A needle shorter than the depth would be pushed on past its base
    // with the force of its last section.
    const BoundingBox box = bounding_box(source.mesh);
    const double length = box.max[2] - box.min[2];
    if (scene.insertion.depth >= length)
      throw InputError(where + ": the needle is " + format_quantity(length, Dimension::Length) +
                       " long (its mesh) and insertion.depth = " +
                       format_quantity(scene.insertion.depth, Dimension::Length) +
                       " would put its base into the tissue");
    apply_symmetry(needle_symmetry(registry, source, where), n);
    n.frame_note = source.frame_note;
    n.mesh = std::move(source.mesh);
    prepared.push_back(std::move(n));
  }
  return prepared;
}

}  // namespace mneedle
