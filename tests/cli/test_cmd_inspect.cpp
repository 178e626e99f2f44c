// Runs the built `mneedle inspect` on the crafted meshes and checks exit status and output.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include "run_mneedle.h"

#include <algorithm>
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

std::string asset(const std::string& name) {
  return std::string(MNEEDLE_TEST_ASSETS) + "/meshes/" + name;
}

class InspectCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(std::string(MNEEDLE_BINARY_ROOT) + "/cli/mneedle")) {
      FAIL() << "the mneedle binary is not built: build target mneedle_cli first";
    }
  }
};

TEST_F(InspectCommand, ValidMeshJsonReportsGeometryAndFrame) {
  const CommandRun run = run_mneedle("inspect '" + asset("pyramid_binary.stl") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["file"], asset("pyramid_binary.stl"));
  EXPECT_EQ(out["unit"], "mm");
  EXPECT_EQ(out["valid"], true);
  EXPECT_EQ(out["triangles"], 6);
  EXPECT_NEAR(out["volume_m3"].get<double>(), 4e-9, 1e-14);
  EXPECT_NEAR(out["area_m2"].get<double>(), (4.0 + 4.0 * std::sqrt(10.0)) * 1e-6, 1e-12);
  EXPECT_NEAR(out["bounding_box_m"]["min"][2].get<double>(), 1e-3, 1e-12);
  EXPECT_NEAR(out["bounding_box_m"]["max"][2].get<double>(), 4e-3, 1e-12);
  EXPECT_EQ(out["axis"], nlohmann::json::array({0.0, 0.0, -1.0}));
  EXPECT_NEAR(out["tip_m"][0].get<double>(), 0.5e-3, 1e-12);
  EXPECT_NEAR(out["tip_m"][1].get<double>(), 0.25e-3, 1e-12);
  EXPECT_NEAR(out["tip_m"][2].get<double>(), 1e-3, 1e-12);
  EXPECT_TRUE(out["errors"].empty());
  EXPECT_TRUE(out["repairs"].empty());
}

