// Runs the built `mneedle force` on scenes and checks exit status and output.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include "run_mneedle.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {

using mneedle::test::CommandRun;
using mneedle::test::run_mneedle;

std::string scene_asset(const std::string& name) {
  return std::string(MNEEDLE_TEST_ASSETS) + "/scenes/" + name;
}

std::string design(const std::string& name) {
  return std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/" + name;
}

class ForceCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(std::string(MNEEDLE_BINARY_ROOT) + "/cli/mneedle")) {
      FAIL() << "the mneedle binary is not built: build target mneedle_cli first";
    }
  }
};

TEST_F(ForceCommand, JsonGivesOneCurveOfFiniteSummedLoadsPerNeedle) {
  const CommandRun run =
      run_mneedle("force '" + scene_asset("stl_needle.toml") + "' --json --step 100um");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  ASSERT_EQ(out["needles"].size(), 2u);
  for (const auto& needle : out["needles"]) {
    const auto& curve = needle["curve"];
    ASSERT_EQ(curve.size(), 6u);  // 0 to the scene's 0.5 mm in 0.1 mm steps
    EXPECT_DOUBLE_EQ(curve[0]["force_N"].get<double>(), 0.0);
    EXPECT_NEAR(curve[5]["depth_m"].get<double>(), 0.5e-3, 1e-12);
    for (const auto& p : curve) {
      const double sum =
          p["alpha_N"].get<double>() + p["beta_N"].get<double>() + p["friction_N"].get<double>();
      EXPECT_TRUE(std::isfinite(p["force_N"].get<double>()));
      EXPECT_NEAR(p["force_N"].get<double>(), sum, 1e-15);
    }
    EXPECT_GT(curve[5]["force_N"].get<double>(), curve[1]["force_N"].get<double>());
  }
}

TEST_F(ForceCommand, CsvHasTheNeedleColumnAndOneRowPerDepth) {
  const CommandRun run =
      run_mneedle("force '" + scene_asset("stl_needle.toml") + "' --csv --step 250um");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(run.out);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header, "needle,depth_m,force_N,alpha_N,beta_N,friction_N");
  int rows = 0;
  for (std::string line; std::getline(lines, line);) ++rows;
  EXPECT_EQ(rows, 2 * 3);
}

TEST_F(ForceCommand, PluginBevelInSiliconeLoadsBetaAndFrictionOnly) {
  const CommandRun run = run_mneedle("force '" + design("silicone_phantom.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  const auto& last = out["needles"][0]["curve"].back();
  EXPECT_GT(last["beta_N"].get<double>(), 0.0);
  EXPECT_GT(last["friction_N"].get<double>(), 0.0);
}

TEST_F(ForceCommand, NonPositiveStepIsAnErrorNamingTheOption) {
  const CommandRun run = run_mneedle("force '" + scene_asset("stl_needle.toml") + "' --step 0um");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--step"), std::string::npos) << run.err;
}

TEST_F(ForceCommand, MissingSceneIsAnError) {
  const CommandRun run = run_mneedle("force '" + scene_asset("no_such_scene.toml") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("mneedle: error:"), std::string::npos) << run.err;
}

}  // namespace
