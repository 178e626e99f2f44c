// OpenBLAS thread limits: one holds the count, overlapping ones (from several threads) share it,
// and the count from before the first comes back when the last ends, in whatever order they end.
#include "mneedle/blas_threads.h"

#include <gtest/gtest.h>

#include <memory>

namespace mneedle {
namespace {

TEST(BlasThreads, OverlappingLimitsRestoreTheCountWhenTheLastEnds) {
  const int before = blas_threads();
  if (before == 0) GTEST_SKIP() << "this process's BLAS is not OpenBLAS";
  auto first = std::make_unique<BlasThreadLimit>(1);
  EXPECT_EQ(blas_threads(), 1);
  auto second = std::make_unique<BlasThreadLimit>(1);
  first.reset();  // the first ends before the second: still held
  EXPECT_EQ(blas_threads(), 1);
  second.reset();
  EXPECT_EQ(blas_threads(), before);
}

}  // namespace
}  // namespace mneedle
