#include "mneedle/fe/parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "mneedle/fe/blas_kernels.h"

namespace mneedle::fe {
namespace {

// Runs parallel_chunks and returns the chunks it made, sorted by their start.
std::vector<std::pair<std::size_t, std::size_t>> chunks_of(std::size_t count, int threads) {
  std::mutex guard;
  std::vector<std::pair<std::size_t, std::size_t>> chunks;
  parallel_chunks(count, threads, [&](std::size_t begin, std::size_t end) {
    std::lock_guard<std::mutex> lock(guard);
    chunks.emplace_back(begin, end);
  });
  std::sort(chunks.begin(), chunks.end());
  return chunks;
}

TEST(ParallelChunks, ChunksCoverTheRangeOnceInContiguousPieces) {
  for (std::size_t count : {1u, 2u, 7u, 1000u})
    for (int threads : {1, 2, 3, 8}) {
      const auto chunks = chunks_of(count, threads);
      ASSERT_FALSE(chunks.empty());
      EXPECT_LE(chunks.size(), std::min<std::size_t>(count, static_cast<std::size_t>(threads)));
      std::size_t next = 0;
      for (const auto& [begin, end] : chunks) {
        EXPECT_EQ(begin, next) << count << " items on " << threads << " threads";
        EXPECT_LT(begin, end);
        next = end;
      }
      EXPECT_EQ(next, count);
    }
}

TEST(ParallelChunks, NothingToDoCallsNothing) {
  EXPECT_TRUE(chunks_of(0, 4).empty());
}

TEST(ParallelChunks, ANonPositiveThreadCountRunsOneChunk) {
  EXPECT_EQ(chunks_of(10, 0).size(), 1u);
  EXPECT_EQ(chunks_of(10, -3).size(), 1u);
}

TEST(ParallelChunks, EachIndexWritingItsOwnSlotGivesTheSameResultOnAnyThreadCount) {
  const auto run = [](int threads) {
    std::vector<double> out(5000);
    parallel_chunks(out.size(), threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        double sum = 0.0;
        for (std::size_t j = 1; j <= i % 97 + 1; ++j) sum += 1.0 / static_cast<double>(i + j);
        out[i] = sum;
      }
    });
    return out;
  };
  const std::vector<double> one = run(1);
  EXPECT_EQ(run(2), one);
  EXPECT_EQ(run(5), one);
}

TEST(ParallelChunks, AChunksExceptionReachesTheCallerAfterEveryChunkEnded) {
  std::mutex guard;
  std::size_t done = 0;
  EXPECT_THROW(parallel_chunks(100, 4,
                               [&](std::size_t begin, std::size_t end) {
                                 if (begin == 50) throw std::runtime_error("chunk failed");
                                 std::lock_guard<std::mutex> lock(guard);
                                 done += end - begin;
                               }),
               std::runtime_error);
  EXPECT_EQ(done, 75u);  // the other three chunks of 25 ran to their end
}

TEST(LoopThreads, FollowsOpenBlasWithinOneAndTheCores) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_GE(loop_threads(), 1);
  EXPECT_LE(loop_threads(), cores);
  const int blas = openblas_threads();
  if (blas > 0) {
    EXPECT_EQ(loop_threads(), std::min(blas, cores));
  }
}

}  // namespace
}  // namespace mneedle::fe
