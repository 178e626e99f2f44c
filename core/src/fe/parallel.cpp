#include "mneedle/fe/parallel.h"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

#include "mneedle/fe/blas_kernels.h"

namespace mneedle::fe {

int loop_threads() {
  // OpenBLAS takes OPENBLAS_NUM_THREADS above the core count as given; a loop gains nothing from
  // more threads than cores.
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::clamp(openblas_threads(), 1, cores);
}

void parallel_chunks(std::size_t count, int threads,
                     const std::function<void(std::size_t begin, std::size_t end)>& body) {
  if (count == 0) return;
  const std::size_t chunks = std::min(count, static_cast<std::size_t>(std::max(1, threads)));
  if (chunks == 1) {
    body(0, count);
    return;
  }
  // Chunk c covers [c * count / chunks, (c + 1) * count / chunks): the calling thread runs the
  // first, each other one a thread of its own.
  const auto bound = [&](std::size_t c) { return c * count / chunks; };
  std::vector<std::exception_ptr> failed(chunks);
  const auto run = [&](std::size_t c) {
    try {
      body(bound(c), bound(c + 1));
    } catch (...) {
      failed[c] = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  workers.reserve(chunks - 1);
  std::size_t started = 1;
  try {
    for (; started < chunks; ++started) workers.emplace_back(run, started);
  } catch (...) {
    // No thread to be had (std::system_error, or std::bad_alloc from its start): the calling
    // thread runs the chunks not started, and the started threads are still joined below (an
    // unjoined one would end the process).
  }
  run(0);
  for (std::size_t c = started; c < chunks; ++c) run(c);
  for (std::thread& worker : workers) worker.join();
  for (const std::exception_ptr& error : failed)
    if (error) std::rethrow_exception(error);
}

}  // namespace mneedle::fe
