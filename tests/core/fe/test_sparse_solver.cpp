#include "mneedle/fe/sparse_solver.h"

#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/base/memory.h"

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

// A factor that cannot fit in the memory left is refused at the analysis, before CHOLMOD
// allocates it, with what it needs and what there is (docs/performance.md, "Memory").
TEST(SparseSolver, AFactorThatCannotFitIsRefusedBeforeItIsAllocated) {
  const SpMat matrix = shifted_laplacian(200, 0.01);
  mneedle::fe::SparseSolver solver;
  solver.factorize(matrix);
  if (solver.backend() != "cholmod-supernodal-llt") GTEST_SKIP() << "the check is CHOLMOD's";
  struct Budget {  // the process's limit, removed whatever the test does
    Budget() { mneedle::set_memory_limit_bytes(1); }
    ~Budget() { mneedle::set_memory_limit_bytes(std::nullopt); }
  };
  {
    const Budget budget;
    mneedle::fe::SparseSolver refused;
    try {
      refused.analyze(matrix);
      FAIL() << "expected a SolverError";
    } catch (const mneedle::SolverError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("the factor of 200 unknowns needs"), std::string::npos) << what;
      EXPECT_NE(what.find("more than the 0 MiB of memory left"), std::string::npos) << what;
    }
  }
  mneedle::fe::SparseSolver fits;  // the same matrix once the memory is there
  EXPECT_NO_THROW(fits.analyze(matrix));
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

// Without the fallback an indefinite matrix is reported at once (a caller that shifts it does
// not pay for a factorisation it would discard); the next positive definite one factorises, and
// turning the fallback back on brings LDLT back.
TEST(SparseSolver, WithoutTheFallbackAnIndefiniteMatrixIsReportedNotFactorised) {
  const SpMat indefinite = shifted_laplacian(40, -0.5);
  mneedle::fe::SparseSolver solver;
  solver.set_indefinite_fallback(false);
  solver.factorize(indefinite);
  EXPECT_FALSE(solver.ok());
  EXPECT_EQ(solver.backend(), "none");
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(40)), mneedle::SolverError);
  const SpMat definite = shifted_laplacian(40, 0.5);
  solver.factorize(definite);
  ASSERT_TRUE(solver.ok());
  EXPECT_NE(solver.backend(), "eigen-simplicial-ldlt");
  solver.set_indefinite_fallback(true);
  solver.factorize(indefinite);
  ASSERT_TRUE(solver.ok());
  EXPECT_EQ(solver.backend(), "eigen-simplicial-ldlt");
}

// The LDLT fallback needs about as much again as the factor that failed: when that does not fit
// it is refused before Eigen allocates it (docs/performance.md, "Memory").
TEST(SparseSolver, AnLdltFallbackThatCannotFitIsRefusedBeforeItIsAllocated) {
  mneedle::fe::SparseSolver spd;
  spd.factorize(shifted_laplacian(40, 0.5));
  if (spd.backend() != "cholmod-supernodal-llt") GTEST_SKIP() << "the check is CHOLMOD's";
  const SpMat matrix = shifted_laplacian(40, -0.5);
  mneedle::fe::SparseSolver solver;
  solver.analyze(matrix);
  struct Budget {  // the process's limit, removed whatever the test does
    Budget() { mneedle::set_memory_limit_bytes(1); }
    ~Budget() { mneedle::set_memory_limit_bytes(std::nullopt); }
  };
  {
    const Budget budget;
    try {
      solver.factorize(matrix);
      FAIL() << "expected an OutOfMemoryError";
    } catch (const mneedle::OutOfMemoryError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("sparse solver: the LDLT fallback for 40 unknowns needs ", 0), 0u)
          << what;
    }
  }
  solver.factorize(matrix);  // with the memory there
  EXPECT_TRUE(solver.ok());
  EXPECT_EQ(solver.backend(), "eigen-simplicial-ldlt");
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

// A solid-like system: a 3-D grid Laplacian (k³ nodes) times an SPD 3×3 coupling per node, plus
// `shift` on the diagonal; 3 dofs per node, node by node.
SpMat nodal_system(int k, double shift) {
  const Eigen::Matrix3d coupling =
      (Eigen::Matrix3d() << 2, 0.5, 0.2, 0.5, 1.5, 0.3, 0.2, 0.3, 1).finished();
  std::vector<Eigen::Triplet<double>> entries;
  auto node = [k](int x, int y, int z) { return (z * k + y) * k + x; };
  auto add_block = [&](int a, int b, double scale) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        entries.emplace_back(3 * a + i, 3 * b + j, scale * coupling(i, j));
  };
  for (int z = 0; z < k; ++z)
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x) {
        const int a = node(x, y, z);
        add_block(a, a, 6.0 + shift);
        for (const auto& [dx, dy, dz] : {std::array{1, 0, 0}, {0, 1, 0}, {0, 0, 1}})
          if (x + dx < k && y + dy < k && z + dz < k) {
            add_block(a, node(x + dx, y + dy, z + dz), -1.0);
            add_block(node(x + dx, y + dy, z + dz), a, -1.0);
          }
      }
  SpMat matrix(3 * k * k * k, 3 * k * k * k);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

