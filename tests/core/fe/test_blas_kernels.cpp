#include "mneedle/fe/blas_kernels.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <cstdlib>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/fe/sparse_solver.h"

namespace {

using mneedle::fe::better_openblas_core;
using mneedle::fe::openblas_core_level;
using mneedle::fe::SimdLevel;

// OpenBLAS's fallback for a CPU model it does not know is its SSE3 "Prescott" core: replaced
// by the widest kernels the CPU has.
TEST(BlasKernels, TheSse3FallbackIsReplacedByTheWidestKernelsTheCpuHas) {
  EXPECT_EQ(better_openblas_core("Prescott", SimdLevel::Avx512), "SkylakeX");
  EXPECT_EQ(better_openblas_core("Prescott", SimdLevel::Avx2), "Haswell");
  EXPECT_EQ(better_openblas_core("PRESCOTT", SimdLevel::Avx512), "SkylakeX");  // any case
  EXPECT_EQ(better_openblas_core("Nehalem", SimdLevel::Avx2), "Haswell");
  EXPECT_EQ(better_openblas_core("Sandybridge", SimdLevel::Avx512), "SkylakeX");
}

// A core OpenBLAS chose for a CPU it knows is kept, as is one on a CPU without AVX2 (nothing
// better to give) and a name this table does not list (another architecture, a newer release).
TEST(BlasKernels, AKnownCoreAnOldCpuAndAnUnknownNameAreKept) {
  EXPECT_EQ(better_openblas_core("Haswell", SimdLevel::Avx512), "");
  EXPECT_EQ(better_openblas_core("Zen", SimdLevel::Avx512), "");
  EXPECT_EQ(better_openblas_core("SkylakeX", SimdLevel::Avx512), "");
  EXPECT_EQ(better_openblas_core("Prescott", SimdLevel::Avx), "");
  EXPECT_EQ(better_openblas_core("Prescott", SimdLevel::Sse), "");
  EXPECT_EQ(better_openblas_core("Prescott", SimdLevel::Unknown), "");
  EXPECT_EQ(better_openblas_core("armv8", SimdLevel::Avx512), "");
  EXPECT_EQ(better_openblas_core("", SimdLevel::Avx512), "");
  EXPECT_EQ(openblas_core_level("Cooperlake"), SimdLevel::Avx512);
  EXPECT_EQ(openblas_core_level("Opteron_SSE3"), SimdLevel::Sse);
  EXPECT_EQ(openblas_core_level("neoversen1"), SimdLevel::Unknown);
}

// MNEEDLE_BLAS_KERNELS: "auto" (or unset, or empty) and "off"; anything else is one line naming
// the variable and the value.
TEST(BlasKernels, TheEnvironmentChoiceIsAutoOrOffAndAnythingElseIsOneLine) {
  const char* saved = std::getenv("MNEEDLE_BLAS_KERNELS");
  const std::string keep = saved ? saved : "";
  ::unsetenv("MNEEDLE_BLAS_KERNELS");
  EXPECT_EQ(mneedle::fe::blas_kernel_choice_from_environment(),
            mneedle::fe::BlasKernelChoice::Auto);
  ::setenv("MNEEDLE_BLAS_KERNELS", "", 1);
  EXPECT_EQ(mneedle::fe::blas_kernel_choice_from_environment(),
            mneedle::fe::BlasKernelChoice::Auto);
  ::setenv("MNEEDLE_BLAS_KERNELS", " off ", 1);
  EXPECT_EQ(mneedle::fe::blas_kernel_choice_from_environment(), mneedle::fe::BlasKernelChoice::Off);
  ::setenv("MNEEDLE_BLAS_KERNELS", "avx512", 1);
  try {
    mneedle::fe::blas_kernel_choice_from_environment();
    ADD_FAILURE() << "no error for 'avx512'";
  } catch (const mneedle::InputError& e) {
    EXPECT_STREQ(e.what(), "MNEEDLE_BLAS_KERNELS: must be \"auto\" or \"off\", got 'avx512'");
  }
  if (saved)
    ::setenv("MNEEDLE_BLAS_KERNELS", keep.c_str(), 1);
  else
    ::unsetenv("MNEEDLE_BLAS_KERNELS");
}

// On this machine: the first factorisation chooses the kernels (auto), the choice is the table's
// for the detected core and this CPU, and a supernodal factorisation large enough to run in the
// BLAS (a dense 400 x 400 block) solves as Eigen's dense Cholesky does, to round-off.
TEST(BlasKernels, TheFirstFactorisationRunsOnTheChosenKernelsAndSolvesToRoundOff) {
  const int n = 400;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = 1.0 / (1.0 + std::abs(i - j)) + (i == j ? n : 0.0);
  const Eigen::SparseMatrix<double> sparse = a.sparseView();
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  mneedle::fe::SparseSolver solver;
  solver.factorize(sparse);
  ASSERT_TRUE(solver.ok());
  const Eigen::VectorXd x = solver.solve(b);
  const Eigen::VectorXd reference = a.llt().solve(b);
  // Condition number about 1.1 (diagonally dominant): round-off is ~n eps of the solution.
  EXPECT_LT((x - reference).norm(), 1e-13 * reference.norm());

  const mneedle::fe::BlasKernels kernels = mneedle::fe::select_blas_kernels();
  if (kernels.detected.empty()) GTEST_SKIP() << "the BLAS is not a dynamic OpenBLAS";
  const char* named = std::getenv("OPENBLAS_CORETYPE");
  const std::string better = better_openblas_core(kernels.detected, mneedle::fe::cpu_simd_level());
  if (named != nullptr || better.empty()) {
    EXPECT_EQ(kernels.used, kernels.detected);
  } else {
    // The table's core, and the environment left as it was (the variable unset again).
    EXPECT_EQ(kernels.used, better);
    EXPECT_EQ(std::getenv("OPENBLAS_CORETYPE"), nullptr);
  }
  // The choice is made once: a later call with another choice returns the first.
  const mneedle::fe::BlasKernels again =
      mneedle::fe::select_blas_kernels(mneedle::fe::BlasKernelChoice::Off);
  EXPECT_EQ(again.used, kernels.used);
  EXPECT_EQ(again.detected, kernels.detected);
}

}  // namespace
