// screen --json as a library call: rows in the order given, each with "resumed", the ranking
// keys of the run.
#include "mneedle/api/screening_report.h"

#include <gtest/gtest.h>

namespace mneedle {
namespace {

ScreeningRow row(const std::string& name, double depth, bool resumed) {
  ScreeningRow r;
  r.design = name;
  r.ok = true;
  r.resumed = resumed;
  r.json = nlohmann::json{{"design", name}, {"puncture_depth_m", depth}}.dump();
  return r;
}

TEST(ScreeningReport, RowsKeepTheirOrderAndSayWhetherTheyWereResumed) {
  ScreeningOptions o;
  const nlohmann::json j =
      screening_json({row("b", 1e-4, false), row("a", 2e-4, true)}, "scene.toml", o);
  EXPECT_EQ(j["scene"], "scene.toml");
  EXPECT_EQ(j["fidelity"], o.fidelity);
  ASSERT_EQ(j["designs"].size(), 2u);
  EXPECT_EQ(j["designs"][0]["design"], "b");
  EXPECT_FALSE(j["designs"][0]["resumed"].get<bool>());
  EXPECT_TRUE(j["designs"][1]["resumed"].get<bool>());
  EXPECT_EQ(j["ranking"], nlohmann::json({"puncture_depth_m", "puncture_force_N"}));
}

TEST(ScreeningReport, UncertaintyRunsRankByTheProbabilityOfPassing) {
  ScreeningOptions o;
  o.vary.push_back(parse_varied_value("silicone.E=uniform(0.1MPa,0.3MPa)"));
  const nlohmann::json j = screening_json({}, "s.toml", o);
  EXPECT_EQ(j["ranking"][0], "uncertainty.pass_probability");
}

}  // namespace
}  // namespace mneedle