// Ordering by node is CHOLMOD's (METIS on the nodal graph); without CHOLMOD every order is Eigen's.
bool with_cholmod() {
  mneedle::fe::SparseSolver solver;
  solver.factorize(shifted_laplacian(3, 1.0));
  return solver.backend() == "cholmod-supernodal-llt";
}

TEST(SparseSolver, OrderingByNodeSolvesWhatOrderingByDofSolves) {
  const SpMat matrix = nodal_system(6, 0.05);
  const Eigen::MatrixXd rhs = Eigen::MatrixXd::Random(matrix.rows(), 4);
  mneedle::fe::SparseSolver by_dof, by_node(3);
  by_dof.factorize(matrix);
  by_node.factorize(matrix);
  ASSERT_TRUE(by_node.ok());
  EXPECT_EQ(by_node.ordered_by_node(), with_cholmod());
  EXPECT_FALSE(by_dof.ordered_by_node());
  EXPECT_NE(by_node.backend().find("llt"), std::string::npos);
  const Eigen::MatrixXd x = by_node.solve_many(rhs);
  // Residual and agreement at round-off of a system whose condition number is about 1e3.
  EXPECT_LT((matrix * x - rhs).norm(), 1e-11 * rhs.norm());
  EXPECT_LT((x - by_dof.solve_many(rhs)).norm(), 1e-11 * x.norm());
  const Eigen::VectorXd one = by_node.solve(rhs.col(0));
  EXPECT_LT((one - x.col(0)).norm(), 1e-14 * one.norm());
}

// CHOLMOD's blocks of 8 MB and more come from the huge-page allocator (sparse_solver.cpp): a
// factor of several million entries must solve as a small one does, and factorise again.
TEST(SparseSolver, AFactorLargeEnoughForHugePagesSolvesToRoundoff) {
  const SpMat matrix = nodal_system(14, 0.05);
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(matrix.rows(), -1.0, 1.0);
  mneedle::fe::SparseSolver solver(3);
  for (int round = 0; round < 2; ++round) {
    solver.factorize(matrix);
    ASSERT_TRUE(solver.ok());
    if (with_cholmod()) {
      EXPECT_GT(solver.factor_nonzeros(), 1.0e6) << solver.factor_nonzeros();  // 8 MB at least
    }
    const Eigen::VectorXd x = solver.solve(rhs);
    // Condition number about 1e3, as above.
    EXPECT_LT((matrix * x - rhs).norm(), 1e-11 * rhs.norm());
  }
}

// The process's mappings whose kernel flags (/proc/self/smaps, VmFlags) include `flag`: "hg"
// for memory advised onto huge pages, "nh" for memory advised away from them.
int mappings_flagged(const std::string& flag) {
  std::ifstream smaps("/proc/self/smaps");
  int count = 0;
  for (std::string line; std::getline(smaps, line);)
    if (line.rfind("VmFlags:", 0) == 0 && (line + " ").find(" " + flag + " ") != std::string::npos)
      ++count;
  return count;
}

// Restores the process-wide default however the test ends.
struct HugePagesRestored {
  ~HugePagesRestored() { mneedle::fe::set_huge_pages(false); }
};

// The default (MNEEDLE_HUGE_PAGES unset or off, docs/cli.md "Environment") advises the large
// blocks away from huge pages; set_huge_pages(true) advises the same blocks onto them, and the
// factor and every solve are bit for bit those of the default run: only where the memory comes
// from changes. The advice is read back from the kernel's flags while each factor is held
// (skipped where the kernel has no THP).
TEST(SparseSolver, HugePagesOnAdvisesTheFactorOntoThemAndSolvesBitForBitAsTheDefault) {
  const HugePagesRestored restore;
  const SpMat matrix = nodal_system(14, 0.05);
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(matrix.rows(), -1.0, 1.0);
  ASSERT_FALSE(mneedle::fe::huge_pages());  // the default
  Eigen::VectorXd x_on, x_off;
  double nonzeros_off = 0.0;
  bool advised = false;
  {
    const int before = mappings_flagged("nh");
    mneedle::fe::SparseSolver off(3);
    off.factorize(matrix);
    ASSERT_TRUE(off.ok());
    advised = mappings_flagged("nh") > before;
    x_off = off.solve(rhs);
    nonzeros_off = off.factor_nonzeros();
  }
  mneedle::fe::set_huge_pages(true);
  EXPECT_TRUE(mneedle::fe::huge_pages());
  const int onto_before = mappings_flagged("hg");
  mneedle::fe::SparseSolver on(3);
  on.factorize(matrix);
  ASSERT_TRUE(on.ok());
  x_on = on.solve(rhs);
  EXPECT_EQ(on.factor_nonzeros(), nonzeros_off);
  EXPECT_EQ((x_on - x_off).cwiseAbs().maxCoeff(), 0.0);
  if (!with_cholmod() || !advised) GTEST_SKIP() << "no huge-page advice on this kernel or build";
  EXPECT_GT(mappings_flagged("hg"), onto_before);
}

