// Structured graded 6-node triangle mesh of a layered tissue cylinder, and the rigid needle's
// profile of revolution.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/fe/axisymmetric.h"

namespace mneedle::fe {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Points a..b, n equal intervals.
void append_uniform(std::vector<double>& points, double a, double b, int n) {
  for (int i = 1; i <= n; ++i) points.push_back(a + (b - a) * i / n);
}

int uniform_count(double length, double h, int minimum) {
  return std::max(minimum, static_cast<int>(std::ceil(length / h - 1e-9)));
}

// Points after a, up to b, whose spacing starts at h and grows by `growth` (capped); the last
// interval absorbs the remainder so the sequence ends exactly at b. Returns the next spacing.
double append_graded(std::vector<double>& points, double a, double b, double h, double growth,
                     double h_max, int minimum) {
  std::vector<double> steps;
  double sum = 0.0;
  while (sum + h < (b - a) * (1.0 - 1e-9)) {
    steps.push_back(h);
    sum += h;
    h = std::min(h * growth, h_max);
  }
  const double rest = (b - a) - sum;
  if (steps.empty() || rest > 0.5 * h)
    steps.push_back(rest);
  else
    steps.back() += rest;
  if (static_cast<int>(steps.size()) < minimum) {
    append_uniform(points, a, b, minimum);
    return std::min(h, (b - a) / minimum * growth);
  }
  double x = a;
  for (double s : steps) points.push_back(x += s);
  points.back() = b;
  return h;
}

// Offsets from a band's edge across a segment `length` long: cells from `band` growing by
// `growth` while below h, then equal cells of at most h for the rest (so the far end has the
// mesh's own size, not a remainder). Ends at `length`.
std::vector<double> band_offsets(double length, double band, double h, double growth) {
  std::vector<double> x;
  double at = 0.0, cell = band;
  while (cell < h && at + cell < length * (1.0 - 1e-9)) {
    x.push_back(at += cell);
    cell *= growth;
  }
  const double rest = length - at;
  if (rest > 1e-9 * length) {
    const int n = uniform_count(rest, h, 1);
    for (int i = 1; i <= n; ++i) x.push_back(at + rest * i / n);
  }
  x.back() = length;
  return x;
}

std::vector<double> radial_grid(const AxisymmetricMeshOptions& o) {
  const double fine = std::min(o.fine_radius_m, o.radius_m);
  std::vector<double> breaks{0.0, fine};
  for (double r : o.radial_breaks_m)
    if (r > 0.0 && r < fine) breaks.push_back(r);
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end(),
                           [](double x, double y) { return std::abs(x - y) < 1e-12; }),
               breaks.end());
  std::vector<double> r{0.0};
  const bool band = o.band_size_m > 0.0 && o.band_size_m < o.h_m;
  auto at_band = [&](double x) { return band && std::abs(x - o.band_radius_m) < 1e-12; };
  for (std::size_t i = 1; i < breaks.size(); ++i) {
    const double a = breaks[i - 1], b = breaks[i];
    if (at_band(a)) {  // from the band outward: band_size_m growing to h_m
      for (double x : band_offsets(b - a, o.band_size_m, o.h_m, o.growth)) r.push_back(a + x);
    } else if (at_band(b)) {  // towards the band: the same grading, mirrored
      const std::vector<double> x = band_offsets(b - a, o.band_size_m, o.h_m, o.growth);
      for (std::size_t k = x.size() - 1; k-- > 0;) r.push_back(b - x[k]);
      r.push_back(b);
    } else {
      append_uniform(r, a, b, uniform_count(b - a, o.h_m, 1));
    }
  }
  if (fine < o.radius_m) append_graded(r, fine, o.radius_m, o.h_m, o.growth, o.max_size_m, 1);
  return r;
}

