// Runs the built `mneedle simulate` on small axisymmetric scenes and checks exit status and
// output.

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

std::string scene(const std::string& name) {
  return std::string(MNEEDLE_TEST_ASSETS) + "/scenes/" + name;
}

TEST(CmdSimulate, FlatPunchJsonHasTheIssueKeysAndAPlausibleForce) {
  const CommandRun run = run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["mesh"]["axisymmetric"].get<bool>());
  EXPECT_EQ(j["mesh"]["order"].get<int>(), 2);
  EXPECT_GT(j["mesh"]["nodes"].get<int>(), 0);
  const auto& needle = j["needles"].at(0);
  EXPECT_EQ(needle["name"], "punch");
  const auto& last = needle["curve"].back();
  EXPECT_NEAR(last["depth_m"].get<double>(), 50e-6, 1e-12);
  for (const char* key : {"force_N", "contact_area_m2", "contact_pressure_Pa", "strain_energy_J"})
    EXPECT_TRUE(last.contains(key)) << key;
  EXPECT_EQ(last["lateral_force_N"].size(), 2u);
  // Boussinesq 2 a E* d with a = 115 um, E = 0.2 MPa, nu = 0.45, d = 50 um: 2.88 mN; the
  // 1.15 mm layer (a/h = 0.1) and the bonded contact add about 10 %.
  EXPECT_NEAR(last["force_N"].get<double>(), 3.2e-3, 0.3e-3);
  const double a = 115e-6;
  EXPECT_NEAR(last["contact_area_m2"].get<double>(), M_PI * a * a, 1e-3 * M_PI * a * a);
}

TEST(CmdSimulate, CsvHasOneRowPerDepth) {
  const CommandRun run = run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(run.out);
  std::string header, row;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("depth_m,force_N,", 0), 0u);
  int rows = 0;
  while (std::getline(lines, row)) rows += row.empty() ? 0 : 1;
  EXPECT_EQ(rows, 10);  // fast fidelity: 10 output depths
}

TEST(CmdSimulate, AxisymmetricModelRefusesABevelClearly) {
  const CommandRun run =
      run_mneedle("simulate '" + scene("bevel_needs_3d.toml") + "' --model axisymmetric");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("bevel_needs_3d.toml:"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("3-D model"), std::string::npos) << run.err;
}

TEST(CmdSimulate, BevelRunsIn3dWithALateralForce) {
  const CommandRun run = run_mneedle("simulate '" + scene("bevel_3d_linear.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_FALSE(j["mesh"]["axisymmetric"].get<bool>());
  const auto& last = j["needles"][0]["curve"].back();
  EXPECT_NEAR(last["depth_m"].get<double>(), 50e-6, 1e-12);
  EXPECT_GT(last["force_N"].get<double>(), 0.0);
  // The bevel faces one side: the tissue pushes it sideways, along x in the plugin's frame.
  EXPECT_GT(std::abs(last["lateral_force_N"][0].get<double>()), 0.0);
  EXPECT_NEAR(last["lateral_force_N"][1].get<double>(), 0.0, 1e-9);
}

TEST(CmdSimulate, FrictionlessIsRefusedUntilImplemented) {
  const CommandRun run =
      run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --contact frictionless");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("frictionless"), std::string::npos) << run.err;
}

}  // namespace
