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

}  // namespace
}  // namespace mneedle
