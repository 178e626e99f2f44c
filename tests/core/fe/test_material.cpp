#include "mneedle/fe/material.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <array>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
constexpr std::array<std::array<int, 2>, 6> kPairs{
    {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}}};

MaterialParameters parameters(MaterialModel model) {
  MaterialParameters p;
  p.model = model;
  p.E = 2.0e5;
  p.nu = 0.45;
  if (model == MaterialModel::MooneyRivlin) {
    p.c10 = 2.0e4;
    p.c01 = 1.0e4;
  }
  return p;
}

// A deformation with stretch, shear and volume change (J != 1), moderate so SVK stays convex.
Eigen::Matrix3d sample_deformation() {
  Eigen::Matrix3d F;
  F << 1.12, 0.08, -0.05, 0.03, 0.93, 0.06, -0.04, 0.02, 1.05;
  return F;
}

// Green-Lagrange strain E -> a deformation gradient with that strain (symmetric square root).
Eigen::Matrix3d stretch_from_strain(const Eigen::Matrix3d& E) {
  const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() + 2.0 * E;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).operatorSqrt();
}

// Adds h to Voigt strain component b (engineering shear: half on each off-diagonal entry).
Eigen::Matrix3d perturb(const Eigen::Matrix3d& E, int b, double h) {
  Eigen::Matrix3d out = E;
  const int k = kPairs[b][0], l = kPairs[b][1];
  if (k == l) {
    out(k, k) += h;
  } else {
    out(k, l) += 0.5 * h;
    out(l, k) += 0.5 * h;
  }
  return out;
}

// Finite-difference dS/dE for a material whose strain measure is `strain_of(F)`.
Matrix6 finite_difference_tangent(const Material& material, const Eigen::Matrix3d& F) {
  const bool linear = material.is_linear();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d E0 = linear ? Eigen::Matrix3d(0.5 * (F + F.transpose()) - I)
                                    : Eigen::Matrix3d(0.5 * (F.transpose() * F - I));
  auto deformation = [&](const Eigen::Matrix3d& E) -> Eigen::Matrix3d {
    return linear ? Eigen::Matrix3d(I + E) : stretch_from_strain(E);
  };
  const double h = 1e-6;
  Matrix6 C;
  for (int b = 0; b < 6; ++b) {
    const Eigen::Matrix3d Sp = material.evaluate(deformation(perturb(E0, b, h))).S;
    const Eigen::Matrix3d Sm = material.evaluate(deformation(perturb(E0, b, -h))).S;
    const Eigen::Matrix3d dS = (Sp - Sm) / (2.0 * h);
    for (int a = 0; a < 6; ++a) C(a, b) = dS(kPairs[a][0], kPairs[a][1]);
  }
  return C;
}

class EveryModel : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(EveryModel, TangentMatchesFiniteDifferenceOfStress) {
  const Material material(parameters(GetParam()));
  const Eigen::Matrix3d F = sample_deformation();
  const Matrix6 analytic = material.evaluate(F).C;
  const Matrix6 numeric = finite_difference_tangent(material, F);
  // Central differences with h = 1e-6 on stresses of order 1e5 Pa: truncation ~1e-12 relative,
  // round-off ~1e-16 * 1e5 / 1e-6 ~ 1e-5 Pa against entries of order 1e5 Pa.
  EXPECT_LT((analytic - numeric).norm(), 1e-6 * analytic.norm()) << "analytic\n"
                                                                 << analytic << "\nnumeric\n"
                                                                 << numeric;
}

TEST_P(EveryModel, StressIsEnergyDerivative) {
  const Material material(parameters(GetParam()));
  const Eigen::Matrix3d F = sample_deformation();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const bool linear = material.is_linear();
  const Eigen::Matrix3d E0 = linear ? Eigen::Matrix3d(0.5 * (F + F.transpose()) - I)
                                    : Eigen::Matrix3d(0.5 * (F.transpose() * F - I));
  const Eigen::Matrix3d S = material.evaluate(F).S;
  const double h = 1e-7;
  for (int b = 0; b < 6; ++b) {
    auto energy = [&](double step) {
      const Eigen::Matrix3d E = perturb(E0, b, step);
      return material.evaluate(linear ? Eigen::Matrix3d(I + E) : stretch_from_strain(E))
          .energy_density;
    };
    const double dW = (energy(h) - energy(-h)) / (2.0 * h);
    EXPECT_NEAR(dW, S(kPairs[b][0], kPairs[b][1]), 1e-5 * S.norm()) << "component " << b;
  }
}

