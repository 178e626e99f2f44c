#pragma once
// PRIVATE to mneedle::core: point queries against a rigid needle mesh (CGAL lives in the .cpp).

#include <Eigen/Core>
#include <memory>

#include "mneedle/mesh.h"

namespace mneedle::fe {

/// A closed needle surface in the needle frame (tip at the origin, body along +z).
class NeedleShape {
 public:
  /// Throws InputError when the mesh is empty or not closed.
  explicit NeedleShape(const TriangleMesh& mesh);
  ~NeedleShape();
  NeedleShape(NeedleShape&&) noexcept;
  NeedleShape& operator=(NeedleShape&&) noexcept;

  /// Inside or on the needle surface (point in the needle frame).
  bool contains(const Eigen::Vector3d& point) const;
  /// Nearest point of the needle surface (needle frame), found through an AABB tree of the faces.
  Eigen::Vector3d closest_point(const Eigen::Vector3d& point) const;
  /// Where the vertical line through `point` (inside the needle) leaves the needle downward:
  /// the face that reached the point as the needle moved along -z. Falls back to the closest
  /// surface point when that face is vertical or the ray grazes an edge.
  Eigen::Vector3d lower_surface_below(const Eigen::Vector3d& point) const;
  /// Largest distance from the needle axis of the faces that reach below `height` above the tip.
  double max_radius_up_to(double height) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mneedle::fe