TEST(SparseSolver, OrderingByNodeFindsTheFillOfOrderingByDof) {
  // The point of the nodal order is its cost, not a different factor: the fill must stay that of
  // CHOLMOD's own choice (AMD or METIS on the dofs).
  if (!with_cholmod()) GTEST_SKIP() << "the nodal order is CHOLMOD's";
  const SpMat matrix = nodal_system(10, 0.05);
  mneedle::fe::SparseSolver by_dof, by_node(3);
  by_dof.factorize(matrix);
  by_node.factorize(matrix);
  ASSERT_GT(by_dof.factor_nonzeros(), 0.0);
  // 10 %: METIS's separators on the nodal and the dof graph differ (nodal / dof fill measured
  // 0.996 here and 1.00 on paper A's skin half model, 1.24e7 entries either way).
  EXPECT_LT(by_node.factor_nonzeros(), 1.1 * by_dof.factor_nonzeros());
}

TEST(SparseSolver, ANewPatternOfAnotherSizeIsOrderedAfresh) {
  mneedle::fe::SparseSolver solver(3);
  for (const SpMat& matrix :
       {nodal_system(4, 0.1), shifted_laplacian(100, 0.01), nodal_system(5, 0.2)}) {
    solver.factorize(matrix);
    EXPECT_EQ(solver.ordered_by_node(), matrix.rows() % 3 == 0 && with_cholmod());
    const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(matrix.rows(), -1.0, 1.0);
    EXPECT_LT((matrix * solver.solve(rhs) - rhs).norm(), 1e-10 * rhs.norm());
  }
  EXPECT_EQ(solver.analysis_count(), 3);
}

TEST(SparseSolver, OrderingByNodeReadsTheLowerTriangleOnly) {
  const SpMat matrix = nodal_system(4, 0.1);
  const SpMat lower = matrix.triangularView<Eigen::Lower>();
  mneedle::fe::SparseSolver solver(3);
  solver.factorize(lower);
  EXPECT_EQ(solver.ordered_by_node(), with_cholmod());
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(matrix.rows(), -1.0, 1.0);
  EXPECT_LT((matrix * solver.solve(rhs) - rhs).norm(), 1e-11 * rhs.norm());
}

TEST(SparseSolver, OrderingByNodeFallsBackToLdltForAnIndefiniteMatrix) {
  // The matrix is (L + shift I) ⊗ C with the grid's L spanning 1.76–10.24 and C positive: a
  // shift of -5.1 leaves some eigenvalues negative and every LDLT pivot away from zero (at -8 LDLT
  // met a zero pivot in AMD's order).
  const SpMat matrix = nodal_system(3, -5.1);
  mneedle::fe::SparseSolver solver(3);
  solver.factorize(matrix);
  ASSERT_TRUE(solver.ok());
  EXPECT_EQ(solver.backend(), "eigen-simplicial-ldlt");
  EXPECT_EQ(solver.ordered_by_node(), with_cholmod());
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(matrix.rows(), 0.0, 1.0);
  EXPECT_LT((matrix * solver.solve(rhs) - rhs).norm(), 1e-8 * rhs.norm());
}

TEST(SparseSolver, ASizeThatIsNoWholeNumberOfNodesIsOrderedByDof) {
  const SpMat matrix = shifted_laplacian(100, 0.01);  // 100 is not a multiple of 3
  mneedle::fe::SparseSolver solver(3);
  solver.factorize(matrix);
  EXPECT_FALSE(solver.ordered_by_node());
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(100);
  EXPECT_LT((matrix * solver.solve(rhs) - rhs).norm(), 1e-9);
  EXPECT_THROW(mneedle::fe::SparseSolver(0), mneedle::SolverError);
}

