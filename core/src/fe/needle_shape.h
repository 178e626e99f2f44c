#pragma once
// PRIVATE to mneedle::core: point queries against a rigid needle mesh (CGAL lives in the .cpp).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "mneedle/needle/mesh.h"

namespace mneedle::fe {

/// A closed needle surface in the needle frame (tip at the origin, body along +z).
class NeedleShape {
 public:
  /// Throws InputError when the mesh is empty or not closed; an inward-oriented mesh is flipped.
  explicit NeedleShape(const TriangleMesh& mesh);
  ~NeedleShape();
  NeedleShape(NeedleShape&&) noexcept;
  NeedleShape& operator=(NeedleShape&&) noexcept;

  /// Inside or on the needle surface (point in the needle frame).
  bool contains(const Eigen::Vector3d& point) const;
  /// contains(), or the point a relative 10⁻⁶ of its radius outside the surface: a grid node put
  /// on the wall at a bevel's tip, where rounding alone would decide the side.
  bool touches(const Eigen::Vector3d& point) const;
  /// Nearest point of the needle surface (needle frame), found through an AABB tree of the faces.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& point) const;
  /// The same, and the outward unit normal of the face that holds it.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& point, Eigen::Vector3d* face_normal) const;
  /// Where the vertical line through `point` (inside the needle) leaves the needle downward:
  /// the face that reached the point as the needle moved along -z. Falls back to the closest
  /// surface point when that face is vertical or the ray grazes an edge.
  Eigen::Vector3d lower_surface_below(const Eigen::Vector3d& point) const;
  /// Where sticking contact holds a tissue node found inside the needle at `point` that crossed
  /// the surface at `entered` (both in the needle frame; docs/model.md, "Contact with the rigid
  /// needle (sticking)"): lower_surface_below(point), the face that swept over it, unless that
  /// lies more than `tolerance` (m) farther than the nearest face, as for a node that entered a
  /// wall sideways; then the surface point nearest to `entered`.
  Eigen::Vector3d sticking_anchor(const Eigen::Vector3d& point, const Eigen::Vector3d& entered,
                                  double tolerance) const;
  /// First crossing of the vertical ray from `point` (down or up) with the surface: the point
  /// and the outward normal of its face. False when the ray misses the needle.
  bool vertical_hit(const Eigen::Vector3d& point, bool downward, Eigen::Vector3d* hit,
                    Eigen::Vector3d* face_normal) const;
  /// Largest distance from the needle axis of the faces that reach below `height` above the tip.
  double max_radius_up_to(double height) const;
  /// True when the mirror image (x, -y, z) of every vertex lies on the surface within
  /// `tolerance` (m): the needle is symmetric about its y = 0 plane.
  bool mirror_symmetric_y(double tolerance) const;
  /// The same for the image (-x, y, z): symmetric about its x = 0 plane.
  bool mirror_symmetric_x(double tolerance) const;
  /// Mean (x, y) of the lowest vertices (within `tolerance` of the lowest z): where the needle
  /// first touches a flat surface, needle frame.
  Eigen::Vector2d first_contact_xy(double tolerance) const;
  /// Convex hull (x, y) of the same lowest vertices, counter-clockwise, needle frame: one point
  /// for a pointed tip, a polygon for a flat end.
  std::vector<Eigen::Vector2d> first_contact_outline(double tolerance) const;
  /// True when some face has all three corners within `tolerance` of the lowest z: the first
  /// contact is a flat. A rounded point or a knife edge has none.
  bool first_contact_has_a_face(double tolerance) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mneedle::fe
