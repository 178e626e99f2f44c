#include "mneedle/geometry/footprint.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <iterator>
#include <limits>

namespace mneedle {
namespace {

using Kernel = CGAL::Epick;
using CgalPoint2 = Kernel::Point_2;

double lowest_z(const TriangleMesh& mesh) {
  double z = std::numeric_limits<double>::infinity();
  for (const Vec3& p : mesh.vertices) z = std::min(z, p[2]);
  return z;
}

void add_edge_crossing(const Vec3& a, const Vec3& b, double plane_z,
                       std::vector<CgalPoint2>& points) {
  if ((a[2] < plane_z) == (b[2] < plane_z) || a[2] == b[2]) return;
  const double t = (plane_z - a[2]) / (b[2] - a[2]);
  points.emplace_back(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
}

std::vector<CgalPoint2> submerged_points(const TriangleMesh& mesh, double plane_z) {
  std::vector<CgalPoint2> points;
  for (const Vec3& p : mesh.vertices) {
    if (p[2] <= plane_z) points.emplace_back(p[0], p[1]);
  }
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      add_edge_crossing(mesh.vertices[t[k]], mesh.vertices[t[(k + 1) % 3]], plane_z, points);
    }
  }
  return points;
}

double polygon_area(const std::vector<Point2>& loop) {
  double twice = 0.0;
  for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
    twice += loop[i][0] * loop[(i + 1) % n][1] - loop[(i + 1) % n][0] * loop[i][1];
  }
  return 0.5 * twice;
}

}  // namespace

Footprint footprint(const TriangleMesh& mesh, double depth_m) {
  Footprint result;
  result.depth_m = depth_m;
  if (mesh.vertices.empty() || !(depth_m >= 0.0)) return result;
  const std::vector<CgalPoint2> points = submerged_points(mesh, lowest_z(mesh) + depth_m);
  std::vector<CgalPoint2> hull;
  CGAL::convex_hull_2(points.begin(), points.end(), std::back_inserter(hull));
  for (const CgalPoint2& p : hull) result.hull.push_back({p.x(), p.y()});
  result.area_m2 = result.hull.size() >= 3 ? polygon_area(result.hull) : 0.0;
  return result;
}

}  // namespace mneedle
