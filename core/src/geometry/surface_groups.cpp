#include "mneedle/geometry/surface_groups.h"

#include <cmath>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"
#include "needle/vec3_ops.h"

namespace mneedle {
namespace {

void check_tolerance(double value, const char* field) {
  if (!(value >= 0.0 && value < std::numbers::pi / 4.0)) {
    throw InputError(std::string("surface groups: ") + field + " = " + std::to_string(value) +
                     " rad is outside [0, pi/4)");
  }
}

Vec3 unit_direction_or_throw(const Vec3& direction) {
  const double length = vec3::norm(direction);
  if (!(length > 0.0) || !std::isfinite(length)) {
    throw InputError("surface groups: insertion direction must be a finite non-zero vector");
  }
  return vec3::scale(direction, 1.0 / length);
}

}  // namespace

std::string_view group_name(SurfaceGroup group) {
  switch (group) {
    case SurfaceGroup::side:
      return "side";
    case SurfaceGroup::alpha:
      return "alpha";
    case SurfaceGroup::beta:
      return "beta";
    case SurfaceGroup::back:
      return "back";
  }
  return "side";
}

SurfaceGroup classify_normal(const Vec3& unit_normal, const Vec3& unit_direction,
                             const GroupTolerances& tolerances) {
  const double along = vec3::dot(unit_normal, unit_direction);
  if (std::abs(along) <= std::sin(tolerances.side_rad)) return SurfaceGroup::side;
  if (along < 0.0) return SurfaceGroup::back;
  // |n x d| rather than sqrt(1 - (n.d)^2): it keeps its precision near parallel.
  const double across = vec3::norm(vec3::cross(unit_normal, unit_direction));
  return across <= std::sin(tolerances.alpha_rad) ? SurfaceGroup::alpha : SurfaceGroup::beta;
}

SurfaceGroups classify_surface(const TriangleMesh& mesh, const Vec3& direction,
                               const GroupTolerances& tolerances) {
  check_tolerance(tolerances.side_rad, "tol_side");
  check_tolerance(tolerances.alpha_rad, "tol_alpha");
  const Vec3 d = unit_direction_or_throw(direction);
  SurfaceGroups groups;
  groups.face_group.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3 twice_area_normal =
        vec3::cross(vec3::sub(mesh.vertices[t[1]], a), vec3::sub(mesh.vertices[t[2]], a));
    const SurfaceGroup group = classify_normal(vec3::normalized(twice_area_normal), d, tolerances);
    groups.face_group.push_back(group);
    GroupSummary& summary = groups.summary[static_cast<std::size_t>(group)];
    ++summary.count;
    summary.area_m2 += 0.5 * vec3::norm(twice_area_normal);
  }
  return groups;
}

}  // namespace mneedle
