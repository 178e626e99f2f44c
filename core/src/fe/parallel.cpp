#include "mneedle/fe/parallel.h"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

#include "mneedle/fe/blas_kernels.h"

namespace mneedle::fe {

int loop_threads() {
  return std::max(1, openblas_threads());
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
  for (std::size_t c = 1; c < chunks; ++c) workers.emplace_back(run, c);
  run(0);
  for (std::thread& worker : workers) worker.join();
  for (const std::exception_ptr& error : failed)
    if (error) std::rethrow_exception(error);
}

}  // namespace mneedle::fe