// Depth below the surface (s = -z) of every node row, surface first. Depth breaks split a
// layer into segments meshed like layers; a segment needs its share of the layer's minimum.
std::vector<double> depth_grid(const std::vector<AxisymmetricLayer>& layers,
                               const AxisymmetricMeshOptions& o) {
  std::vector<double> s{0.0};
  double top = 0.0;
  double h = o.h_m;
  for (std::size_t k = 0; k < layers.size(); ++k) {
    const double layer_top = top, layer_bottom = top + layers[k].thickness_m;
    const int layer_minimum = k == 0 && o.elements_through_top > 0
                                  ? std::max(o.elements_through_top, 1)
                                  : o.min_elements_per_layer;
    std::vector<double> ends;
    for (double b : o.depth_breaks_m)
      if (b > layer_top + 1e-9 * layers[k].thickness_m &&
          b < layer_bottom - 1e-9 * layers[k].thickness_m)
        ends.push_back(b);
    std::sort(ends.begin(), ends.end());
    ends.push_back(layer_bottom);
    for (double bottom : ends) {
      const double fraction = (bottom - top) / layers[k].thickness_m;
      const int minimum = std::max(1, static_cast<int>(std::ceil(layer_minimum * fraction - 1e-9)));
      // A fine-zone end within round-off of a segment's end (a depth break computed as 2a where
      // the fine zone ends at a + a) would leave a row of zero height.
      double fine_end = std::clamp(o.fine_depth_m, top, bottom);
      const double snap = 1e-9 * (bottom - top);
      if (bottom - fine_end <= snap) fine_end = bottom;
      if (fine_end - top <= snap) fine_end = top;
      // The band's rows: band_size_m apart down to band_depth_m, then grading to h_m.
      const bool band = o.band_size_m > 0.0 && o.band_size_m < o.h_m && o.band_depth_m > top;
      if (fine_end > top && band) {
        const double band_end = std::min(o.band_depth_m, fine_end);
        append_uniform(
            s, top, band_end,
            uniform_count(band_end - top, o.band_size_m, fine_end >= bottom ? minimum : 1));
        h = o.band_size_m;
        if (fine_end > band_end) h = append_graded(s, band_end, fine_end, h, o.growth, o.h_m, 1);
      } else if (fine_end > top) {
        const bool whole = fine_end >= bottom;
        append_uniform(s, top, fine_end, uniform_count(fine_end - top, o.h_m, whole ? minimum : 1));
        h = o.h_m;
      }
      if (fine_end < bottom)
        h = append_graded(s, fine_end, bottom, h, o.growth, o.max_size_m,
                          fine_end > top ? 1 : minimum);
      top = bottom;
    }
  }
  return s;
}

void require(bool condition, const std::string& message) {
  if (!condition) throw InputError("axisymmetric mesh: " + message);
}

void measure_quality(AxisymmetricMesh& mesh) {
  double min_angle = 180.0, max_aspect = 0.0;
  for (const auto& e : mesh.elements) {
    const Eigen::Vector2d p[3] = {mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]]};
    const double twice_area =
        (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    double longest = 0.0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
      const double angle = std::acos(std::clamp(a.dot(b) / (a.norm() * b.norm()), -1.0, 1.0));
      min_angle = std::min(min_angle, angle * 180.0 / kPi);
      longest = std::max(longest, a.norm());
    }
    max_aspect = std::max(max_aspect, longest * longest / twice_area);
  }
  mesh.min_angle_deg = min_angle;
  mesh.max_aspect_ratio = max_aspect;
}

}  // namespace

AxisymmetricNeedle AxisymmetricNeedle::flat_punch(double radius_m, double bore_radius_m) {
  require(radius_m > 0.0 && bore_radius_m >= 0.0 && bore_radius_m < radius_m,
          "flat punch needs 0 <= bore radius < radius");
  return AxisymmetricNeedle{{0.0}, {radius_m}, bore_radius_m};
}

AxisymmetricNeedle AxisymmetricNeedle::cone(double half_angle_rad, double base_radius_m,
                                            double bore_radius_m) {
  require(half_angle_rad > 0.0 && half_angle_rad < 0.5 * kPi,
          "cone half-angle must be in (0, 90) deg");
  require(base_radius_m > 0.0 && bore_radius_m >= 0.0 && bore_radius_m < base_radius_m,
          "cone needs 0 <= bore radius < base radius");
  // A hollow cone is a truncated cone whose tip ring is the bore.
  const double tip = bore_radius_m;
  const double height = (base_radius_m - tip) / std::tan(half_angle_rad);
  return AxisymmetricNeedle{{0.0, height}, {tip, base_radius_m}, bore_radius_m};
}

double AxisymmetricNeedle::max_radius() const {
  return radii_m.empty() ? 0.0 : *std::max_element(radii_m.begin(), radii_m.end());
}

