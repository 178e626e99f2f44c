// The finite gate: every NaN/Inf in a JSON tree, a CSV row or a single number is refused with a
// SolverError that names where it is; finite trees pass unchanged.
#include "mneedle/api/finite_json.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "error_message.h"
#include "mneedle/base/error.h"

namespace mneedle {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::string message_of(const auto& call) {
  return testing::error_message<SolverError>(call);
}

TEST(FiniteJson, FiniteTreePasses) {
  const nlohmann::json tree = {{"needles", {{{"name", "a"}, {"force_N", 1.5e-3}, {"n", 3}}}},
                               {"ok", true},
                               {"missing", nullptr},
                               {"max_double", std::numeric_limits<double>::max()}};
  EXPECT_NO_THROW(require_finite_json(tree, "force"));
}

TEST(FiniteJson, NaNDeepInAnArrayIsNamedByItsPath) {
  nlohmann::json tree = {{"needles", nlohmann::json::array()}};
  tree["needles"].push_back({{"name", "a"}, {"curve", {{{"depth_m", 0.0}, {"force_N", 0.0}}}}});
  tree["needles"].push_back(
      {{"name", "b"}, {"curve", {{{"depth_m", 0.0}, {"force_N", 1.0}}, {{"force_N", kNaN}}}}});
  const std::string m = message_of([&] { require_finite_json(tree, "mneedle force"); });
  EXPECT_EQ(m, "mneedle force: non-finite value NaN at needles[1].curve[1].force_N");
}

TEST(FiniteJson, InfinityIsRefusedWithItsSign) {
  nlohmann::ordered_json tree = {{"a", {{"b", -kInf}}}};
  EXPECT_EQ(message_of([&] { require_finite_json(tree, "scene"); }),
            "scene: non-finite value -Inf at a.b");
  tree = {{"x", {1.0, kInf}}};
  EXPECT_EQ(message_of([&] { require_finite_json(tree, "scene"); }),
            "scene: non-finite value +Inf at x[1]");
}

TEST(FiniteJson, TopLevelNumberIsNamed) {
  EXPECT_EQ(message_of([] { require_finite_json(nlohmann::json(kNaN), "c"); }),
            "c: non-finite value NaN at the top level");
}

TEST(FiniteJson, SingleNumbersAndCsvRows) {
  EXPECT_EQ(require_finite(2.5, "force_N", "c"), 2.5);
  EXPECT_EQ(message_of([] { require_finite(kNaN, "force_N", "strength"); }),
            "strength: non-finite value NaN at force_N");
  EXPECT_NO_THROW(require_finite_row({1.0, 2.0}, {"depth_m", "force_N"}, "row 1", "c"));
  EXPECT_EQ(message_of([] {
              require_finite_row({1.0, kInf}, {"depth_m", "force_N"}, "needle a, row 4", "csv");
            }),
            "csv: non-finite value +Inf at needle a, row 4, force_N");
  EXPECT_EQ(message_of([] { require_finite_row({kNaN}, {}, "row 2", "csv"); }),
            "csv: non-finite value NaN at row 2, column 1");
}

}  // namespace
}  // namespace mneedle
