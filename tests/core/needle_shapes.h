#pragma once
// Test helper: closed, outward-oriented needle meshes in the needle frame (tip lowest, body
// toward +z) built by hand, so the surface-load tests do not depend on the geometry plugins.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <vector>

#include "mneedle/needle/mesh.h"

namespace mneedle::test {

struct ShapeOptions {
  double radius = 115e-6;
  double bore = 0.0;  ///< bore radius, 0 for a solid needle
  double length = 1000e-6;
  int segments = 64;  ///< around the axis
  int rings = 8;      ///< axial subdivisions of the walls
};

namespace detail {

inline std::uint32_t add_vertex(TriangleMesh& m, double x, double y, double z) {
  m.vertices.push_back({x, y, z});
  return static_cast<std::uint32_t>(m.vertices.size() - 1);
}

// A wall of columns at the given angles from z = bottom(x, y) to the top; rings axial steps.
// Returns the column vertex indices [column][ring]. inward flips the faces (a bore).
inline std::vector<std::vector<std::uint32_t>> add_wall(
    TriangleMesh& m, const std::vector<double>& angles, double radius, double top, int rings,
    const std::function<double(double, double)>& bottom, bool inward) {
  std::vector<std::vector<std::uint32_t>> column(angles.size());
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double x = radius * std::cos(angles[i]);
    const double y = radius * std::sin(angles[i]);
    const double z0 = bottom(x, y);
    for (int k = 0; k <= rings; ++k) {
      column[i].push_back(add_vertex(m, x, y, z0 + (top - z0) * k / rings));
    }
  }
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const auto& a = column[i];
    const auto& b = column[(i + 1) % angles.size()];
    for (int k = 0; k < rings; ++k) {
      if (!inward) {
        m.triangles.push_back({a[k], b[k], b[k + 1]});
        m.triangles.push_back({a[k], b[k + 1], a[k + 1]});
      } else {
        m.triangles.push_back({a[k], b[k + 1], b[k]});
        m.triangles.push_back({a[k], a[k + 1], b[k + 1]});
      }
    }
  }
  return column;
}

// Fan of a planar convex loop from its centroid; down = the face looks toward -z.
inline void add_fan(TriangleMesh& m, const std::vector<std::uint32_t>& loop, bool down) {
  double c[3] = {0, 0, 0};
  for (auto v : loop) {
    for (int k = 0; k < 3; ++k) c[k] += m.vertices[v][k] / static_cast<double>(loop.size());
  }
  const auto centre = add_vertex(m, c[0], c[1], c[2]);
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const auto cur = loop[i];
    const auto next = loop[(i + 1) % loop.size()];
    if (down) {
      m.triangles.push_back({centre, next, cur});
    } else {
      m.triangles.push_back({centre, cur, next});
    }
  }
}

// Strip between an outer and an inner loop of equal length (an annulus).
inline void add_annulus(TriangleMesh& m, const std::vector<std::uint32_t>& outer,
                        const std::vector<std::uint32_t>& inner, bool down) {
  for (std::size_t i = 0; i < outer.size(); ++i) {
    const std::size_t j = (i + 1) % outer.size();
    if (down) {
      m.triangles.push_back({outer[i], inner[j], outer[j]});
      m.triangles.push_back({outer[i], inner[i], inner[j]});
    } else {
      m.triangles.push_back({outer[i], outer[j], inner[j]});
      m.triangles.push_back({outer[i], inner[j], inner[i]});
    }
  }
}

inline std::vector<double> even_angles(int n) {
  std::vector<double> angles;
  for (int i = 0; i < n; ++i) angles.push_back(-std::numbers::pi + 2.0 * std::numbers::pi * i / n);
  return angles;
}

inline std::vector<std::uint32_t> ring(const std::vector<std::vector<std::uint32_t>>& column,
                                       std::size_t level) {
  std::vector<std::uint32_t> r;
  for (const auto& c : column) r.push_back(c[std::min(level, c.size() - 1)]);
  return r;
}

// A straight column needle whose bottom is the plane z = bottom(x, y) (flat or bevel).
inline TriangleMesh columnar(const ShapeOptions& o,
                             const std::function<double(double, double)>& bottom) {
  TriangleMesh m;
  const auto angles = even_angles(o.segments);
  const auto outer = add_wall(m, angles, o.radius, o.length, o.rings, bottom, false);
  if (o.bore > 0.0) {
    const auto inner = add_wall(m, angles, o.bore, o.length, o.rings, bottom, true);
    add_annulus(m, ring(outer, 0), ring(inner, 0), true);
    add_annulus(m, ring(outer, o.rings), ring(inner, o.rings), false);
  } else {
    add_fan(m, ring(outer, 0), true);
    add_fan(m, ring(outer, o.rings), false);
  }
  return m;
}

}  // namespace detail

