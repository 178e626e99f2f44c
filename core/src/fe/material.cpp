#include "mneedle/fe/material.h"

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// Voigt index -> tensor index pair, order xx, yy, zz, yz, xz, xy.
constexpr std::array<std::array<int, 2>, 6> kVoigtPairs{
    {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};

Vector6 to_voigt_stress(const Eigen::Matrix3d& A) {
  Vector6 v;
  for (int a = 0; a < 6; ++a) v(a) = A(kVoigtPairs[a][0], kVoigtPairs[a][1]);
  return v;
}

Eigen::Matrix3d from_voigt_stress(const Vector6& v) {
  Eigen::Matrix3d A;
  for (int a = 0; a < 6; ++a) {
    A(kVoigtPairs[a][0], kVoigtPairs[a][1]) = v(a);
    A(kVoigtPairs[a][1], kVoigtPairs[a][0]) = v(a);
  }
  return A;
}

Vector6 to_voigt_strain(const Eigen::Matrix3d& A) {
  Vector6 v = to_voigt_stress(A);
  v.tail<3>() *= 2.0;
  return v;
}

// Voigt matrix of the fourth-order tensor (A (x) A)_sym: 1/2 (A_ik A_jl + A_il A_jk).
Matrix6 symmetric_product(const Eigen::Matrix3d& A) {
  Matrix6 M;
  for (int a = 0; a < 6; ++a) {
    const int i = kVoigtPairs[a][0], j = kVoigtPairs[a][1];
    for (int b = a; b < 6; ++b) {
      const int k = kVoigtPairs[b][0], l = kVoigtPairs[b][1];
      M(a, b) = M(b, a) = 0.5 * (A(i, k) * A(j, l) + A(i, l) * A(j, k));
    }
  }
  return M;
}

// First and second derivatives of W(I1, I2, I3) with respect to the invariants of C.
struct InvariantDerivatives {
  double W = 0.0;
  std::array<double, 3> d{};                  // dW/dI1, dW/dI2, dW/dI3
  std::array<std::array<double, 3>, 3> dd{};  // symmetric second derivatives
};

// W = c10 (I1 I3^-1/3 - 3) + c01 (I2 I3^-2/3 - 3) + kappa/8 (ln I3)^2.
InvariantDerivatives mooney_rivlin(double c10, double c01, double kappa, double I1, double I2,
                                   double I3) {
  const double lnI3 = std::log(I3);
  const double p13 = std::pow(I3, -1.0 / 3.0);
  const double p23 = p13 * p13;
  InvariantDerivatives w;
  w.W = c10 * (I1 * p13 - 3.0) + c01 * (I2 * p23 - 3.0) + 0.125 * kappa * lnI3 * lnI3;
  w.d[0] = c10 * p13;
  w.d[1] = c01 * p23;
  w.d[2] =
      -c10 * I1 * p13 / (3.0 * I3) - 2.0 * c01 * I2 * p23 / (3.0 * I3) + 0.25 * kappa * lnI3 / I3;
  w.dd[0][2] = w.dd[2][0] = -c10 * p13 / (3.0 * I3);
  w.dd[1][2] = w.dd[2][1] = -2.0 * c01 * p23 / (3.0 * I3);
  w.dd[2][2] = 4.0 * c10 * I1 * p13 / (9.0 * I3 * I3) + 10.0 * c01 * I2 * p23 / (9.0 * I3 * I3) +
               0.25 * kappa * (1.0 - lnI3) / (I3 * I3);
  return w;
}

// S = 2 dW/dC and C = 4 d2W/dCdC for a W given through the invariants of the right
// Cauchy-Green tensor Cg: one code path for every isotropic hyperelastic model.
MaterialResponse invariant_response(const Eigen::Matrix3d& Cg, double I1, double I3,
                                    const InvariantDerivatives& w) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Cinv = Cg.inverse();
  const std::array<Eigen::Matrix3d, 3> dI{I, I1 * I - Cg, I3 * Cinv};
  std::array<Vector6, 3> dIv;
  for (int n = 0; n < 3; ++n) dIv[n] = to_voigt_stress(dI[n]);

  MaterialResponse r;
  r.energy_density = w.W;
  r.S = 2.0 * (w.d[0] * dI[0] + w.d[1] * dI[1] + w.d[2] * dI[2]);

  const Vector6 iv = to_voigt_stress(I);
  const Vector6 cinv = to_voigt_stress(Cinv);
  Matrix6 C = Matrix6::Zero();
  for (int m = 0; m < 3; ++m)
    for (int n = 0; n < 3; ++n) C += w.dd[m][n] * dIv[m] * dIv[n].transpose();
  C += w.d[1] * (iv * iv.transpose() - symmetric_product(I));
  C += w.d[2] * I3 * (cinv * cinv.transpose() - symmetric_product(Cinv));
  r.C = 4.0 * C;
  return r;
}

