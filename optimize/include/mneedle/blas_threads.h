#pragma once
// Parallel screening runs several CHOLMOD factorisations at once; each would otherwise start as
// many OpenBLAS threads as there are cores and oversubscribe them. This caps OpenBLAS's threads
// process-wide while parallel jobs run.

namespace mneedle {

/// OpenBLAS's current thread count, or 0 when the BLAS in this process is not OpenBLAS.
int blas_threads();

/// Holds OpenBLAS at `threads` for its lifetime and restores the previous count afterwards.
/// Limits that overlap (from several threads) share one: the first sets it, the last restores
/// the count from before the first (every caller asks for one thread). Does nothing when the
/// BLAS is not OpenBLAS (reference BLAS is single-threaded anyway).
class BlasThreadLimit {
 public:
  explicit BlasThreadLimit(int threads);
  ~BlasThreadLimit();
  BlasThreadLimit(const BlasThreadLimit&) = delete;
  BlasThreadLimit& operator=(const BlasThreadLimit&) = delete;
};

}  // namespace mneedle
