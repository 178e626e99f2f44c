#pragma once
// Closed, outward-oriented needle meshes for the 3-D contact tests and benchmarks (needle frame:
// tip at the origin, body along +z), built here so the tests do not depend on the plugins.

#include <cmath>
#include <cstdint>
#include <numbers>

#include "mneedle/needle/mesh.h"

namespace mneedle::test {

/// Rings of (radius, z) from the tip upward, closed by a flat cap at each end (a ring of radius 0
/// is a single apex vertex).
inline TriangleMesh revolved_needle(const std::vector<std::array<double, 2>>& rings, int segments) {
  TriangleMesh mesh;
  std::vector<std::uint32_t> first;  // first vertex of each ring
  for (const auto& [radius, z] : rings) {
    first.push_back(static_cast<std::uint32_t>(mesh.vertices.size()));
    const int count = radius == 0.0 ? 1 : segments;
    for (int k = 0; k < count; ++k) {
      const double angle = 2.0 * std::numbers::pi * k / segments;
      mesh.vertices.push_back({radius * std::cos(angle), radius * std::sin(angle), z});
    }
  }
  auto vertex = [&](std::size_t ring, int k) -> std::uint32_t {
    if (rings[ring][0] == 0.0) return first[ring];
    return first[ring] + static_cast<std::uint32_t>(k % segments);
  };
  auto cap = [&](std::size_t ring, bool bottom) {
    if (rings[ring][0] == 0.0) return;
    const auto centre = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.push_back({0.0, 0.0, rings[ring][1]});
    for (int k = 0; k < segments; ++k)
      mesh.triangles.push_back(bottom ? Triangle{centre, vertex(ring, k + 1), vertex(ring, k)}
                                      : Triangle{centre, vertex(ring, k), vertex(ring, k + 1)});
  };
  cap(0, true);
  for (std::size_t r = 0; r + 1 < rings.size(); ++r)
    for (int k = 0; k < segments; ++k) {
      const auto a = vertex(r, k), b = vertex(r, k + 1), c = vertex(r + 1, k),
                 d = vertex(r + 1, k + 1);
      if (a != b) mesh.triangles.push_back({a, b, d});
      if (c != d) mesh.triangles.push_back({a, d, c});
    }
  cap(rings.size() - 1, false);
  return mesh;
}

/// Flat-ended cylinder (rigid flat punch) of radius `radius` and length `length` (m).
inline TriangleMesh cylinder_needle(double radius, double length, int segments = 48) {
  return revolved_needle({{radius, 0.0}, {radius, length}}, segments);
}

/// Cone with half-angle `half_angle` (rad) up to radius `radius`, then a cylinder to `length`.
inline TriangleMesh cone_needle(double half_angle, double radius, double length,
                                int segments = 48) {
  const double cone_height = radius / std::tan(half_angle);
  std::vector<std::array<double, 2>> rings{{0.0, 0.0}};
  for (int k = 1; k <= 8; ++k) rings.push_back({radius * k / 8.0, cone_height * k / 8.0});
  rings.push_back({radius, std::max(length, 1.01 * cone_height)});
  return revolved_needle(rings, segments);
}

/// Sharp bevel: a cylinder of radius `radius` cut by a plane through the tip at angle
/// `bevel_angle` (rad) to the axis; vertices on `segments` generators, closed by a top cap.
inline TriangleMesh bevel_needle(double radius, double bevel_angle, double length,
                                 int segments = 48) {
  TriangleMesh mesh;
  const double slope = 1.0 / std::tan(bevel_angle);  // bevel height gained per unit of x
  // Bevel face z = (x + radius) * slope: zero at the tip (x = -radius).
  const auto n = static_cast<std::uint32_t>(segments);
  for (int k = 0; k < segments; ++k) {
    const double angle = 2.0 * std::numbers::pi * k / segments;
    const double x = radius * std::cos(angle), y = radius * std::sin(angle);
    mesh.vertices.push_back({x, y, (x + radius) * slope});
  }
  for (int k = 0; k < segments; ++k) {
    const double angle = 2.0 * std::numbers::pi * k / segments;
    mesh.vertices.push_back({radius * std::cos(angle), radius * std::sin(angle), length});
  }
  const auto bevel_centre = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.push_back({0.0, 0.0, radius * slope});
  const auto top_centre = bevel_centre + 1;
  mesh.vertices.push_back({0.0, 0.0, length});
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t k1 = (k + 1) % n;
    mesh.triangles.push_back({bevel_centre, k1, k});
    mesh.triangles.push_back({k, k1, n + k1});
    mesh.triangles.push_back({k, n + k1, n + k});
    mesh.triangles.push_back({top_centre, n + k, n + k1});
  }
  return mesh;
}

}  // namespace mneedle::test