void require(bool condition, const std::string& message) {
  if (!condition) throw InputError("material: " + message);
}

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

Eigen::Matrix<double, 6, 6> isotropic_elasticity(double E, double nu) {
  const double lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double mu = E / (2.0 * (1.0 + nu));
  Matrix6 D = Matrix6::Zero();
  D.topLeftCorner<3, 3>().setConstant(lambda);
  D.topLeftCorner<3, 3>().diagonal().array() += 2.0 * mu;
  D.bottomRightCorner<3, 3>().diagonal().setConstant(mu);
  return D;
}

Material::Material(const MaterialParameters& p) : parameters_(p) {
  require(std::isfinite(p.E) && p.E > 0.0, "field E must be > 0 Pa, got " + number(p.E));
  require(std::isfinite(p.nu) && p.nu > -1.0 && p.nu < 0.5,
          "field nu must lie in (-1, 0.5), got " + number(p.nu));
  require(std::isfinite(p.c10) && p.c10 >= 0.0, "field C10 must be >= 0 Pa, got " + number(p.c10));
  require(std::isfinite(p.c01) && p.c01 >= 0.0, "field C01 must be >= 0 Pa, got " + number(p.c01));
  lambda_ = p.E * p.nu / ((1.0 + p.nu) * (1.0 - 2.0 * p.nu));
  mu_ = p.E / (2.0 * (1.0 + p.nu));
  kappa_ = p.E / (3.0 * (1.0 - 2.0 * p.nu));
  if (p.model == MaterialModel::MooneyRivlin) {
    if (p.c10 + p.c01 == 0.0) parameters_.c10 = 0.5 * mu_;
    // The small-strain response follows the Mooney-Rivlin shear modulus and E/nu's bulk modulus.
    mu_ = 2.0 * (parameters_.c10 + parameters_.c01);
    lambda_ = kappa_ - 2.0 * mu_ / 3.0;
  }
}

bool Material::is_linear() const {
  return parameters_.model == MaterialModel::Linear;
}

MaterialResponse Material::evaluate(const Eigen::Matrix3d& F) const {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  MaterialResponse r;
  switch (parameters_.model) {
    case MaterialModel::Linear:
    case MaterialModel::StVenantKirchhoff: {
      const Eigen::Matrix3d strain = parameters_.model == MaterialModel::Linear
                                         ? Eigen::Matrix3d(0.5 * (F + F.transpose()) - I)
                                         : Eigen::Matrix3d(0.5 * (F.transpose() * F - I));
      r.C = isotropic_elasticity(parameters_.E, parameters_.nu);
      const Vector6 s = r.C * to_voigt_strain(strain);
      r.S = from_voigt_stress(s);
      r.energy_density = 0.5 * s.dot(to_voigt_strain(strain));
      return r;
    }
    case MaterialModel::NeoHookean: {
      // Closed form (Bonet & Wood): S = mu (I - C^-1) + lambda ln J C^-1,
      // C = lambda C^-1 (x) C^-1 + 2 (mu - lambda ln J) (C^-1 (x) C^-1)_sym; the generic
      // invariant path below gives the same, at twice the cost (the solvers' hot spot).
      const double J = F.determinant();
      if (!(J > 0.0)) throw SolverError("inverted element (det F = " + number(J) + ")");
      const Eigen::Matrix3d Cg = F.transpose() * F;
      const Eigen::Matrix3d Cinv = Cg.inverse();
      const double lnJ = std::log(J);
      r.energy_density = 0.5 * mu_ * (Cg.trace() - 3.0) - mu_ * lnJ + 0.5 * lambda_ * lnJ * lnJ;
      r.S = mu_ * (I - Cinv) + lambda_ * lnJ * Cinv;
      const Vector6 cinv = to_voigt_stress(Cinv);
      r.C =
          lambda_ * cinv * cinv.transpose() + 2.0 * (mu_ - lambda_ * lnJ) * symmetric_product(Cinv);
      return r;
    }
    case MaterialModel::MooneyRivlin: {
      const double J = F.determinant();
      if (!(J > 0.0)) throw SolverError("inverted element (det F = " + number(J) + ")");
      const Eigen::Matrix3d Cg = F.transpose() * F;
      const double I1 = Cg.trace();
      const double I2 = 0.5 * (I1 * I1 - (Cg * Cg).trace());
      const double I3 = J * J;
      const InvariantDerivatives w =
          mooney_rivlin(parameters_.c10, parameters_.c01, kappa_, I1, I2, I3);
      return invariant_response(Cg, I1, I3, w);
    }
  }
  throw InputError("material: unknown model");
}

}  // namespace mneedle::fe
