#pragma once
// Paper A's grouping of a needle's surface triangles by outward normal n against the insertion
// direction d (paper A section 3, Figs. 6-7): the shaft (Group 1), faces pushing into the tissue
// (Group 2, split into alpha flats and beta slopes) and faces looking back (Group 3).

#include <array>
#include <cstddef>
#include <string_view>
#include <vector>

#include "mneedle/needle/mesh.h"

namespace mneedle {

enum class SurfaceGroup : unsigned char {
  side,   ///< |n.d| <= sin(tol_side): the shaft, paper A's Group 1
  alpha,  ///< forward and |n x d| <= sin(tol_alpha): flats facing the tissue
  beta,   ///< forward, not alpha: cone slopes, bevel faces
  back,   ///< n.d < -sin(tol_side): faces looking back, paper A's Group 3
};

/// "side", "alpha", "beta", "back".
std::string_view group_name(SurfaceGroup group);

/// The insertion direction of the needle frame: the tip at the origin, the body along +z.
inline constexpr Vec3 kNeedleFrameInsertion{0.0, 0.0, -1.0};

/// Angular tolerances in radians. A face inclined at angle t to the needle axis has
/// n.d = sin t, so tol_side must stay below the half-angle of the slenderest cone that should
/// still count as beta: the 0.5 degree default keeps a 1 degree cone's slopes beta while an STL's
/// float noise (about 1e-7 rad) never moves a shaft face. A face exactly on a threshold goes to
/// side (resp. alpha): the tests use <=.
struct GroupTolerances {
  double side_rad = 0.5 * 3.14159265358979323846 / 180.0;
  double alpha_rad = 0.5 * 3.14159265358979323846 / 180.0;
};

struct GroupSummary {
  std::size_t count = 0;
  double area_m2 = 0.0;
};

struct SurfaceGroups {
  std::vector<SurfaceGroup> face_group;   ///< one per triangle, in mesh order
  std::array<GroupSummary, 4> summary{};  ///< indexed by SurfaceGroup

  const GroupSummary& of(SurfaceGroup group) const {
    return summary[static_cast<std::size_t>(group)];
  }
};

/// Group of one face from its unit outward normal and the unit insertion direction.
/// A zero normal (a degenerate face) is `side`: it carries no load.
SurfaceGroup classify_normal(const Vec3& unit_normal, const Vec3& unit_direction,
                             const GroupTolerances& tolerances = {});

/// Classifies every triangle of a closed, outward-oriented mesh. Throws InputError for a zero
/// direction or tolerances outside [0, 45) degrees. Moving the mesh and `direction` together by
/// any rigid motion leaves the result unchanged.
SurfaceGroups classify_surface(const TriangleMesh& mesh,
                               const Vec3& direction = kNeedleFrameInsertion,
                               const GroupTolerances& tolerances = {});

}  // namespace mneedle
