#pragma once
// What the two plane-strain models (the slit opened by a needle, docs/model.md "The plane-strain
// crack", and the insertion along a cut, "Plane-strain insertion") share: the bilinear rectangle
// of a tensor-product grid and the geometric grading of that grid away from the needle.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mneedle::fe {

/// A number as the models' error messages print it (default stream format).
std::string str(double v);

/// Stiffness of a bilinear rectangle hx x hy (m), plane strain, per metre out of plane, with
/// selective reduced integration: the shear part at 2 x 2 Gauss points, the volumetric part at
/// the centre, so that nu near 0.5 does not lock. Node order (0,0), (hx,0), (hx,hy), (0,hy);
/// dofs u_x, u_y per node.
Eigen::Matrix<double, 8, 8> plane_strain_rectangle_stiffness(double hx, double hy, double E,
                                                             double nu);

/// Appends the points after `a` up to and including `b`: spacings start at h and grow by the
/// ratio g; the last interval absorbs the remainder (merged into the previous one when it is
/// under half a spacing).
void append_graded(std::vector<double>& points, double a, double b, double h, double g);

/// Number of intervals of a geometric sequence (first h, ratio g > 1) that covers `length`: an
/// upper bound on what append_graded adds, for counting a mesh before it is built.
double graded_count(double length, double h, double g);

}  // namespace mneedle::fe
