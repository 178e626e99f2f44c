#include "mneedle/fe/stress_probe.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/fe/material.h"

namespace mneedle::fe {

namespace {

constexpr int kEdgeNodes[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
// Sub-tetrahedra cut by the averaging sphere are split into eight until they are this many
// levels deep (4096 pieces per element at most); the cut's volume error then falls as 8^-level.
constexpr int kMaxLevel = 4;

using Barycentric = Eigen::Vector4d;

// dN/dX at barycentric point `l` (TET4 or TET10, VTK node order) for an element whose reference
// geometry is affine (midside nodes at edge midpoints, as the tissue mesh makes them).
Eigen::MatrixXd shape_gradients(int node_count, const Barycentric& l,
                                const Eigen::Matrix3d& inverse_jacobian) {
  Eigen::MatrixXd by_barycentric = Eigen::MatrixXd::Zero(node_count, 4);
  if (node_count == 4) {
    by_barycentric.setIdentity();
  } else {
    for (int i = 0; i < 4; ++i) by_barycentric(i, i) = 4.0 * l(i) - 1.0;
    for (int e = 0; e < 6; ++e) {
      const int a = kEdgeNodes[e][0], b = kEdgeNodes[e][1];
      by_barycentric(4 + e, a) = 4.0 * l(b);
      by_barycentric(4 + e, b) = 4.0 * l(a);
    }
  }
  Eigen::Matrix<double, 4, 3> chain;
  chain << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return by_barycentric * chain * inverse_jacobian;
}

// One element of the layer: its corner geometry, displacement and material.
struct ElementField {
  std::array<Eigen::Vector3d, 4> corners;
  Eigen::Matrix3d inverse_jacobian;
  Eigen::MatrixXd displacement;  // node_count x 3
  const Material* material = nullptr;
  bool linear_kinematics = true;

  Eigen::Vector3d position(const Barycentric& l) const {
    return l(0) * corners[0] + l(1) * corners[1] + l(2) * corners[2] + l(3) * corners[3];
  }

  // Largest eigenvalue of the Cauchy stress; the linear law's stress is already Cauchy.
  double max_principal(const Barycentric& l) const {
    const Eigen::MatrixXd g =
        shape_gradients(static_cast<int>(displacement.rows()), l, inverse_jacobian);
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + displacement.transpose() * g;
    if (!linear_kinematics && !(F.determinant() > 0.0))
      throw SolverError("stress probe: inverted element (det F <= 0)");
    const Eigen::Matrix3d S = material->evaluate(F).S;
    const Eigen::Matrix3d sigma =
        linear_kinematics ? S : Eigen::Matrix3d(F * S * F.transpose() / F.determinant());
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(sigma, Eigen::EigenvaluesOnly)
        .eigenvalues()
        .maxCoeff();
  }
};

struct Accumulator {
  double stress_volume = 0.0;  // Pa m^3
  double volume = 0.0;         // m^3
};

double tet_volume(const std::array<Eigen::Vector3d, 4>& p) {
  return std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6.0;
}

// Integrates over a sub-tetrahedron (four barycentric corners) of the element: whole when it is
// inside the sphere, skipped when outside, split in eight when cut. The stress of a TET10 is
// linear in the element, so a 4-point rule per piece, and 1 point for a TET4, is enough.
void integrate(const ElementField& field, const std::array<Barycentric, 4>& sub,
               const Eigen::Vector3d& centre, double radius, int level, Accumulator* sum) {
  std::array<Eigen::Vector3d, 4> p;
  for (int i = 0; i < 4; ++i) p[static_cast<std::size_t>(i)] = field.position(sub[i]);
  const Eigen::Vector3d mid = 0.25 * (p[0] + p[1] + p[2] + p[3]);
  double reach = 0.0, farthest = 0.0;
  for (const auto& q : p) {
    reach = std::max(reach, (q - mid).norm());
    farthest = std::max(farthest, (q - centre).norm());
  }
  const double distance = (mid - centre).norm();
  if (distance - reach > radius) return;
  const double volume = tet_volume(p);
  const bool inside = farthest <= radius;
  if (!inside && level < kMaxLevel) {
    std::array<std::array<Barycentric, 4>, 8> children;
    const auto m = [&](int a, int b) { return Barycentric(0.5 * (sub[a] + sub[b])); };
    const Barycentric m01 = m(0, 1), m02 = m(0, 2), m03 = m(0, 3), m12 = m(1, 2), m13 = m(1, 3),
                      m23 = m(2, 3);
    children = {{{sub[0], m01, m02, m03},
                 {m01, sub[1], m12, m13},
                 {m02, m12, sub[2], m23},
                 {m03, m13, m23, sub[3]},
                 {m01, m02, m03, m13},
                 {m01, m02, m12, m13},
                 {m02, m03, m13, m23},
                 {m02, m12, m13, m23}}};
    for (const auto& child : children) integrate(field, child, centre, radius, level + 1, sum);
    return;
  }
  const Barycentric centroid = 0.25 * (sub[0] + sub[1] + sub[2] + sub[3]);
  if (!inside && (field.position(centroid) - centre).norm() > radius) return;
  if (field.displacement.rows() == 4) {
    sum->stress_volume += volume * field.max_principal(centroid);
  } else {
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    for (int i = 0; i < 4; ++i) {
      Barycentric weights = Barycentric::Constant(b);
      weights(i) = a;
      Barycentric l = Barycentric::Zero();
      for (int j = 0; j < 4; ++j) l += weights(j) * sub[static_cast<std::size_t>(j)];
      sum->stress_volume += 0.25 * volume * field.max_principal(l);
    }
  }
  sum->volume += volume;
}

}  // namespace

double averaged_max_principal_stress(const TetMesh& mesh, const Eigen::VectorXd& u,
                                     const Eigen::Vector3d& point_m, double length_m, int layer) {
  if (!(length_m > 0.0) || !std::isfinite(length_m))
    throw InputError("stress probe: averaging length must be positive and finite");
  if (layer < 0 || layer >= static_cast<int>(mesh.layers.size()))
    throw InputError("stress probe: layer index out of range");
  if (u.size() != 3 * static_cast<Eigen::Index>(mesh.nodes.size()))
    throw InputError("stress probe: displacement size does not match the mesh");
  // Same kinematics as the solid model: small strain only when every layer is linear, and a
  // linear layer in a nonlinear model is its St Venant-Kirchhoff extension.
  bool all_linear = true;
  for (const TissueLayer& l : mesh.layers)
    all_linear = all_linear && l.material.model == MaterialModel::Linear;
  MaterialParameters parameters = mesh.layers[static_cast<std::size_t>(layer)].material;
  if (!all_linear && parameters.model == MaterialModel::Linear)
    parameters.model = MaterialModel::StVenantKirchhoff;
  const Material material(parameters);

  const int n = mesh.nodes_per_element();
  const std::array<Barycentric, 4> whole = {Barycentric(1, 0, 0, 0), Barycentric(0, 1, 0, 0),
                                            Barycentric(0, 0, 1, 0), Barycentric(0, 0, 0, 1)};
  Accumulator sum;
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    if (mesh.element_layer[e] != layer) continue;
    const auto& element = mesh.elements[e];
    ElementField field;
    for (int i = 0; i < 4; ++i)
      field.corners[static_cast<std::size_t>(i)] = mesh.nodes[static_cast<std::size_t>(element[i])];
    // Cheap rejection before any per-element work.
    const Eigen::Vector3d mid =
        0.25 * (field.corners[0] + field.corners[1] + field.corners[2] + field.corners[3]);
    double reach = 0.0;
    for (const auto& q : field.corners) reach = std::max(reach, (q - mid).norm());
    if ((mid - point_m).norm() - reach > length_m) continue;
    Eigen::Matrix3d jacobian;
    for (int i = 0; i < 3; ++i) jacobian.col(i) = field.corners[i + 1] - field.corners[0];
    field.inverse_jacobian = jacobian.inverse();  // dX/dL_i = X_i - X_0 for L1..L3
    field.displacement.resize(n, 3);
    for (int a = 0; a < n; ++a)
      field.displacement.row(a) =
          u.segment<3>(3 * static_cast<Eigen::Index>(element[static_cast<std::size_t>(a)]))
              .transpose();
    field.material = &material;
    field.linear_kinematics = all_linear;
    integrate(field, whole, point_m, length_m, 0, &sum);
  }
  return sum.volume > 0.0 ? sum.stress_volume / sum.volume : 0.0;
}

}  // namespace mneedle::fe
