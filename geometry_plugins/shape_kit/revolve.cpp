#include <cmath>
#include <numbers>

#include "shape_kit.h"

namespace mneedle::shape_kit {

namespace {

double profile_extent(const std::vector<ProfilePoint>& loop) {
  double extent = 0;
  for (const auto& p : loop) extent = std::max({extent, std::abs(p.r), std::abs(p.z)});
  return extent;
}

}  // namespace

MeshBuilder build_revolved(const std::vector<ProfilePoint>& loop, int segments) {
  if (loop.size() < 3) throw std::invalid_argument("a revolved profile needs three points");
  if (segments < 3) throw ParameterError("resolution must be at least 3 segments");
  for (const auto& p : loop) {
    if (!(p.r >= 0) || !std::isfinite(p.z)) throw std::invalid_argument("bad profile point");
  }
  MeshBuilder mesh(1e-9 * profile_extent(loop));
  // Corners by index so that the last segment closes on exactly the first angle.
  std::vector<double> cosines(segments), sines(segments);
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * std::numbers::pi * i / segments;
    cosines[i] = std::cos(a);
    sines[i] = std::sin(a);
  }
  const auto at = [&](ProfilePoint p, int i) {
    return Point3{p.r * cosines[i % segments], p.r * sines[i % segments], p.z};
  };
  for (std::size_t j = 0; j < loop.size(); ++j) {
    const ProfilePoint p = loop[j], q = loop[(j + 1) % loop.size()];
    for (int i = 0; i < segments; ++i) {
      mesh.add_triangle(at(p, i), at(q, i), at(q, i + 1));
      mesh.add_triangle(at(p, i), at(q, i + 1), at(p, i + 1));
    }
  }
  if (mesh.signed_volume() < 0) mesh.flip();
  return mesh;
}

}  // namespace mneedle::shape_kit
