#pragma once
// The process's memory use as the operating system counts it, for run reports.

#include <cstddef>

namespace mneedle {

/// Peak resident set of this process so far (bytes): getrusage's ru_maxrss. It covers the whole
/// process, so a report of one run is exact only when the process did nothing bigger before.
std::size_t peak_memory_bytes();

}  // namespace mneedle
