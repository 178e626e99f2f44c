#include "mneedle/blas_threads.h"

#include <dlfcn.h>

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

}  // namespace

int blas_threads() {
  const GetThreads get = get_threads();
  return get ? get() : 0;
}

BlasThreadLimit::BlasThreadLimit(int threads) : previous_(blas_threads()) {
  if (const SetThreads set = set_threads(); set && previous_ > 0) set(threads);
}

BlasThreadLimit::~BlasThreadLimit() {
  if (const SetThreads set = set_threads(); set && previous_ > 0) set(previous_);
}

}  // namespace mneedle
