#pragma once
// Splitting a loop over the cores the factorisations use. The work is cut into contiguous
// chunks, one per thread, and each index's result goes to its own slot: the answer does not
// depend on the thread count (docs/performance.md, "The stress criterion's cost").

#include <cstddef>
#include <functional>

namespace mneedle::fe {

/// The threads a loop beside the factorisations may use: OpenBLAS's own count as it stands now
/// (`screen` lowers it to one per job while its jobs run), at most the cores, else 1 where the
/// BLAS is not a dynamic OpenBLAS.
int loop_threads();

/// Calls body(begin, end) on contiguous chunks covering [0, count), on up to `threads` threads
/// (the calling one included; fewer when count is small; the calling one runs those no thread
/// could be started for). Returns once every chunk has ended; an exception thrown by a chunk is
/// rethrown here (the first chunk's, in index order).
void parallel_chunks(std::size_t count, int threads,
                     const std::function<void(std::size_t begin, std::size_t end)>& body);

}  // namespace mneedle::fe
