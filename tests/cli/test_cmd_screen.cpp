// `mneedle screen` and `mneedle strength` end to end: the README's main job ranked by puncture
// depth, bad designs among good ones, results kept on disk, JSON with units in its keys.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::run_mneedle;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;
const std::string kSkin = kRoot + "/designs/scenes/human_skin.toml";

TEST(ScreenCommand, ReadmeMainJobRanksEveryShippedDesignByPunctureDepth) {
  const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["designs"].size(), 4u);
  EXPECT_EQ(j["fidelity"], "fast");
  // What the README says of this table: the cone and the sharp bevel fire at first contact (the
  // first depth step, 10 um), the blunt bevel and the cylinder do not puncture within 200 um.
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& d : j["designs"]) {
    EXPECT_TRUE(d["ok"].get<bool>()) << d.dump();
    EXPECT_GT(d["peak_force_N"].get<double>(), 0.0);
    EXPECT_GT(d["capacity_N"].get<double>(), 0.0);
    EXPECT_DOUBLE_EQ(d["target_depth_m"].get<double>(), 200e-6);
    by_name[d["design"].get<std::string>()] = d;
  }
  for (const char* sharp : {"cone", "sharp_bevel"}) {
    ASSERT_TRUE(by_name[sharp]["punctured"].get<bool>()) << sharp;
    EXPECT_TRUE(by_name[sharp]["puncture_at_first_contact"].get<bool>()) << sharp;
    EXPECT_DOUBLE_EQ(by_name[sharp]["puncture_depth_m"].get<double>(), 10e-6) << sharp;
  }
  for (const char* blunt : {"blunt_bevel", "cylinder"}) {
    EXPECT_FALSE(by_name[blunt]["punctured"].get<bool>()) << blunt;
    EXPECT_TRUE(by_name[blunt]["puncture_depth_m"].is_null()) << blunt;
    EXPECT_FALSE(by_name[blunt]["passes"].get<bool>()) << blunt;
  }
  // The ranking's invariants: punctured rows first, each within the target depth and at a force
  // no larger than the peak its curve reaches.
  bool seen_unpunctured = false;
  for (const auto& d : j["designs"]) {
    if (!d["punctured"].get<bool>()) {
      seen_unpunctured = true;
      continue;
    }
    EXPECT_FALSE(seen_unpunctured) << "a punctured design ranked after one that is not";
    EXPECT_GT(d["puncture_depth_m"].get<double>(), 0.0);
    EXPECT_LE(d["puncture_depth_m"].get<double>(), 200e-6);
    EXPECT_GT(d["puncture_force_N"].get<double>(), 0.0);
    EXPECT_LE(d["puncture_force_N"].get<double>(), d["peak_force_N"].get<double>() * (1 + 1e-9));
  }
}

TEST(ScreenCommand, DepthAtFirstContactIsMarkedAndRankedAfterResolvedBeforeNone) {
  // On the analytic model in skin the flat punch's F / A_sec is above 3 MPa at the first depth
  // step (its edge is singular): a puncture "at first contact", whose depth is the step's. The
  // sharp bevel's falls below the threshold (the stratum corneum spreads the load): no puncture.
  const std::string designs =
      "'" + kRoot + "/designs/cylinder.stl' '" + kRoot + "/designs/sharp_bevel.stl'";
  const auto run =
      run_mneedle("screen " + designs + " --scene '" + kSkin + "' --model analytic --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["designs"].size(), 2u);
  EXPECT_EQ(j["designs"][0]["design"], "cylinder") << j.dump(2);
  EXPECT_TRUE(j["designs"][0]["puncture_at_first_contact"].get<bool>());
  EXPECT_FALSE(j["designs"][1]["punctured"].get<bool>());
  EXPECT_EQ(j["model"], "analytic");
  for (const auto& d : j["designs"]) EXPECT_EQ(d["models_run"][0], "analytic") << d.dump();
  const auto table = run_mneedle("screen " + designs + " --scene '" + kSkin + "' --model analytic");
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find(" um* "), std::string::npos) << table.out;
}

TEST(ScreenCommand, BrokenDesignGetsAnErrorRowAndTheOthersAreKept) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_screen_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  fs::copy_file(kRoot + "/designs/cone.stl", dir / "in" / "cone.stl");
  fs::copy_file(std::string(MNEEDLE_TEST_ASSETS) + "/meshes/open_box.stl",
                dir / "in" / "broken.stl");
  const auto run = run_mneedle("screen '" + (dir / "in").string() + "' --scene '" + kSkin +
                               "' --model analytic --out '" + (dir / "out").string() + "'");
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

}  // namespace