TEST_P(EveryModel, ReducesToLinearElasticityAtSmallStrain) {
  const MaterialParameters p = parameters(GetParam());
  const Material material(p);
  // Mooney-Rivlin's shear modulus comes from c10 + c01; compare with the equivalent E.
  const double mu = material.mu();
  const double kappa = p.E / (3.0 * (1.0 - 2.0 * p.nu));
  const double E_equivalent = 9.0 * kappa * mu / (3.0 * kappa + mu);
  const double nu_equivalent = (3.0 * kappa - 2.0 * mu) / (2.0 * (3.0 * kappa + mu));
  const Matrix6 D = isotropic_elasticity(E_equivalent, nu_equivalent);

  Eigen::Matrix3d H;
  H << 0.3, -0.2, 0.1, 0.4, -0.5, 0.2, 0.1, 0.3, 0.6;
  const double scale = 1e-6;
  const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + scale * H;
  const Eigen::Matrix3d eps = 0.5 * scale * (H + H.transpose());
  Eigen::Matrix<double, 6, 1> eps_voigt;
  for (int a = 0; a < 6; ++a) eps_voigt(a) = (a < 3 ? 1.0 : 2.0) * eps(kPairs[a][0], kPairs[a][1]);
  const Eigen::Matrix<double, 6, 1> expected = D * eps_voigt;
  const MaterialResponse r = material.evaluate(F);
  for (int a = 0; a < 6; ++a) {
    // Geometric nonlinearity is O(strain^2): relative 1e-6 here; rotations in H are O(1e-6) too.
    EXPECT_NEAR(r.S(kPairs[a][0], kPairs[a][1]), expected(a), 1e-4 * expected.norm());
  }
  EXPECT_LT((r.C - D).norm(), 1e-4 * D.norm());
}

INSTANTIATE_TEST_SUITE_P(Materials, EveryModel,
                         ::testing::Values(MaterialModel::Linear, MaterialModel::StVenantKirchhoff,
                                           MaterialModel::NeoHookean, MaterialModel::MooneyRivlin));

TEST(Material, RejectsIncompressibleOrWorsePoissonRatio) {
  MaterialParameters p = parameters(MaterialModel::NeoHookean);
  p.nu = 0.5;
  EXPECT_THROW(Material{p}, InputError);
  p.nu = 0.7;
  EXPECT_THROW(Material{p}, InputError);
  p.nu = -1.0;
  EXPECT_THROW(Material{p}, InputError);
}

TEST(Material, RejectsNonPositiveModulus) {
  MaterialParameters p = parameters(MaterialModel::Linear);
  p.E = 0.0;
  EXPECT_THROW(Material{p}, InputError);
  p.E = -1.0;
  EXPECT_THROW(Material{p}, InputError);
}

TEST(Material, MooneyRivlinWithoutConstantsTakesShearModulusFromYoungsModulus) {
  MaterialParameters p = parameters(MaterialModel::MooneyRivlin);
  p.c10 = p.c01 = 0.0;
  const Material material(p);
  EXPECT_NEAR(material.mu(), p.E / (2.0 * (1.0 + p.nu)), 1e-9 * p.E);
}

TEST(Material, InvertedDeformationIsASolverError) {
  const Material material(parameters(MaterialModel::NeoHookean));
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(2, 2) = -0.1;
  EXPECT_THROW(material.evaluate(F), SolverError);
}

TEST(Material, UndeformedStateIsStressFreeForEveryModel) {
  for (MaterialModel m : {MaterialModel::Linear, MaterialModel::StVenantKirchhoff,
                          MaterialModel::NeoHookean, MaterialModel::MooneyRivlin}) {
    const MaterialResponse r = Material(parameters(m)).evaluate(Eigen::Matrix3d::Identity());
    EXPECT_LT(r.S.norm(), 1e-9);
    EXPECT_NEAR(r.energy_density, 0.0, 1e-12);
  }
}

}  // namespace
}  // namespace mneedle::fe