double AxisymmetricNeedle::lowest_height_at(double r) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double tolerance = 1e-9 * max_radius();
  if (radii_m.empty() || r > max_radius() + tolerance) return kInf;
  if (bore_radius_m > 0.0 && r < bore_radius_m - tolerance) return kInf;
  if (r <= radii_m.front() + tolerance) return 0.0;
  for (std::size_t i = 1; i < radii_m.size(); ++i) {
    if (r <= radii_m[i] + tolerance) {
      const double span = radii_m[i] - radii_m[i - 1];
      const double t = span > 0.0 ? std::clamp((r - radii_m[i - 1]) / span, 0.0, 1.0) : 0.0;
      return heights_m[i - 1] + t * (heights_m[i] - heights_m[i - 1]);
    }
  }
  return kInf;
}

AxisymmetricMesh make_axisymmetric_mesh(const std::vector<AxisymmetricLayer>& layers,
                                        const AxisymmetricMeshOptions& o) {
  require(!layers.empty(), "no layers");
  for (const AxisymmetricLayer& l : layers) require(l.thickness_m > 0.0, "layer thickness <= 0");
  require(o.radius_m > 0.0, "cylinder radius must be > 0");
  require(o.h_m > 0.0 && o.h_m <= o.radius_m, "element size must be in (0, radius]");
  require(o.growth >= 1.0, "growth ratio must be >= 1");

  const std::vector<double> r = radial_grid(o);
  const std::vector<double> s = depth_grid(layers, o);
  const int nr = static_cast<int>(r.size()), nz = static_cast<int>(s.size());
  // Node grid at half steps: even indices are corners, odd ones mid-edges and cell centres.
  const int cols = 2 * nr - 1, rows = 2 * nz - 1;
  auto coordinate = [](const std::vector<double>& g, int i) {
    return i % 2 == 0 ? g[i / 2] : 0.5 * (g[i / 2] + g[i / 2 + 1]);
  };
  AxisymmetricMesh mesh;
  mesh.nodes.reserve(static_cast<std::size_t>(cols) * rows);
  // Row index j counts from the bottom so that (r, z) cells are counter-clockwise.
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i)
      mesh.nodes.emplace_back(coordinate(r, i), -coordinate(s, rows - 1 - j));
  auto id = [cols](int i, int j) { return static_cast<std::uint32_t>(j * cols + i); };

  std::vector<double> layer_bottom;
  double depth = 0.0;
  for (const AxisymmetricLayer& l : layers) layer_bottom.push_back(depth += l.thickness_m);
  for (int cj = 0; cj < nz - 1; ++cj) {
    const double centre_depth = -mesh.nodes[id(0, 2 * cj + 1)].y();
    const int layer =
        static_cast<int>(std::lower_bound(layer_bottom.begin(), layer_bottom.end(), centre_depth) -
                         layer_bottom.begin());
    for (int ci = 0; ci < nr - 1; ++ci) {
      const int i = 2 * ci, j = 2 * cj;
      const std::uint32_t A = id(i, j), B = id(i + 2, j), C = id(i + 2, j + 2), D = id(i, j + 2);
      const std::uint32_t AB = id(i + 1, j), BC = id(i + 2, j + 1), CD = id(i + 1, j + 2),
                          DA = id(i, j + 1), M = id(i + 1, j + 1);
      // Alternate diagonals so the mesh has no preferred direction.
      if ((ci + cj) % 2 == 0) {
        mesh.elements.push_back({A, B, C, AB, BC, M});
        mesh.elements.push_back({A, C, D, M, CD, DA});
      } else {
        mesh.elements.push_back({A, B, D, AB, M, DA});
        mesh.elements.push_back({B, C, D, BC, CD, M});
      }
      mesh.element_layer.push_back(std::min<int>(layer, static_cast<int>(layers.size()) - 1));
      mesh.element_layer.push_back(mesh.element_layer.back());
    }
  }
  for (int i = 0; i < cols; ++i) mesh.surface_nodes.push_back(id(i, rows - 1));
  for (int j = 0; j < rows; ++j) mesh.axis_nodes.push_back(id(0, j));
  for (int i = 0; i < cols; ++i) mesh.fixed_nodes.push_back(id(i, 0));
  for (int j = 1; j < rows; ++j) mesh.fixed_nodes.push_back(id(cols - 1, j));
  measure_quality(mesh);
  return mesh;
}

double equal_area_radius(double width_m) {
  return width_m / std::sqrt(kPi);
}

}  // namespace mneedle::fe
