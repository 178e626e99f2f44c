#pragma once
// The real recordings beside the repository (../shared/refdata): tests that read them skip with
// a message where they are absent, and fail where they are required — `.ci/run` sets
// MNEEDLE_REQUIRE_REFDATA, so CI cannot pass by skipping them.

#include <cstdlib>
#include <filesystem>

namespace mneedle::test {

inline std::filesystem::path refdata_dir() {
  return std::filesystem::path(MNEEDLE_SOURCE_ROOT) / ".." / "shared" / "refdata";
}

inline bool refdata_required() {
  return std::getenv("MNEEDLE_REQUIRE_REFDATA") != nullptr;
}

}  // namespace mneedle::test

/// In a TEST body: FAIL when `file` is absent and refdata is required, else skip.
#define MNEEDLE_NEED_REFDATA(file)                                                     \
  do {                                                                                 \
    if (!std::filesystem::exists(file)) {                                              \
      if (::mneedle::test::refdata_required())                                         \
        FAIL() << "refdata required (MNEEDLE_REQUIRE_REFDATA) but absent: " << (file); \
      GTEST_SKIP() << "refdata absent: " << (file);                                    \
    }                                                                                  \
  } while (false)
