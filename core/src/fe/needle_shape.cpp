#include "fe/needle_shape.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "mneedle/base/error.h"
#include "needle/cgal_mesh.h"

namespace mneedle::fe {

namespace {
using Primitive = CGAL::AABB_face_graph_triangle_primitive<SurfaceMesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<CgalKernel, Primitive>>;
using Inside = CGAL::Side_of_triangle_mesh<SurfaceMesh, CgalKernel>;

CgalPoint to_cgal(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}
}  // namespace

struct NeedleShape::Impl {
  SurfaceMesh surface;
  std::optional<Tree> tree;
  std::optional<Inside> inside;
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
};

NeedleShape::NeedleShape(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.triangles.empty()) throw InputError("needle mesh: no triangles");
  impl_->surface = to_surface_mesh(mesh);
  if (!CGAL::is_closed(impl_->surface))
    throw InputError("needle mesh: surface is not closed (contact needs a solid needle)");
  // Frictionless contact pushes along the face normals: they must point out of the needle.
  if (!CGAL::Polygon_mesh_processing::is_outward_oriented(impl_->surface))
    CGAL::Polygon_mesh_processing::reverse_face_orientations(impl_->surface);
  impl_->tree.emplace(faces(impl_->surface).first, faces(impl_->surface).second, impl_->surface);
  impl_->tree->accelerate_distance_queries();
  impl_->inside.emplace(impl_->surface);
  for (const Vec3& v : mesh.vertices) impl_->vertices.emplace_back(v[0], v[1], v[2]);
  impl_->triangles = mesh.triangles;
}

NeedleShape::~NeedleShape() = default;
NeedleShape::NeedleShape(NeedleShape&&) noexcept = default;
NeedleShape& NeedleShape::operator=(NeedleShape&&) noexcept = default;

bool NeedleShape::contains(const Eigen::Vector3d& point) const {
  return (*impl_->inside)(to_cgal(point)) != CGAL::ON_UNBOUNDED_SIDE;
}

namespace {

std::optional<Eigen::Vector3d> point_below(const auto& tree, const Eigen::Vector3d& point) {
  const CgalKernel::Ray_3 down(to_cgal(point), CgalKernel::Direction_3(0, 0, -1));
  const auto hit = tree.first_intersection(down);
  if (hit)
    if (const CgalPoint* p = boost::get<CgalPoint>(&hit->first))
      return Eigen::Vector3d(p->x(), p->y(), p->z());
  return std::nullopt;
}

}  // namespace

namespace {

// The point moved a relative hair toward the needle axis.
Eigen::Vector3d toward_axis(Eigen::Vector3d point) {
  point.head<2>() *= 1.0 - 1e-6;
  return point;
}

}  // namespace

bool NeedleShape::touches(const Eigen::Vector3d& point) const {
  return contains(point) || contains(toward_axis(point));
}

Eigen::Vector3d NeedleShape::lower_surface_below(const Eigen::Vector3d& point) const {
  // The needle travels along -z, so a tissue point it reaches enters through the face below it.
  if (const auto hit = point_below(*impl_->tree, point)) return *hit;
  // A point on a vertical face (the grid node on the wall at a bevel's tip) sends the ray along
  // that face. A hair toward the axis the ray meets the face that swept the point: the tip.
  // Falling back to the point itself would hold the node where it was touched, a whole depth
  // step late, with no force.
  if (const auto hit = point_below(*impl_->tree, toward_axis(point))) return *hit;
  return closest_point(point);
}

Eigen::Vector3d NeedleShape::sticking_anchor(const Eigen::Vector3d& point,
                                             const Eigen::Vector3d& entered,
                                             double tolerance) const {
  // A node pressed sideways into the shaft above a bevel has the bevel face far below it:
  // holding it there would pull it down the whole height.
  const Eigen::Vector3d below = lower_surface_below(point);
  const double nearest = (closest_point(point) - point).norm();
  if ((below - point).norm() <= nearest + tolerance) return below;
  return closest_point(entered);
}

Eigen::Vector3d NeedleShape::closest_point(const Eigen::Vector3d& point) const {
  const CgalPoint q = impl_->tree->closest_point(to_cgal(point));
  return {q.x(), q.y(), q.z()};
}

