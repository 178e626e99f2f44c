#include "option_values.h"

#include <gtest/gtest.h>

#include <string>

#include "mneedle/base/error.h"

namespace {

using mneedle::Dimension;
using mneedle::cli::option_length_unit;
using mneedle::cli::option_quantity;
using mneedle::cli::positive_option_quantity;

std::string error_of(void (*call)()) {
  try {
    call();
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(OptionValues, AQuantityIsReadInSiWithItsUnit) {
  EXPECT_NEAR(option_quantity("--step", "10um", Dimension::Length), 10e-6, 1e-18);
  EXPECT_NEAR(option_quantity("--speed", "2 mm/s", Dimension::Speed), 2e-3, 1e-15);
  EXPECT_NEAR(positive_option_quantity("--step", "0.5mm", Dimension::Length), 0.5e-3, 1e-15);
}

// `force --step 10` said only '"10" needs a unit': the option is named first.
TEST(OptionValues, AnErrorNamesTheOptionBeforeTheProblem) {
  const std::string missing = error_of([] { option_quantity("--step", "10", Dimension::Length); });
  EXPECT_EQ(missing.rfind("--step: \"10\" needs a unit: a length", 0), 0u) << missing;
  const std::string wrong = error_of([] { option_quantity("--speed", "2 mm", Dimension::Speed); });
  EXPECT_EQ(wrong.rfind("--speed: ", 0), 0u) << wrong;
}

// plane-strain replaced a zero cell by its default in silence: zero and below are refused.
TEST(OptionValues, APositiveOptionRefusesZeroAndBelowWithTheTextGiven) {
  EXPECT_EQ(error_of([] { positive_option_quantity("--element-size", "0mm", Dimension::Length); }),
            "--element-size 0mm: must be positive");
  EXPECT_EQ(error_of([] { positive_option_quantity("--step", "-1mm", Dimension::Length); }),
            "--step -1mm: must be positive");
}

// inspect and screen said "unknown length unit 'cm'" without naming --unit.
TEST(OptionValues, AMeshUnitIsReadInMetresAndAnUnknownOneNamesTheOption) {
  EXPECT_DOUBLE_EQ(option_length_unit("um"), 1e-6);
  EXPECT_DOUBLE_EQ(option_length_unit("mm"), 1e-3);
  EXPECT_EQ(error_of([] { option_length_unit("cm"); }).rfind("--unit: unknown length unit 'cm'", 0),
            0u);
}

}  // namespace