/// Flat-ended cylinder, end face at z = 0.
inline TriangleMesh cylinder(const ShapeOptions& o) {
  return detail::columnar(o, [](double, double) { return 0.0; });
}

/// Sharp bevel: the plane z = (R - x) / tan(theta), theta the bevel angle to the axis, tip at x =
/// R.
inline TriangleMesh sharp_bevel(const ShapeOptions& o, double bevel_angle) {
  const double r = o.radius;
  const double t = std::tan(bevel_angle);
  return detail::columnar(o, [r, t](double x, double) { return (r - x) / t; });
}

/// Blunt bevel (solid): the sharp bevel truncated by a flat z = 0 of sagitta w (x >= R - w).
inline TriangleMesh blunt_bevel(const ShapeOptions& o, double bevel_angle, double flat_width) {
  using namespace detail;
  TriangleMesh m;
  const double r = o.radius;
  const double crease = r - flat_width;
  const double t = std::tan(bevel_angle);
  auto angles = even_angles(o.segments);
  const double phi_c = std::acos(crease / r);
  std::erase_if(angles, [&](double a) { return std::abs(std::abs(a) - phi_c) < 1e-9; });
  angles.push_back(phi_c);
  angles.push_back(-phi_c);
  std::sort(angles.begin(), angles.end());
  auto bottom = [crease, t](double x, double) { return std::max(0.0, (crease - x) / t); };
  const auto outer = add_wall(m, angles, r, o.length, o.rings, bottom, false);
  std::vector<std::uint32_t> flat;
  std::vector<std::uint32_t> bevel_tail;
  std::vector<std::uint32_t> bevel_head;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double a = angles[i];
    if (std::abs(a) <= phi_c + 1e-12) flat.push_back(outer[i][0]);
    if (a >= phi_c - 1e-12) bevel_head.push_back(outer[i][0]);
    if (a <= -phi_c + 1e-12) bevel_tail.push_back(outer[i][0]);
  }
  bevel_head.insert(bevel_head.end(), bevel_tail.begin(), bevel_tail.end());
  add_fan(m, flat, true);
  add_fan(m, bevel_head, true);
  add_fan(m, ring(outer, o.rings), false);
  return m;
}

/// Cone of half-angle alpha from an apex at the origin up to the shaft radius, then the shaft.
/// cone_rings subdivide the slope.
inline TriangleMesh cone(const ShapeOptions& o, double half_angle, int cone_rings = 4) {
  using detail::add_vertex;
  TriangleMesh m;
  const auto angles = detail::even_angles(o.segments);
  const double cone_height = o.radius / std::tan(half_angle);
  std::vector<std::pair<double, double>> profile;  // (radius, z), apex excluded
  for (int k = 1; k <= cone_rings; ++k) {
    profile.push_back({o.radius * k / cone_rings, cone_height * k / cone_rings});
  }
  for (int k = 1; k <= o.rings; ++k) {
    profile.push_back({o.radius, cone_height + (o.length - cone_height) * k / o.rings});
  }
  const auto apex = add_vertex(m, 0.0, 0.0, 0.0);
  std::vector<std::vector<std::uint32_t>> rings;
  for (const auto& [radius, z] : profile) {
    std::vector<std::uint32_t> r;
    for (double a : angles)
      r.push_back(add_vertex(m, radius * std::cos(a), radius * std::sin(a), z));
    rings.push_back(r);
  }
  const std::size_t n = angles.size();
  for (std::size_t i = 0; i < n; ++i) {
    m.triangles.push_back({apex, rings[0][(i + 1) % n], rings[0][i]});
  }
  for (std::size_t k = 0; k + 1 < rings.size(); ++k) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      m.triangles.push_back({rings[k][i], rings[k][j], rings[k + 1][j]});
      m.triangles.push_back({rings[k][i], rings[k + 1][j], rings[k + 1][i]});
    }
  }
  detail::add_fan(m, rings.back(), false);
  return m;
}

/// Rotates about a unit axis by an angle (Rodrigues) then translates: a rigid motion.
inline Vec3 rigid_motion(const Vec3& p, const Vec3& axis, double angle, const Vec3& shift) {
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  const double k_dot_p = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
  const Vec3 k_cross_p{axis[1] * p[2] - axis[2] * p[1], axis[2] * p[0] - axis[0] * p[2],
                       axis[0] * p[1] - axis[1] * p[0]};
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    out[i] = p[i] * c + k_cross_p[i] * s + axis[i] * k_dot_p * (1.0 - c) + shift[i];
  }
  return out;
}

inline TriangleMesh moved(TriangleMesh m, const Vec3& axis, double angle, const Vec3& shift) {
  for (Vec3& p : m.vertices) p = rigid_motion(p, axis, angle, shift);
  return m;
}

}  // namespace mneedle::test
