// GCC 12 at -O2/-O3 flags boost::graph edge descriptors copied inside CGAL's slicer as "maybe
// uninitialized" (a false positive in library code). It must be silenced before any include so
// it covers the instantiation sites in the standard headers.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "mneedle/geometry/cross_section.h"

#include <CGAL/Polygon_mesh_slicer.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "needle/cgal_mesh.h"

namespace mneedle {
namespace {

using Slicer = CGAL::Polygon_mesh_slicer<SurfaceMesh, CgalKernel>;
using Polyline = std::vector<CgalPoint>;

double shoelace_area(const std::vector<Point2>& loop) {
  double twice = 0.0;
  for (std::size_t i = 0, n = loop.size(); i < n; ++i) {
    const Point2& p = loop[i];
    const Point2& q = loop[(i + 1) % n];
    twice += p[0] * q[1] - q[0] * p[1];
  }
  return 0.5 * twice;
}

// Even-odd ray casting; section loops never cross, so one vertex decides for the whole loop.
bool contains(const std::vector<Point2>& loop, const Point2& p) {
  bool inside = false;
  for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const Point2& a = loop[i];
    const Point2& b = loop[j];
    if ((a[1] > p[1]) != (b[1] > p[1]) &&
        p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]) {
      inside = !inside;
    }
  }
  return inside;
}

std::vector<Point2> to_loop(const Polyline& polyline) {
  std::vector<Point2> loop;
  loop.reserve(polyline.size());
  for (const CgalPoint& p : polyline) loop.push_back({p.x(), p.y()});
  // A closed polyline repeats its first point at the end.
  if (loop.size() > 1 && loop.front() == loop.back()) loop.pop_back();
  return loop;
}

double lowest_z(const TriangleMesh& mesh) {
  double z = std::numeric_limits<double>::infinity();
  for (const Vec3& p : mesh.vertices) z = std::min(z, p[2]);
  return mesh.vertices.empty() ? 0.0 : z;
}

}  // namespace

int nested_loop_sign(const std::vector<std::vector<Point2>>& polygons, std::size_t i) {
  if (polygons[i].size() < 3) return 0;
  int depth = 0;
  for (std::size_t j = 0; j < polygons.size(); ++j) {
    if (j != i && polygons[j].size() >= 3 && contains(polygons[j], polygons[i].front())) ++depth;
  }
  return depth % 2 == 0 ? 1 : -1;
}

double outline_area(const std::vector<std::vector<Point2>>& polygons) {
  std::vector<CgalKernel::Point_2> points;
  for (const auto& loop : polygons)
    for (const Point2& p : loop) points.emplace_back(p[0], p[1]);
  if (points.size() < 3) return 0.0;
  std::vector<CgalKernel::Point_2> hull;
  CGAL::convex_hull_2(points.begin(), points.end(), std::back_inserter(hull));
  std::vector<Point2> loop;
  for (const auto& p : hull) loop.push_back({p.x(), p.y()});
  return std::abs(shoelace_area(loop));
}

namespace {

double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double length2 = ux * ux + uy * uy;
  double t = length2 > 0.0 ? ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p[0] - a[0] - t * ux, p[1] - a[1] - t * uy);
}

// Smallest distance from the points of `from` to the edges of `to`.
double loop_distance(const std::vector<Point2>& from, const std::vector<Point2>& to) {
  double d = std::numeric_limits<double>::infinity();
  for (const Point2& p : from)
    for (std::size_t i = 0, n = to.size(); i < n; ++i)
      d = std::min(d, segment_distance(p, to[i], to[(i + 1) % n]));
  return d;
}

}  // namespace

double thinnest_wall(const std::vector<std::vector<Point2>>& polygons) {
  double wall = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < polygons.size(); ++i) {
    if (nested_loop_sign(polygons, i) != 1) continue;
    bool hollow = false;
    for (std::size_t j = 0; j < polygons.size(); ++j) {
      if (j == i || nested_loop_sign(polygons, j) != -1 ||
          !contains(polygons[i], polygons[j].front()))
        continue;
      hollow = true;
      wall = std::min(
          {wall, loop_distance(polygons[j], polygons[i]), loop_distance(polygons[i], polygons[j])});
    }
    if (!hollow) {
      // A solid section: from its area centroid to the nearest edge (the inradius of a convex
      // section about its centre).
      const auto& loop = polygons[i];
      double cx = 0.0, cy = 0.0, twice = 0.0;
      for (std::size_t k = 0, n = loop.size(); k < n; ++k) {
        const Point2& p = loop[k];
        const Point2& q = loop[(k + 1) % n];
        const double c = p[0] * q[1] - q[0] * p[1];
        twice += c;
        cx += (p[0] + q[0]) * c;
        cy += (p[1] + q[1]) * c;
      }
      if (twice == 0.0) continue;
      wall = std::min(wall, loop_distance({{cx / (3.0 * twice), cy / (3.0 * twice)}}, loop));
    }
  }
  return std::isfinite(wall) ? wall : 0.0;
}

double nested_polygon_area(const std::vector<std::vector<Point2>>& polygons) {
  double area = 0.0;
  for (std::size_t i = 0; i < polygons.size(); ++i)
    area += nested_loop_sign(polygons, i) * std::abs(shoelace_area(polygons[i]));
  return area;
}

struct CrossSectionSlicer::Impl {
  explicit Impl(const TriangleMesh& mesh)
      : surface(to_surface_mesh(mesh)), slicer(surface), tip_z(lowest_z(mesh)) {}
  SurfaceMesh surface;
  Slicer slicer;
  double tip_z;
};

CrossSectionSlicer::CrossSectionSlicer(const TriangleMesh& mesh)
    : impl_(std::make_unique<Impl>(mesh)) {}
CrossSectionSlicer::~CrossSectionSlicer() = default;
CrossSectionSlicer::CrossSectionSlicer(CrossSectionSlicer&&) noexcept = default;
CrossSectionSlicer& CrossSectionSlicer::operator=(CrossSectionSlicer&&) noexcept = default;

CrossSection CrossSectionSlicer::slice(double height_m) const {
  CrossSection section;
  section.height_m = height_m;
  std::vector<Polyline> polylines;
  const double z = impl_->tip_z + height_m;
  impl_->slicer(CgalKernel::Plane_3(0.0, 0.0, 1.0, -z), std::back_inserter(polylines));
  for (const Polyline& polyline : polylines) {
    std::vector<Point2> loop = to_loop(polyline);
    if (loop.size() >= 3) section.polygons.push_back(std::move(loop));
  }
  section.area_m2 = nested_polygon_area(section.polygons);
  section.outline_area_m2 = outline_area(section.polygons);
  return section;
}

CrossSection cross_section(const TriangleMesh& mesh, double height_m) {
  return CrossSectionSlicer(mesh).slice(height_m);
}

}  // namespace mneedle
