#pragma once
// The stress puncture criterion's measure: the maximum principal stress in one layer near a
// point, averaged over a material length so that it converges under a sharp tip where the
// pointwise stress is singular.

#include <Eigen/Core>

#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::fe {

/// Volume-weighted mean of the maximum principal Cauchy stress (Pa) over the part of `layer`
/// within `length_m` of `point_m` (reference coordinates), at nodal displacement `u` (3 per node,
/// m). Returns 0 when no part of the layer is within reach.
double averaged_max_principal_stress(const TetMesh& mesh, const Eigen::VectorXd& u,
                                     const Eigen::Vector3d& point_m, double length_m, int layer);

}  // namespace mneedle::fe
