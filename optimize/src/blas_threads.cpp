#include "mneedle/blas_threads.h"

#include <dlfcn.h>

#include <mutex>

#include "mneedle/fe/blas_kernels.h"

namespace mneedle {
namespace {

// Looked up at run time: CHOLMOD reaches OpenBLAS through Debian's libblas.so.3 alternative, so
// whether these exist depends on the machine, not on what mneedle was linked against.
using GetThreads = int (*)();
using SetThreads = void (*)(int);

GetThreads get_threads() {
  return reinterpret_cast<GetThreads>(::dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
}

SetThreads set_threads() {
  return reinterpret_cast<SetThreads>(::dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
}

// Limits may overlap (two Python threads each screening with jobs > 1): the first one saves the
// count and sets the limit, the last one restores it, so overlapping limits never leave
// OpenBLAS at the limit.
std::mutex limit_mutex;
int active_limits = 0;
int saved_threads = 0;

}  // namespace

int blas_threads() {
  const GetThreads get = get_threads();
  return get ? get() : 0;
}

BlasThreadLimit::BlasThreadLimit(int threads) {
  // The threads about to share OpenBLAS must find its kernels chosen (fe/blas_kernels.h).
  fe::select_blas_kernels();
  std::lock_guard<std::mutex> lock(limit_mutex);
  if (active_limits++ > 0) return;
  saved_threads = blas_threads();
  if (const SetThreads set = set_threads(); set && saved_threads > 0) set(threads);
}

BlasThreadLimit::~BlasThreadLimit() {
  std::lock_guard<std::mutex> lock(limit_mutex);
  if (--active_limits > 0) return;
  if (const SetThreads set = set_threads(); set && saved_threads > 0) set(saved_threads);
}

}  // namespace mneedle
