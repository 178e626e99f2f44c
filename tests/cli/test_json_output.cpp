// Printing a command's JSON: a finite tree is printed with the run's provenance; a tree with a
// NaN or Inf prints nothing (the gate itself: tests/api/test_finite_json.cpp).
#include "json_output.h"

#include <gtest/gtest.h>

#include <limits>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle::cli {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(JsonOutput, FiniteTreePrintsWithProvenance) {
  const nlohmann::json tree = {{"needles", {{{"name", "a"}, {"force_N", 1.5e-3}, {"n", 3}}}},
                               {"ok", true},
                               {"missing", nullptr},
                               {"max_double", std::numeric_limits<double>::max()}};
  std::ostringstream out;
  print_checked_json(out, tree, "force");
  nlohmann::json printed = nlohmann::json::parse(out.str());
  // the run's provenance joins every printed object (docs/cli.md, "Provenance")
  ASSERT_TRUE(printed.contains("provenance"));
  EXPECT_EQ(printed["provenance"]["tool"], "mneedle");
  printed.erase("provenance");
  EXPECT_EQ(printed, tree);
}

TEST(JsonOutput, PrintWritesNothingWhenTheTreeIsNotFinite) {
  std::ostringstream out;
  EXPECT_THROW(print_checked_json(out, nlohmann::json{{"v", kNaN}}, "c"), SolverError);
  EXPECT_TRUE(out.str().empty());
}

}  // namespace
}  // namespace mneedle::cli
