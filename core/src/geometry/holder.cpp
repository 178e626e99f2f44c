#include "mneedle/geometry/holder.h"

#include <CGAL/Polygon_mesh_processing/clip.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "mneedle/base/error.h"
#include "mneedle/geometry/cross_section.h"
#include "needle/cgal_mesh.h"

namespace mneedle {
namespace {

constexpr int kSamples = 400;
constexpr int kSkipNearTip = 3;  // a tip's area grows steeply over its first samples

double lowest_z(const TriangleMesh& mesh) {
  double z = std::numeric_limits<double>::infinity();
  for (const Vec3& p : mesh.vertices) z = std::min(z, p[2]);
  return z;
}

double highest_z(const TriangleMesh& mesh) {
  double z = -std::numeric_limits<double>::infinity();
  for (const Vec3& p : mesh.vertices) z = std::max(z, p[2]);
  return z;
}

}  // namespace

std::optional<HolderJump> find_holder_jump(const TriangleMesh& mesh, double ratio) {
  if (mesh.vertices.empty()) return std::nullopt;
  const double bottom = lowest_z(mesh);
  const double height = highest_z(mesh) - bottom;
  if (!(height > 0.0)) return std::nullopt;
  const CrossSectionSlicer slicer(mesh);
  const double step = height / kSamples;
  const auto outline = [&](double h) { return slicer.slice(h).outline_area_m2; };
  double previous = outline(step * kSkipNearTip);
  for (int i = kSkipNearTip + 1; i < kSamples; ++i) {
    const double current = outline(step * i);
    if (previous > 0.0 && current >= ratio * previous) {
      // Bisect the step: the lowest height whose outline is above the geometric middle.
      const double threshold = std::sqrt(previous * current);
      double lo = step * (i - 1), hi = step * i;
      for (int k = 0; k < 40 && hi - lo > 1e-9 * height; ++k) {
        const double mid = 0.5 * (lo + hi);
        (outline(mid) >= threshold ? hi : lo) = mid;
      }
      return HolderJump{hi, previous, current, height};
    }
    previous = current;
  }
  return std::nullopt;
}

TriangleMesh cut_above(const TriangleMesh& mesh, double height_m) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  SurfaceMesh surface = to_surface_mesh(mesh);
  const double z = lowest_z(mesh) + height_m;
  // Keeps the side opposite the plane's normal (+z): everything below the cut, capped.
  PMP::clip(surface, CgalKernel::Plane_3(0.0, 0.0, 1.0, -z), CGAL::parameters::clip_volume(true));
  surface.collect_garbage();
  TriangleMesh out = from_surface_mesh(surface);
  if (out.triangles.empty() || !CGAL::is_closed(surface)) {
    throw InputError("cutting the needle from its holder at " + std::to_string(height_m * 1e6) +
                     " um above the tip left no closed needle");
  }
  return out;
}

}  // namespace mneedle
