#pragma once
// PRIVATE to mneedle::core: what a 3-D step writes for ParaView (docs/cli.md, "Fields"): the
// tissue with its fields, reflected back to the whole block when the model is a half or a
// quarter, and the needles' surfaces at the step's depth.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fe/vtu_writer.h"
#include "mneedle/fe/indentation3d.h"
#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::fe {

/// One step of the 3-D model as solved (the meshed part only).
struct TissueStep3d {
  const TetMesh* mesh = nullptr;
  Eigen::VectorXd u;                    ///< 3 per node, m
  Eigen::VectorXd internal_force;       ///< 3 per node, N: the needle's force at contact nodes
  std::vector<char> in_contact;         ///< per node: touched by a needle
  std::vector<Eigen::Matrix3d> stress;  ///< Cauchy, per element, Pa
  std::vector<double> energy_density;   ///< per element, J/m^3
};

/// The tissue file: point data displacement_m, contact_force_N, contact_traction_Pa,
/// contact_pressure_Pa; cell data von_mises_Pa, principal_stress_Pa (largest first),
/// energy_density_J_per_m3, layer; field data depth_m. A mirror-reduced mesh is reflected
/// across y = 0 and then x = 0, so the file always holds the whole block.
VtuFile tissue_vtu(const TissueStep3d& step, double depth_m);

/// Appends the mirror image across coordinate[axis] = 0: points off the plane doubled, cells
/// doubled with their orientation kept positive, the axis component of 3-vector point arrays
/// negated; at points on the plane the array named `plane_sum` (a nodal force, of which each
/// half carried half) is doubled and its axis component (the symmetry reaction) dropped, and
/// the axis component of every other 3-vector is set to 0. Returns each original point's image.
std::vector<std::int64_t> reflect_across(VtuFile& file, int axis, const std::string& plane_sum);

/// The needles' surfaces at `depth_m` (tip of needle i at (x_i, y_i, -depth)), triangles with
/// cell data `needle` (index in `needles`) and field data depth_m.
VtuFile needles_vtu(const std::vector<Needle3d>& needles, double depth_m);

}  // namespace mneedle::fe
