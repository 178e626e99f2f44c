// `mneedle screen` and `mneedle strength` end to end: the README's main job, bad designs among good
// ones, results kept on disk, JSON with units in its keys.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::run_mneedle;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;
const std::string kSkin = kRoot + "/designs/scenes/human_skin.toml";

TEST(ScreenCommand, ReadmeMainJobRanksEveryShippedDesign) {
  const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["designs"].size(), 4u);
  double previous = 0.0;
  for (const auto& d : j["designs"]) {
    EXPECT_TRUE(d["ok"].get<bool>()) << d.dump();
    EXPECT_GT(d["peak_force_N"].get<double>(), 0.0);
    EXPECT_GT(d["capacity_N"].get<double>(), 0.0);
    EXPECT_TRUE(d["puncture"].is_null());
    if (d["passes"].get<bool>()) {
      EXPECT_GE(d["peak_force_N"].get<double>(), previous);
      previous = d["peak_force_N"].get<double>();
    }
  }
}

TEST(ScreenCommand, BrokenDesignGetsAnErrorRowAndTheOthersAreKept) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_screen_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  fs::copy_file(kRoot + "/designs/cone.stl", dir / "in" / "cone.stl");
  fs::copy_file(std::string(MNEEDLE_TEST_ASSETS) + "/meshes/open_box.stl",
                dir / "in" / "broken.stl");
  const auto run = run_mneedle("screen '" + (dir / "in").string() + "' --scene '" + kSkin +
                               "' --out '" + (dir / "out").string() + "'");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("1 of 2 designs failed"), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("not closed"), std::string::npos) << run.out;
  std::ifstream jsonl(dir / "out" / "results.jsonl");
  int lines = 0;
  for (std::string line; std::getline(jsonl, line);) ++lines;
  EXPECT_EQ(lines, 2);
  fs::remove_all(dir);
}

TEST(ScreenCommand, ResumeWithoutOutIsAnError) {
  const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin + "' --resume");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--resume needs --out"), std::string::npos) << run.err;
}

TEST(StrengthCommand, CylinderPluginBucklesAtEulersLoadOverTheWholeLength) {
  // Silicon cylinder 230 µm × 1 mm, flat tip (load from the tip), fixed-free: π²EI/(2L)².
  const auto run = run_mneedle(
      "strength --plugin cylinder --set diameter=230um --set length=1mm --material silicon "
      "--end fixed-free --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const double pi = 3.14159265358979323846, r = 115e-6, length = 1e-3, e = 169e9;
  const double euler = pi * pi * e * (pi * r * r * r * r / 4.0) / (4.0 * length * length);
  EXPECT_NEAR(j["elastic_buckling_N"].get<double>() / euler, 1.0, 1e-3);
  EXPECT_EQ(j["governing"], "buckling");
  EXPECT_DOUBLE_EQ(j["effective_length_factor"].get<double>(), 2.0);
  for (const char* key :
       {"material", "E_Pa", "I_min_m4", "length_m", "buckling_N", "strength_N", "capacity_N"})
    EXPECT_TRUE(j.contains(key)) << key;
}

TEST(StrengthCommand, MeshFileAndPluginAgree) {
  const auto plugin = run_mneedle("strength --plugin sharp_bevel --material silicon --json");
  const auto mesh =
      run_mneedle("strength '" + kRoot + "/designs/sharp_bevel.stl' --material silicon --json");
  ASSERT_EQ(plugin.exit_code, 0) << plugin.err;
  ASSERT_EQ(mesh.exit_code, 0) << mesh.err;
  const auto a = nlohmann::json::parse(plugin.out), b = nlohmann::json::parse(mesh.out);
  EXPECT_NEAR(b["capacity_N"].get<double>() / a["capacity_N"].get<double>(), 1.0, 0.02);
}

TEST(StrengthCommand, UnknownMaterialAndMissingNeedleAreClearErrors) {
  auto run = run_mneedle("strength --plugin cone --material unobtainium");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("unknown needle material 'unobtainium'"), std::string::npos) << run.err;
  run = run_mneedle("strength --material silicon");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("either a mesh FILE or --plugin"), std::string::npos) << run.err;
}

TEST(OptimizeCommand, SearchesABevelAngleAndWritesItsOutputs) {
  const fs::path dir =
      fs::temp_directory_path() / ("mneedle_optimize_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSkin +
                               "' --vary bevel_angle --bound bevel_angle=20deg:60deg"
                               " --material silicon --max-evals 25 --json --out '" +
                               dir.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["feasible"].get<bool>());
  EXPECT_EQ(j["algorithm"], "cobyla");
  EXPECT_TRUE(j["best"]["puncture_depth_m"].is_null());
  // A sharper bevel carries less post-puncture load here: the search goes to the lower bound.
  const double angle = j["best"]["params"]["bevel_angle"].get<double>();
  EXPECT_NEAR(angle, 20.0 * 3.14159265358979323846 / 180.0, 0.01);
  EXPECT_TRUE(fs::exists(dir / "best.stl"));
  EXPECT_TRUE(fs::exists(dir / "history.csv"));
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  fs::remove_all(dir);
}

TEST(OptimizeCommand, UnknownParameterIsAClearError) {
  const auto run = run_mneedle("optimize --plugin cone --scene '" + kSkin + "' --vary bevel_angle");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("has no parameter 'bevel_angle'"), std::string::npos) << run.err;
  const auto negative = run_mneedle("optimize --plugin cone --scene '" + kSkin +
                                    "' --vary half_angle --min-feature -5um");
  EXPECT_EQ(negative.exit_code, 1);
  EXPECT_NE(negative.err.find("--min-feature"), std::string::npos) << negative.err;
}

}  // namespace