TEST_F(InspectCommand, UnitScalesTheReport) {
  const CommandRun run = run_mneedle("inspect '" + asset("pyramid.obj") + "' --unit um --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["unit"], "um");
  EXPECT_NEAR(out["volume_m3"].get<double>(), 4e-18, 1e-23);
}

TEST_F(InspectCommand, ValidMeshTextSummary) {
  const CommandRun run = run_mneedle("inspect '" + asset("pyramid.off") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("valid"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("triangles:    6"), std::string::npos) << run.out;
  EXPECT_TRUE(run.err.empty()) << run.err;
}

TEST_F(InspectCommand, OpenMeshTextIsOneLineOnStderrAndExitOne) {
  const CommandRun run = run_mneedle("inspect '" + asset("open_box.stl") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(run.out.empty()) << run.out;
  EXPECT_NE(run.err.find(asset("open_box.stl") + ": mesh is not closed (4 border edges)"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

TEST_F(InspectCommand, OpenMeshJsonSaysInvalidAndExitsNonZero) {
  const CommandRun run = run_mneedle("inspect '" + asset("open_box.stl") + "' --json");
  EXPECT_NE(run.exit_code, 0);
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["valid"], false);
  ASSERT_EQ(out["errors"].size(), 1u);
  EXPECT_EQ(out["errors"][0], "mesh is not closed (4 border edges)");
}

TEST_F(InspectCommand, RepairFixesInwardMeshAndSaysWhat) {
  const CommandRun run = run_mneedle("inspect '" + asset("all_flipped.stl") + "' --repair --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["valid"], true);
  EXPECT_EQ(out["repairs"], nlohmann::json::array({"reoriented 6 faces"}));
  EXPECT_GT(out["volume_m3"].get<double>(), 0.0);
}

// The repaired mesh is written (and then loads valid without --repair, its unit read back from
// the header); a mesh the repair cannot fix writes nothing.
TEST_F(InspectCommand, RepairWritesTheFixedMeshOnlyWhenItIsValid) {
  const auto fixed = std::filesystem::temp_directory_path() /
                     ("mneedle_fixed_" + std::to_string(::getpid()) + ".stl");
  const CommandRun run = run_mneedle("inspect '" + asset("all_flipped.stl") +
                                     "' --repair --json -o '" + fixed.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const CommandRun again = run_mneedle("inspect '" + fixed.string() + "' --json");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto before = nlohmann::json::parse(run.out), after = nlohmann::json::parse(again.out);
  EXPECT_TRUE(after["repairs"].empty());
  EXPECT_NEAR(after["volume_m3"].get<double>(), before["volume_m3"].get<double>(),
              1e-6 * before["volume_m3"].get<double>());  // float32 STL coordinates
  std::filesystem::remove(fixed);
  const CommandRun broken = run_mneedle("inspect '" + asset("self_intersecting.stl") +
                                        "' --repair -o '" + fixed.string() + "'");
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_FALSE(std::filesystem::exists(fixed));
}

TEST_F(InspectCommand, InwardMeshWithoutRepairFails) {
  const CommandRun run = run_mneedle("inspect '" + asset("all_flipped.stl") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("inward-oriented"), std::string::npos) << run.err;
}

TEST_F(InspectCommand, RepairThatCannotHelpStillFails) {
  const CommandRun run = run_mneedle("inspect '" + asset("self_intersecting.stl") + "' --repair");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("self-intersects"), std::string::npos) << run.err;
}

TEST_F(InspectCommand, UnreadableFileJsonCarriesTheError) {
  const CommandRun run = run_mneedle("inspect '" + asset("truncated_binary.stl") + "' --json");
  EXPECT_NE(run.exit_code, 0);
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["valid"], false);
  EXPECT_NE(out["errors"][0].get<std::string>().find("truncated binary STL"), std::string::npos);
  EXPECT_NE(run.err.find("truncated binary STL"), std::string::npos) << run.err;
}

TEST_F(InspectCommand, MissingFileFails) {
  const CommandRun run = run_mneedle("inspect '" + asset("does_not_exist.stl") + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("file not found"), std::string::npos) << run.err;
}

TEST_F(InspectCommand, AutoAxisReportsChosenEnd) {
  const CommandRun run =
      run_mneedle("inspect '" + asset("pyramid_ascii.ply") + "' --axis auto --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_NE(out["frame_note"].get<std::string>().find("auto axis"), std::string::npos);
}

TEST_F(InspectCommand, GivenAxisMovesTheTip) {
  const CommandRun run =
      run_mneedle("inspect '" + asset("pyramid_ascii.stl") + "' --axis 0,0,1 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["axis"], nlohmann::json::array({0.0, 0.0, 1.0}));
  EXPECT_NEAR(out["tip_m"][2].get<double>(), 4e-3, 1e-12);  // the flat base is now the tip
}

TEST_F(InspectCommand, MalformedAxisIsRejected) {
  const CommandRun run = run_mneedle("inspect '" + asset("pyramid_ascii.stl") + "' --axis 1,2");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--axis"), std::string::npos) << run.err;
}

TEST_F(InspectCommand, UnknownUnitIsRejected) {
  const CommandRun run = run_mneedle("inspect '" + asset("pyramid_ascii.stl") + "' --unit furlong");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("furlong"), std::string::npos) << run.err;
}

TEST_F(InspectCommand, JsonGroupsTheShippedCylindersFacesAndGivesTipAreas) {
  const std::string file = std::string(MNEEDLE_SOURCE_ROOT) + "/designs/cylinder.stl";
  const CommandRun run = run_mneedle("inspect '" + file + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const double r = 115e-6, pi = 3.14159265358979323846;
  // The flat end is the only alpha face group; no beta faces on a cylinder.
  EXPECT_NEAR(j["groups"]["alpha"]["area_m2"].get<double>() / (pi * r * r), 1.0, 0.005);
  EXPECT_EQ(j["groups"]["beta"]["count"].get<int>(), 0);
  ASSERT_FALSE(j["tip_area"].empty());
  EXPECT_NEAR(j["tip_area"][0]["area_m2"].get<double>() / (pi * r * r), 1.0, 0.005);
}

}  // namespace