Eigen::Vector3d NeedleShape::closest_point(const Eigen::Vector3d& point,
                                           Eigen::Vector3d* face_normal) const {
  const auto [q, face] = impl_->tree->closest_point_and_primitive(to_cgal(point));
  const auto n = CGAL::Polygon_mesh_processing::compute_face_normal(face, impl_->surface);
  *face_normal = Eigen::Vector3d(n.x(), n.y(), n.z()).normalized();
  return {q.x(), q.y(), q.z()};
}

bool NeedleShape::vertical_hit(const Eigen::Vector3d& point, bool downward, Eigen::Vector3d* hit,
                               Eigen::Vector3d* face_normal) const {
  const CgalKernel::Ray_3 ray(to_cgal(point), CgalKernel::Direction_3(0, 0, downward ? -1 : 1));
  const auto found = impl_->tree->first_intersection(ray);
  if (!found) return false;
  const CgalPoint* p = boost::get<CgalPoint>(&found->first);
  if (!p) return false;  // the ray runs along a vertical face: no crossing point
  *hit = {p->x(), p->y(), p->z()};
  const auto n = CGAL::Polygon_mesh_processing::compute_face_normal(found->second, impl_->surface);
  *face_normal = Eigen::Vector3d(n.x(), n.y(), n.z()).normalized();
  return true;
}

double NeedleShape::max_radius_up_to(double height) const {
  // Every triangle that reaches below `height` counts whole, so the radius is never
  // underestimated between two vertex rings.
  double radius = 0.0;
  for (const auto& t : impl_->triangles) {
    double lowest = std::numeric_limits<double>::max();
    for (auto v : t) lowest = std::min(lowest, impl_->vertices[v].z());
    if (lowest > height) continue;
    for (auto v : t) radius = std::max(radius, impl_->vertices[v].head<2>().norm());
  }
  return radius;
}

namespace {

bool maps_onto_itself(const NeedleShape& shape, const std::vector<Eigen::Vector3d>& vertices,
                      const Eigen::Vector3d& mirror, double tolerance) {
  for (const Eigen::Vector3d& v : vertices) {
    const Eigen::Vector3d image = v.cwiseProduct(mirror);
    if ((shape.closest_point(image) - image).norm() > tolerance) return false;
  }
  return true;
}

}  // namespace

bool NeedleShape::mirror_symmetric_y(double tolerance) const {
  return maps_onto_itself(*this, impl_->vertices, {1.0, -1.0, 1.0}, tolerance);
}

bool NeedleShape::mirror_symmetric_x(double tolerance) const {
  return maps_onto_itself(*this, impl_->vertices, {-1.0, 1.0, 1.0}, tolerance);
}

Eigen::Vector2d NeedleShape::first_contact_xy(double tolerance) const {
  double lowest = std::numeric_limits<double>::max();
  for (const Eigen::Vector3d& v : impl_->vertices) lowest = std::min(lowest, v.z());
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (const Eigen::Vector3d& v : impl_->vertices)
    if (v.z() <= lowest + tolerance) {
      sum += v.head<2>();
      ++count;
    }
  return sum / count;
}

std::vector<Eigen::Vector2d> NeedleShape::first_contact_outline(double tolerance) const {
  double lowest = std::numeric_limits<double>::max();
  for (const Eigen::Vector3d& v : impl_->vertices) lowest = std::min(lowest, v.z());
  std::vector<CgalKernel::Point_2> points;
  for (const Eigen::Vector3d& v : impl_->vertices)
    if (v.z() <= lowest + tolerance) points.emplace_back(v.x(), v.y());
  std::vector<CgalKernel::Point_2> hull;
  CGAL::convex_hull_2(points.begin(), points.end(), std::back_inserter(hull));
  std::vector<Eigen::Vector2d> outline;
  for (const auto& p : hull) outline.emplace_back(p.x(), p.y());
  return outline;
}

bool NeedleShape::first_contact_has_a_face(double tolerance) const {
  double lowest = std::numeric_limits<double>::max();
  for (const Eigen::Vector3d& v : impl_->vertices) lowest = std::min(lowest, v.z());
  for (const auto& t : impl_->triangles) {
    bool low = true;
    for (int i = 0; i < 3 && low; ++i)
      low = impl_->vertices[static_cast<std::size_t>(t[static_cast<std::size_t>(i)])].z() <=
            lowest + tolerance;
    if (low) return true;
  }
  return false;
}

}  // namespace mneedle::fe
