#include <algorithm>
#include <cmath>
#include <numbers>

#include "shape_kit.h"

namespace mneedle::shape_kit {

namespace {

struct PlanePoint {
  double x, y;
};

// Polygon corner angles: uniform ones plus every angle where a crease line meets the outer
// or bore circle, so that crease lines cross the polygons only at corners.
std::vector<double> corner_angles(const CutPrism& prism) {
  const double step = 2 * std::numbers::pi / prism.segments;
  std::vector<double> crease_angles;
  for (const double c : prism.creases_x_m) {
    for (const double r : {prism.outer_radius_m, prism.bore_radius_m}) {
      if (r > 0 && std::abs(c) < r) {
        const double a = std::acos(c / r);
        crease_angles.push_back(a);
        crease_angles.push_back(2 * std::numbers::pi - a);
      }
    }
  }
  // Uniform corners too close to a crease corner would make slivers: the crease wins.
  const double min_gap = 1e-3 * step;
  std::vector<double> angles = crease_angles;
  for (int i = 0; i < prism.segments; ++i) {
    const double a = i * step;
    const bool near_crease = std::any_of(crease_angles.begin(), crease_angles.end(), [&](double c) {
      return std::abs(c - a) < min_gap || std::abs(c - a - 2 * std::numbers::pi) < min_gap;
    });
    if (!near_crease) angles.push_back(a);
  }
  std::sort(angles.begin(), angles.end());
  angles.erase(std::unique(angles.begin(), angles.end(),
                           [&](double a, double b) { return b - a < min_gap; }),
               angles.end());
  return angles;
}

// Points of one spoke from the bore (or the axis) out to the rim, with a point wherever a
// crease line crosses it strictly inside.
std::vector<PlanePoint> spoke(const CutPrism& prism, double angle, double tolerance) {
  const double c = std::cos(angle), s = std::sin(angle);
  const PlanePoint inner{prism.bore_radius_m * c, prism.bore_radius_m * s};
  const PlanePoint outer{prism.outer_radius_m * c, prism.outer_radius_m * s};
  std::vector<double> ts;
  const double dx = outer.x - inner.x;
  for (const double crease : prism.creases_x_m) {
    if (std::abs(dx) <= tolerance) continue;
    const double t = (crease - inner.x) / dx;
    if (t * std::abs(dx) > tolerance && (1 - t) * std::abs(dx) > tolerance) ts.push_back(t);
  }
  std::sort(ts.begin(), ts.end());
  std::vector<PlanePoint> points{inner};
  for (const double t : ts) points.push_back({inner.x + t * dx, inner.y + t * (outer.y - inner.y)});
  points.push_back(outer);
  return points;
}

double signed_area(const std::vector<PlanePoint>& polygon) {
  double twice = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const auto& a = polygon[i];
    const auto& b = polygon[(i + 1) % polygon.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return twice / 2;
}

// Splits convex pieces along x = crease. Crease lines cross piece boundaries only at
// corners (see corner_angles and spoke), so each side is the corners on that side.
std::vector<std::vector<PlanePoint>> split_at_creases(std::vector<PlanePoint> cell,
                                                      const std::vector<double>& creases,
                                                      double tolerance) {
  std::vector<std::vector<PlanePoint>> pieces{std::move(cell)};
  for (const double crease : creases) {
    std::vector<std::vector<PlanePoint>> next;
    for (const auto& piece : pieces) {
      std::vector<PlanePoint> low, high;
      for (const auto& p : piece) {
        if (p.x <= crease + tolerance) low.push_back(p);
        if (p.x >= crease - tolerance) high.push_back(p);
      }
      for (auto* side : {&low, &high}) {
        if (side->size() >= 3 && std::abs(signed_area(*side)) > tolerance * tolerance) {
          next.push_back(std::move(*side));
        }
      }
    }
    pieces = std::move(next);
  }
  return pieces;
}

void add_cell_caps(MeshBuilder& mesh, const CutPrism& prism, const std::vector<PlanePoint>& cell,
                   double tolerance) {
  for (const auto& piece : split_at_creases(cell, prism.creases_x_m, tolerance)) {
    std::vector<Point3> top, bottom;
    for (const auto& p : piece) top.push_back({p.x, p.y, prism.top_z_m});
    // The bottom faces -z: its corners run the other way round.
    for (auto it = piece.rbegin(); it != piece.rend(); ++it) {
      bottom.push_back({it->x, it->y, prism.bottom_z_m(it->x)});
    }
    mesh.add_convex_polygon(top);
    mesh.add_convex_polygon(bottom);
  }
}

void add_wall(MeshBuilder& mesh, const CutPrism& prism, PlanePoint a, PlanePoint b, bool outward) {
  const Point3 a_low{a.x, a.y, prism.bottom_z_m(a.x)}, b_low{b.x, b.y, prism.bottom_z_m(b.x)};
  const Point3 a_high{a.x, a.y, prism.top_z_m}, b_high{b.x, b.y, prism.top_z_m};
  if (outward) {
    mesh.add_convex_polygon({a_low, b_low, b_high, a_high});
  } else {
    mesh.add_convex_polygon({b_low, a_low, a_high, b_high});
  }
}

void check_prism(const CutPrism& prism) {
  if (!(prism.outer_radius_m > 0)) throw ParameterError("outer radius must be positive");
  if (prism.bore_radius_m < 0 || prism.bore_radius_m >= prism.outer_radius_m) {
    throw ParameterError("bore must be smaller than the diameter");
  }
  if (prism.segments < 3) throw ParameterError("resolution must be at least 3 segments");
  for (const double x : {-prism.outer_radius_m, prism.outer_radius_m}) {
    if (!(prism.bottom_z_m(x) < prism.top_z_m)) {
      throw ParameterError("the tip is longer than the needle: increase length");
    }
  }
}

}  // namespace

MeshBuilder build_cut_prism(const CutPrism& prism) {
  check_prism(prism);
  const double tolerance = 1e-9 * prism.outer_radius_m;
  MeshBuilder mesh(tolerance);
  const auto angles = corner_angles(prism);
  std::vector<std::vector<PlanePoint>> spokes;
  for (const double a : angles) spokes.push_back(spoke(prism, a, tolerance));
  for (std::size_t k = 0; k < spokes.size(); ++k) {
    const auto& here = spokes[k];
    const auto& next = spokes[(k + 1) % spokes.size()];
    // Counter-clockwise cell: along the rim, in along the next spoke, out along this one.
    std::vector<PlanePoint> cell(next.rbegin(), next.rend());
    cell.insert(cell.begin(), here.back());
    cell.insert(cell.end(), here.begin(), here.end() - 1);
    add_cell_caps(mesh, prism, cell, tolerance);
    add_wall(mesh, prism, here.back(), next.back(), true);
    if (prism.bore_radius_m > 0) add_wall(mesh, prism, here.front(), next.front(), false);
  }
  return mesh;
}

}  // namespace mneedle::shape_kit
