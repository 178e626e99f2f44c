#include "mneedle/fe/sparse_solver.h"

#include <gtest/gtest.h>

#include <vector>

#include "mneedle/base/error.h"

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// 1-D Laplacian with a diagonal shift: SPD for shift > 0, indefinite for a negative shift.
SpMat shifted_laplacian(int n, double shift) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 2.0 + shift);
    if (i + 1 < n) {
      entries.emplace_back(i + 1, i, -1.0);
      entries.emplace_back(i, i + 1, -1.0);
    }
  }
  SpMat matrix(n, n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

TEST(SparseSolver, SolvesSpdSystemToRoundoff) {
  const SpMat matrix = shifted_laplacian(200, 0.01);
  const Eigen::VectorXd expected = Eigen::VectorXd::LinSpaced(200, -1.0, 3.0);
  const Eigen::VectorXd rhs = matrix * expected;
  mneedle::fe::SparseSolver solver;
  solver.analyze(matrix);
  solver.factorize(matrix);
  ASSERT_TRUE(solver.ok());
  EXPECT_NE(solver.backend().find("llt"), std::string::npos);
  EXPECT_LT((solver.solve(rhs) - expected).norm(), 1e-9 * expected.norm());
}

TEST(SparseSolver, ReusesSymbolicAnalysisForSamePattern) {
  mneedle::fe::SparseSolver solver;
  solver.analyze(shifted_laplacian(50, 0.1));
  for (double shift : {0.1, 0.5, 2.0}) {
    const SpMat matrix = shifted_laplacian(50, shift);
    solver.factorize(matrix);
    const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(50);
    EXPECT_LT((matrix * solver.solve(rhs) - rhs).norm(), 1e-10);
  }
  EXPECT_EQ(solver.analysis_count(), 1);
}

TEST(SparseSolver, FallsBackToLdltForIndefiniteMatrix) {
  // Eigenvalues of the 1-D Laplacian lie in (0, 4): a shift of -0.5 makes some negative
  // while keeping every LDLT pivot away from zero.
  const SpMat matrix = shifted_laplacian(40, -0.5);
  mneedle::fe::SparseSolver solver;
  solver.factorize(matrix);
  ASSERT_TRUE(solver.ok());
  EXPECT_EQ(solver.backend(), "eigen-simplicial-ldlt");
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(40, 0.0, 1.0);
  EXPECT_LT((matrix * solver.solve(rhs) - rhs).norm(), 1e-8);
}

TEST(SparseSolver, SolvesSeveralRightHandSidesAtOnce) {
  const SpMat matrix = shifted_laplacian(30, 0.2);
  mneedle::fe::SparseSolver solver;
  solver.factorize(matrix);
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(30, 3);
  EXPECT_LT((matrix * solver.solve_many(rhs) - rhs).norm(), 1e-10);
}

TEST(SparseSolver, SingularMatrixIsReportedNotSolved) {
  SpMat matrix(3, 3);
  matrix.insert(0, 0) = 1.0;
  matrix.insert(1, 1) = 0.0;
  matrix.insert(2, 2) = 1.0;
  mneedle::fe::SparseSolver solver;
  solver.factorize(matrix);
  EXPECT_FALSE(solver.ok());
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(3)), mneedle::SolverError);
}

}  // namespace
