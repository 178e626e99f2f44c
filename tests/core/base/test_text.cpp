#include "mneedle/base/text.h"

#include <gtest/gtest.h>

namespace mneedle {
namespace {

TEST(Text, TrimDropsSpacesTabsAndLineEndsAtBothEnds) {
  EXPECT_EQ(trim(" \t a b \r\n"), "a b");
}

TEST(Text, TrimOfBlankTextIsEmpty) {
  EXPECT_EQ(trim(" \t\r\n"), "");
  EXPECT_EQ(trim(""), "");
}

TEST(Text, TrimKeepsQuotes) {
  EXPECT_EQ(trim(" \"x\" "), "\"x\"");
}

// `force --step 1e-30m` said "199999999999 points" for 2e27 (its 12 characters of the number)
// and `--step 1nm` "2000000.0000 points".
TEST(Text, CountTextIsWholeBelowTenMillionAndThreeDigitsAbove) {
  EXPECT_EQ(count_text(2000000.0), "2000000");
  EXPECT_EQ(count_text(1999999.2), "2000000");
  EXPECT_EQ(count_text(0.0), "0");
  EXPECT_EQ(count_text(2e27), "2e+27");
  EXPECT_EQ(count_text(40000000.0), "4e+07");
  EXPECT_EQ(count_text(12345678.0), "1.23e+07");
}

TEST(Text, EditDistanceCountsInsertionsDeletionsAndSubstitutionsIgnoringCase) {
  EXPECT_EQ(edit_distance("scren", "screen"), 1u);
  EXPECT_EQ(edit_distance("chek", "check"), 1u);
  EXPECT_EQ(edit_distance("SCREEN", "screen"), 0u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
}

}  // namespace
}  // namespace mneedle