// The contact block (docs/performance.md, "The contact block"): nodes eliminated last, K⁻¹ on
// them read from the dense factor of the Schur complement, must be the columns a sparse solve
// gives (round-off of a system whose condition number is about 1e3), in the trailing nodes' own
// numbering, whatever order the nodes are named in.
TEST(SparseSolver, TrailingColumnsAreTheColumnsOfTheInverseOnTheTrailingNodes) {
  if (!with_cholmod()) GTEST_SKIP() << "the trailing block is read from CHOLMOD's factor";
  const SpMat matrix = nodal_system(7, 0.05);
  const std::vector<int> trailing = {171, 3, 170, 100, 342, 57};
  mneedle::fe::SparseSolver plain(3), blocked(3);
  plain.factorize(matrix);
  blocked.set_trailing_nodes(trailing);
  blocked.factorize(matrix);
  ASSERT_TRUE(blocked.has_trailing_block());
  EXPECT_FALSE(plain.has_trailing_block());
  const auto t = static_cast<Eigen::Index>(3 * trailing.size());
  std::vector<Eigen::Index> columns;
  for (Eigen::Index c = 0; c < t; ++c) columns.push_back((5 * c + 2) % t);  // every one, shuffled
  const Eigen::MatrixXd block = blocked.trailing_columns(columns);
  ASSERT_EQ(block.rows(), t);
  ASSERT_EQ(block.cols(), t);
  for (Eigen::Index j = 0; j < t; ++j) {
    const Eigen::Index c = columns[static_cast<std::size_t>(j)];
    Eigen::VectorXd unit = Eigen::VectorXd::Zero(matrix.rows());
    unit(3 * trailing[static_cast<std::size_t>(c / 3)] + c % 3) = 1.0;
    const Eigen::VectorXd x = plain.solve(unit);
    for (Eigen::Index r = 0; r < t; ++r)
      EXPECT_NEAR(block(r, j), x(3 * trailing[static_cast<std::size_t>(r / 3)] + r % 3),
                  1e-12 * x.norm())
          << "row " << r << ", column " << c;
  }
  // A load on the trailing dofs alone: the dense forward solve and CHOLMOD's back substitution
  // give what a whole solve gives.
  const Eigen::VectorXd load = Eigen::VectorXd::LinSpaced(t, -1.0, 2.0);
  Eigen::VectorXd full = Eigen::VectorXd::Zero(matrix.rows());
  for (Eigen::Index r = 0; r < t; ++r)
    full(3 * trailing[static_cast<std::size_t>(r / 3)] + r % 3) = load(r);
  const Eigen::VectorXd x = plain.solve(full);
  EXPECT_LT((blocked.solve_trailing_loads(load).col(0) - x).norm(), 1e-12 * x.norm());
  // The whole solve is unchanged by the order.
  EXPECT_LT((blocked.solve(full) - x).norm(), 1e-12 * x.norm());
}

TEST(SparseSolver, WithoutATrailingBlockItsColumnsAreRefused) {
  const SpMat matrix = nodal_system(3, 0.1);
  mneedle::fe::SparseSolver solver(3);
  solver.factorize(matrix);
  EXPECT_FALSE(solver.has_trailing_block());
  EXPECT_THROW(solver.trailing_columns({0}), mneedle::SolverError);
  EXPECT_THROW(solver.solve_trailing_loads(Eigen::VectorXd::Ones(3)), mneedle::SolverError);
  // A node named twice or out of range: ordered without the list. An empty list clears it.
  solver.set_trailing_nodes({1, 5, 5});
  solver.analyze(matrix);
  solver.factorize(matrix);
  EXPECT_FALSE(solver.has_trailing_block());
  EXPECT_EQ(solver.ordered_by_node(), with_cholmod());
  solver.set_trailing_nodes({0, 99});
  solver.analyze(matrix);
  solver.factorize(matrix);
  EXPECT_FALSE(solver.has_trailing_block());
  EXPECT_EQ(solver.ordered_by_node(), with_cholmod());
  if (!with_cholmod()) return;
  solver.set_trailing_nodes({4, 2});
  solver.analyze(matrix);
  solver.factorize(matrix);
  ASSERT_TRUE(solver.has_trailing_block());
  EXPECT_THROW(solver.trailing_columns({6}), mneedle::SolverError);  // 2 nodes: 6 dofs
  EXPECT_THROW(solver.solve_trailing_loads(Eigen::VectorXd::Ones(5)), mneedle::SolverError);
  solver.set_trailing_nodes({});
  solver.analyze(matrix);
  solver.factorize(matrix);
  EXPECT_FALSE(solver.has_trailing_block());
}

}  // namespace
