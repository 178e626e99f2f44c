#include "mneedle/fe/solid3d.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <set>
#include <utility>

#include "mneedle/base/error.h"
#include "mneedle/fe/sparse_solver.h"

namespace {

using namespace mneedle::fe;
using mneedle::MaterialModel;

std::vector<Eigen::Vector3d> unit_tet() {
  return {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
}

// A distorted 10-node tetrahedron: straight edges with midside nodes at the midpoints.
std::vector<Eigen::Vector3d> quadratic_tet() {
  std::vector<Eigen::Vector3d> p = {
      {0.1, -0.05, 0.0}, {1.2, 0.1, 0.05}, {0.2, 0.9, -0.1}, {0.05, 0.15, 1.1}};
  constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (const auto& e : kEdge)
    p.push_back(0.5 * (p[static_cast<std::size_t>(e[0])] + p[static_cast<std::size_t>(e[1])]));
  return p;
}

TEST(Solid3d, SingleLinearTetMatchesHandResultForUniaxialStrain) {
  const double E = 1000.0, nu = 0.25, strain = 1e-3;
  const Material material({MaterialModel::Linear, E, nu, 0.0, 0.0});
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  Eigen::VectorXd u = Eigen::VectorXd::Zero(12);
  u(3) = strain;  // node 1 at X = 1 moves by strain in x: u_x = strain * X
  const TetResponse r = tet_response(unit_tet(), u, material, true);
  // f_a = V sigma grad N_a with V = 1/6; sigma_xx = (lambda + 2 mu) e, sigma_yy = sigma_zz = lambda
  // e.
  EXPECT_NEAR(r.force(3), (lambda + 2 * mu) * strain / 6, 1e-12);
  EXPECT_NEAR(r.force(7), lambda * strain / 6, 1e-12);
  EXPECT_NEAR(r.force(11), lambda * strain / 6, 1e-12);
  EXPECT_NEAR(r.force(0), -(lambda + 2 * mu) * strain / 6, 1e-12);
  EXPECT_NEAR(r.energy, (lambda + 2 * mu) * strain * strain / 12, 1e-15);
  EXPECT_LT((r.stiffness * u - r.force).norm(), 1e-12);
}

TEST(Solid3d, QuadraticTetStiffnessIsSymmetricWithSixRigidModes) {
  const Material material({MaterialModel::Linear, 1e5, 0.3, 0.0, 0.0});
  const TetResponse r = tet_response(quadratic_tet(), Eigen::VectorXd::Zero(30), material, true);
  EXPECT_LT((r.stiffness - r.stiffness.transpose()).norm(), 1e-9 * r.stiffness.norm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(r.stiffness);
  int zero = 0;
  for (Eigen::Index i = 0; i < 30; ++i)
    if (std::abs(eigen.eigenvalues()(i)) < 1e-9 * eigen.eigenvalues().maxCoeff()) ++zero;
  EXPECT_EQ(zero, 6);
}

class TangentCheck : public ::testing::TestWithParam<MaterialModel> {};

TEST_P(TangentCheck, ConsistentTangentMatchesFiniteDifferences) {
  const Material material({GetParam(), 2e5, 0.45,
                           GetParam() == MaterialModel::MooneyRivlin ? 2e4 : 0.0,
                           GetParam() == MaterialModel::MooneyRivlin ? 1e4 : 0.0});
  const auto nodes = quadratic_tet();
  Eigen::VectorXd u = 0.05 * Eigen::VectorXd::Random(30);  // about 10 % strain
  const TetResponse r = tet_response(nodes, u, material, false);
  const double h = 1e-7;
  Eigen::MatrixXd numeric(30, 30);
  for (int j = 0; j < 30; ++j) {
    Eigen::VectorXd up = u, down = u;
    up(j) += h;
    down(j) -= h;
    numeric.col(j) = (tet_response(nodes, up, material, false).force -
                      tet_response(nodes, down, material, false).force) /
                     (2 * h);
  }
  EXPECT_LT((numeric - r.stiffness).norm(), 1e-6 * r.stiffness.norm());
}

TEST_P(TangentCheck, InternalForceIsTheGradientOfTheStrainEnergy) {
  const Material material({GetParam(), 2e5, 0.4, 0.0, 0.0});
  const auto nodes = quadratic_tet();
  const Eigen::VectorXd u = 0.05 * Eigen::VectorXd::Random(30);
  const Eigen::VectorXd force = tet_response(nodes, u, material, false).force;
  const double h = 1e-7;
  for (int j = 0; j < 30; j += 7) {
    Eigen::VectorXd up = u, down = u;
    up(j) += h;
    down(j) -= h;
    const double slope = (tet_response(nodes, up, material, false).energy -
                          tet_response(nodes, down, material, false).energy) /
                         (2 * h);
    EXPECT_NEAR(slope, force(j), 1e-6 * force.norm());
  }
}

TEST_P(TangentCheck, RigidRotationGivesNoForce) {
  const Material material({GetParam(), 2e5, 0.45, 0.0, 0.0});
  const auto nodes = quadratic_tet();
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd u(30);
  for (int a = 0; a < 10; ++a)
    u.segment<3>(3 * a) =
        rotation * nodes[static_cast<std::size_t>(a)] - nodes[static_cast<std::size_t>(a)];
  const TetResponse r = tet_response(nodes, u, material, false);
  EXPECT_LT(r.force.norm(), 1e-9 * 2e5);
  EXPECT_NEAR(r.energy, 0.0, 1e-9);
}

TEST_P(TangentCheck, ReducesToTheLinearAnswerAtSmallStrain) {
  const Material nonlinear({GetParam(), 2e5, 0.45, 0.0, 0.0});
  const Material linear({MaterialModel::Linear, 2e5, 0.45, 0.0, 0.0});
  const auto nodes = quadratic_tet();
  const Eigen::VectorXd u = 1e-6 * Eigen::VectorXd::Random(30);
  const Eigen::VectorXd f_nonlinear = tet_response(nodes, u, nonlinear, false).force;
  const Eigen::VectorXd f_linear = tet_response(nodes, u, linear, true).force;
  EXPECT_LT((f_nonlinear - f_linear).norm(), 1e-4 * f_linear.norm());
}

INSTANTIATE_TEST_SUITE_P(Hyperelastic, TangentCheck,
                         ::testing::Values(MaterialModel::StVenantKirchhoff,
                                           MaterialModel::NeoHookean, MaterialModel::MooneyRivlin));

TEST(Solid3d, InvertedElementRaisesSolverError) {
  const Material material({MaterialModel::NeoHookean, 1e5, 0.3, 0.0, 0.0});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(12);
  u(11) = -2.0;  // node 3 pushed through the opposite face
  EXPECT_THROW(tet_response(unit_tet(), u, material, false), mneedle::SolverError);
}

// Patch test: a block in a linear displacement field u = A X imposed on its whole boundary; the
// solved interior must reproduce the field exactly and carry no out-of-balance force.
void run_patch_test(int order, MaterialModel model, double scale) {
  TissueBlockSpec spec;
  spec.size_x = 2e-3;
  spec.size_y = 1.5e-3;
  // Two layers of the same material: a constant strain field is then in equilibrium across the
  // interface too (different materials would carry a traction jump there).
  spec.layers = {{"top", 0.2e-3, {model, 1e5, 0.45, 0.0, 0.0}},
                 {"bottom", 0.8e-3, {model, 1e5, 0.45, 0.0, 0.0}}};
  spec.sites = {{0.2e-3, -0.1e-3, 0.3e-3}};
  spec.fidelity = Fidelity::Fast;
  spec.order = order;
  const TetMesh mesh = generate_tissue_mesh(spec);
  const SolidModel solid(mesh);
  Eigen::Matrix3d A;
  A << 1.0, 0.2, -0.3, 0.1, -0.5, 0.4, 0.3, 0.2, 0.7;
  A *= scale;
  std::vector<char> constrained(static_cast<std::size_t>(solid.dof_count()), 0);
  Eigen::VectorXd exact(solid.dof_count());
  Eigen::VectorXd u = Eigen::VectorXd::Zero(solid.dof_count());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    exact.segment<3>(3 * static_cast<Eigen::Index>(n)) = A * mesh.nodes[n];
    const bool boundary = mesh.fixed[n] || mesh.nodes[n].z() == 0.0;
    for (int j = 0; j < 3; ++j) constrained[3 * n + static_cast<std::size_t>(j)] = boundary;
  }
  Eigen::SparseMatrix<double> k = solid.empty_stiffness();
  SparseSolver solver;
  // Boundary displacement applied in increments so no element inverts on the way.
  constexpr int kIncrements = 4;
  for (int increment = 1; increment <= kIncrements; ++increment) {
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
      if (constrained[3 * n])
        u.segment<3>(3 * static_cast<Eigen::Index>(n)) =
            exact.segment<3>(3 * static_cast<Eigen::Index>(n)) * increment / kIncrements;
    for (int iteration = 0; iteration < 10; ++iteration) {
      Eigen::VectorXd force;
      solid.assemble(u, &k, &force);
      for (Eigen::Index i = 0; i < force.size(); ++i)
        if (constrained[static_cast<std::size_t>(i)]) force(i) = 0.0;
      if (force.norm() < 1e-14) break;
      apply_dirichlet(&k, constrained);
      solver.factorize(k);
      u -= solver.solve(force);
    }
  }
  EXPECT_LT((u - exact).lpNorm<Eigen::Infinity>(), 1e-9 * exact.lpNorm<Eigen::Infinity>());
}

TEST(Solid3d, LinearPatchTestIsExactForTet4AndTet10) {
  run_patch_test(1, MaterialModel::Linear, 1e-3);
  run_patch_test(2, MaterialModel::Linear, 1e-3);
}

TEST(Solid3d, NonlinearPatchTestIsExactAtFiniteStrain) {
  run_patch_test(2, MaterialModel::StVenantKirchhoff, 0.1);
  run_patch_test(1, MaterialModel::NeoHookean, 0.1);
}

// A 1 x 1 x 0.5 mm linear block, fast TET10: a few thousand dofs.
TissueBlockSpec small_linear_block() {
  TissueBlockSpec spec;
  spec.size_x = spec.size_y = 1e-3;
  spec.layers = {{"block", 0.5e-3, {MaterialModel::Linear, 1e5, 0.4, 0.0, 0.0}}};
  spec.fidelity = Fidelity::Fast;
  spec.order = 2;
  return spec;
}

TEST(Solid3d, AssembledLinearStiffnessTimesDisplacementIsTheInternalForce) {
  const TetMesh mesh = generate_tissue_mesh(small_linear_block());
  const SolidModel solid(mesh);
  ASSERT_TRUE(solid.is_linear());
  const Eigen::VectorXd u = 1e-6 * Eigen::VectorXd::Random(solid.dof_count());
  Eigen::SparseMatrix<double> k = solid.empty_stiffness();
  Eigen::VectorXd force;
  const double energy = solid.assemble(u, &k, &force);
  const Eigen::VectorXd product = k.selfadjointView<Eigen::Lower>() * u;
  EXPECT_LT((product - force).norm(), 1e-10 * force.norm());
  EXPECT_NEAR(energy, 0.5 * u.dot(force), 1e-10 * energy);
}

// The pattern every assembly writes into: for each pair of nodes sharing an element, node a at
// or below node b, the 3 x 3 block (3a + i, 3b + j); compressed, each column's rows sorted.
TEST(Solid3d, EmptyStiffnessHoldsEachCoupledNodeBlockOnceInTheLowerTriangle) {
  const TetMesh mesh = generate_tissue_mesh(small_linear_block());
  const SolidModel solid(mesh);
  std::set<std::pair<int, int>> expected;
  for (const auto& element : mesh.elements)
    for (int a = 0; a < mesh.nodes_per_element(); ++a)
      for (int b = 0; b < mesh.nodes_per_element(); ++b) {
        const int na = element[static_cast<std::size_t>(a)];
        const int nb = element[static_cast<std::size_t>(b)];
        if (na < nb) continue;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) expected.emplace(3 * na + i, 3 * nb + j);
      }
  const Eigen::SparseMatrix<double> k = solid.empty_stiffness();
  ASSERT_TRUE(k.isCompressed());
  ASSERT_EQ(k.rows(), solid.dof_count());
  ASSERT_EQ(k.nonZeros(), static_cast<Eigen::Index>(expected.size()));
  std::set<std::pair<int, int>> found;
  for (int column = 0; column < k.outerSize(); ++column) {
    int previous = -1;
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, column); it; ++it) {
      EXPECT_GT(it.row(), previous) << "column " << column;
      previous = static_cast<int>(it.row());
      EXPECT_EQ(it.value(), 0.0);
      found.emplace(static_cast<int>(it.row()), column);
    }
  }
  EXPECT_EQ(found, expected);
}

}  // namespace
