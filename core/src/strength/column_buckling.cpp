#include "mneedle/strength/column_buckling.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

// 4-point Gauss–Legendre on [0, 1]: exact for the degree-6 integrand of a quartic EI(h).
constexpr std::array<double, 4> kGaussX = {0.0694318442029737, 0.3300094782075719,
                                           0.6699905217924281, 0.9305681557970263};
constexpr std::array<double, 4> kGaussW = {0.1739274225687269, 0.3260725774312731,
                                           0.3260725774312731, 0.1739274225687269};

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

// Second derivatives of the cubic Hermite functions (w1, θ1, w2, θ2) at ξ, element length l.
Vec4 hermite_curvature(double xi, double l) {
  return {(12 * xi - 6) / (l * l), (6 * xi - 4) / l, (-12 * xi + 6) / (l * l), (6 * xi - 2) / l};
}

// First derivatives (slopes) of the same functions.
Vec4 hermite_slope(double xi, double l) {
  return {(6 * xi * xi - 6 * xi) / l, 3 * xi * xi - 4 * xi + 1, (-6 * xi * xi + 6 * xi) / l,
          3 * xi * xi - 2 * xi};
}

void element_matrices(const std::function<double(double)>& ei, double h0, double l, Mat4& k,
                      Mat4& kg) {
  k.setZero();
  kg.setZero();
  for (std::size_t q = 0; q < kGaussX.size(); ++q) {
    const double xi = kGaussX[q];
    const Vec4 b = hermite_curvature(xi, l);
    const Vec4 g = hermite_slope(xi, l);
    k += kGaussW[q] * l * ei(h0 + xi * l) * b * b.transpose();
    kg += kGaussW[q] * l * g * g.transpose();
  }
}

}  // namespace

double effective_length_factor(EndCondition end) {
  switch (end) {
    case EndCondition::FixedPinned:
      return 0.7;
    case EndCondition::FixedFree:
      return 2.0;
    case EndCondition::PinnedPinned:
      return 1.0;
  }
  return 1.0;
}

EndCondition parse_end_condition(std::string_view text) {
  if (text == "fixed-pinned") return EndCondition::FixedPinned;
  if (text == "fixed-free") return EndCondition::FixedFree;
  if (text == "pinned-pinned") return EndCondition::PinnedPinned;
  throw InputError("end condition '" + std::string(text) +
                   "' is unknown (expected fixed-pinned, fixed-free or pinned-pinned)");
}

std::string_view end_condition_name(EndCondition end) {
  switch (end) {
    case EndCondition::FixedPinned:
      return "fixed-pinned";
    case EndCondition::FixedFree:
      return "fixed-free";
    case EndCondition::PinnedPinned:
      return "pinned-pinned";
  }
  return "unknown";
}

double critical_buckling_load(const std::function<double(double)>& flexural_rigidity, double length,
                              EndCondition end, int elements) {
  if (!(length > 0.0) || !std::isfinite(length))
    throw InputError("buckling: column length must be positive and finite");
  if (elements < 2) throw InputError("buckling: at least two elements are needed");

  // A sharp tip has EI → 0 there; a floor keeps the tip rotation from making K singular
  // without changing the load (the tip carries no moment when pinned or free).
  double ei_max = 0.0;
  for (int i = 0; i <= elements; ++i)
    ei_max = std::max(ei_max, flexural_rigidity(length * i / elements));
  if (!(ei_max > 0.0) || !std::isfinite(ei_max))
    throw InputError("buckling: flexural rigidity must be positive and finite");
  const double ei_floor = 1e-9 * ei_max;
  auto ei = [&](double h) { return std::max(flexural_rigidity(h), ei_floor); };

  const int n_dof = 2 * (elements + 1);
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n_dof, n_dof);
  Eigen::MatrixXd kg = Eigen::MatrixXd::Zero(n_dof, n_dof);
  const double l = length / elements;
  Mat4 ke, kge;
  for (int e = 0; e < elements; ++e) {
    element_matrices(ei, e * l, l, ke, kge);
    k.block<4, 4>(2 * e, 2 * e) += ke;
    kg.block<4, 4>(2 * e, 2 * e) += kge;
  }

  // Node 0 is the tip, node `elements` the base. Keep the free DOFs: the base is clamped (w = θ =
  // 0) unless pinned (w = 0); the tip is free or pinned (w = 0).
  std::vector<int> free_dofs;
  const bool tip_pinned = end != EndCondition::FixedFree;
  const bool base_clamped = end != EndCondition::PinnedPinned;
  for (int dof = 0; dof < n_dof; ++dof) {
    if (dof == 0 && tip_pinned) continue;
    if (dof == n_dof - 2) continue;
    if (dof == n_dof - 1 && base_clamped) continue;
    free_dofs.push_back(dof);
  }
  const Eigen::MatrixXd kf = k(free_dofs, free_dofs);
  const Eigen::MatrixXd kgf = kg(free_dofs, free_dofs);

  // K u = P K_G u  ⇔  K_G u = (1/P) K u with K positive definite: the largest 1/P gives the lowest
  // P.
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(kgf, kf);
  if (solver.info() != Eigen::Success)
    throw SolverError("buckling: the beam eigenproblem did not converge");
  const double inverse_load = solver.eigenvalues().maxCoeff();
  if (!(inverse_load > 0.0)) throw SolverError("buckling: no positive critical load found");
  return 1.0 / inverse_load;
}

double johnson_critical_load(double elastic_load, double area, double strength) {
  const double euler_stress = elastic_load / area;
  if (euler_stress <= 0.5 * strength) return elastic_load;
  return area * strength * (1.0 - strength / (4.0 * euler_stress));
}

}  // namespace mneedle
