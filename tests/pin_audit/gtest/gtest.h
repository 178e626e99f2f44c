// Pin audit only (tests/pin_audit/run_pin_audit.sh puts this folder first on the include path):
// GoogleTest itself, with EXPECT_NEAR and ASSERT_NEAR also writing what they compared to the file
// named by MNEEDLE_PIN_AUDIT, so that a pinned value the code no longer reads exactly is seen
// before it drifts out of its tolerance (docs/validation.md, "Pins and what the code reads").
#pragma once
// A system header to the compiler, so that #include_next (a GCC extension) is not warned about
// in every test file.
#pragma GCC system_header
#include_next <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

namespace mneedle_pin_audit {

inline ::testing::AssertionResult near(const char* actual_text, const char* expected_text,
                                       const char* tolerance_text, double actual, double expected,
                                       double tolerance) {
  if (const char* path = std::getenv("MNEEDLE_PIN_AUDIT")) {
    // One line per comparison, appended whole (tests run in parallel processes).
    if (FILE* f = std::fopen(path, "a")) {
      const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
      std::fprintf(f, "%s.%s\t%s\t%s\t%s\t%.17g\t%.17g\t%.17g\n",
                   info ? info->test_suite_name() : "?", info ? info->name() : "?", actual_text,
                   expected_text, tolerance_text, actual, expected, tolerance);
      std::fclose(f);
    }
  }
  return ::testing::internal::DoubleNearPredFormat(actual_text, expected_text, tolerance_text,
                                                   actual, expected, tolerance);
}

}  // namespace mneedle_pin_audit

#undef EXPECT_NEAR
#undef ASSERT_NEAR
#define EXPECT_NEAR(val1, val2, abs_error) \
  EXPECT_PRED_FORMAT3(::mneedle_pin_audit::near, val1, val2, abs_error)
#define ASSERT_NEAR(val1, val2, abs_error) \
  ASSERT_PRED_FORMAT3(::mneedle_pin_audit::near, val1, val2, abs_error)
