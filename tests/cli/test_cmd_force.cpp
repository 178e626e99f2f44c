// Runs the built `mneedle force` on scenes and checks exit status and output.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include "../plot/svg_reader.h"
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
  std::string provenance, header;
  std::getline(lines, provenance);  // "# provenance: {...}" (docs/cli.md, "Provenance")
  EXPECT_EQ(provenance.rfind("# provenance: ", 0), 0u) << provenance;
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
  // A sharp bevel has no face across the axis: no alpha load at any depth (docs/model.md, "α
  // faces"), beta and friction once it is in.
  for (const auto& sample : out["needles"][0]["curve"]) EXPECT_EQ(sample["alpha_N"], 0.0);
  const auto& last = out["needles"][0]["curve"].back();
  EXPECT_GT(last["beta_N"].get<double>(), 0.0);
  EXPECT_GT(last["friction_N"].get<double>(), 0.0);
}

// Force at `depth_um` of the first needle of a scene (10 um steps, so the depth is a sample).
double force_at(const std::string& scene, double depth_um) {
  const CommandRun run = run_mneedle("force '" + scene + "' --json --step 10um");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  if (run.exit_code != 0) return NAN;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  for (const auto& p : out["needles"][0]["curve"]) {
    if (std::abs(p["depth_m"].get<double>() * 1e6 - depth_um) < 1e-6) return p["force_N"];
  }
  ADD_FAILURE() << "no sample at " << depth_um << " um";
  return NAN;
}

// Paper A, paragraph on Fig. 17: a blunt bevel that must pass 300 um into the E = 0.5 MPa phantom
// "must withstand 0.14 N". Our reconstruction of the vertex law (its cos term is lost) gives
// 121.65 mN there: pinned to 0.1 mN (the model is closed form; any move is a change to explain),
// 13 % below the paper's figure (docs/validation.md, "Paper A's figures"), and K linear in E.
TEST_F(ForceCommand, PaperAFig17BluntBevelAt300UmIsWithinItsDocumentedMissOfThePaper) {
  const std::string scene = design("paper_a_fig17_blunt_bevel.toml");
  const double at_05 = force_at(scene, 300.0);
  EXPECT_NEAR(at_05, 0.12165, 1e-4);
  EXPECT_LT(std::abs(at_05 - 0.14) / 0.14, 0.14);
  std::ifstream in(scene);
  std::stringstream text;
  text << in.rdbuf();
  std::string soft = text.str();
  soft.replace(soft.find("E = \"0.5 MPa\""), 13, "E = \"0.2 MPa\"");
  const auto copy = std::filesystem::temp_directory_path() /
                    ("fig17_soft_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(copy) << soft;
  EXPECT_NEAR(force_at(copy.string(), 300.0), at_05 * 0.2 / 0.5, 1e-12);
  std::filesystem::remove(copy);
}

// Paper A's Figs. 20 and 22 in the Fig. 17 mode (paper A's K of the E = 0.2 MPa phantom, S =
// 0.168, l = 1 um, no friction): the text gives one number, the sharp bevel's 14 mN at its 0.23 mm
// puncture, and Fig. 20 draws the cylinder with the largest force of the three. Ours: 32.9 mN
// (+135 %) and a cylinder at 0.73 mN, the reverse order (docs/validation.md, "Paper A's figures":
// the lost cos term of the vertex law). Pinned so that the miss stays in view (closed form: a move
// is a change to explain).
TEST_F(ForceCommand, PaperAFig20SharpBevelAndCylinderInTheFig17ModeArePinnedWithTheirMiss) {
  std::string text = mneedle::test::file_text(design("paper_a_fig17_blunt_bevel.toml"));
  text.replace(text.find("E = \"0.5 MPa\""), 13, "E = \"0.2 MPa\"");
  const std::string blunt =
      "geometry = { plugin = \"blunt_bevel\", diameter = \"230 um\", length = \"1000 um\", "
      "bevel_angle = \"30 deg\", flat_width = \"50 um\" }";
  const auto at = text.find(blunt);
  ASSERT_NE(at, std::string::npos);
  auto with = [&](const std::string& geometry, const std::string& name) {
    std::string scene = text;
    scene.replace(at, blunt.size(), geometry);
    const auto file = std::filesystem::temp_directory_path() /
                      (name + "_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(file) << scene;
    return file.string();
  };
  const std::string sharp = with(
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length = \"1000 um\", "
      "bevel_angle = \"30 deg\" }",
      "fig20_sharp");
  const std::string cylinder =
      with("geometry = { plugin = \"cylinder\", diameter = \"230 um\", length = \"1000 um\" }",
           "fig20_cylinder");
  const double f_sharp = force_at(sharp, 230.0);
  const double f_cylinder = force_at(cylinder, 230.0);
  EXPECT_NEAR(f_sharp, 0.0329, 1e-4);
  EXPECT_NEAR(f_sharp / 0.014 - 1.0, 1.35, 0.01);  // the miss against paper A's 14 mN
  EXPECT_NEAR(f_cylinder, 0.00073, 1e-5);
  EXPECT_LT(f_cylinder, f_sharp);  // the reverse of paper A's Fig. 20, where it is the largest
  std::filesystem::remove(sharp);
  std::filesystem::remove(cylinder);
}

// The shipped silicone scenes carry q = 570 kPa, fitted so that paper A's sharp bevel carries its
// measured 14 mN at 0.23 mm (docs/validation.md). The blunt bevel at its measured puncture
// (1.226 mm, 217 mN in paper A) and the cylinder at 2 mm are predictions: pinned here, misses
// reported there. The fit point to 0.1 mN (q is fitted to two digits); the predictions to 1 uN
// (closed form: any move is a change to explain). The blunt bevel was pinned at 107.68 mN
// within 0.5 mN from the day it was fitted, where the model read 107.392 mN (checked on that
// commit): the loose bound hid the pin's own error.
TEST_F(ForceCommand, SiliconePressureScaleReproducesItsFitPointAndPinsThePredictions) {
  EXPECT_NEAR(force_at(design("paper_a_silicone_sharp_bevel.toml"), 230.0), 0.014, 0.0001);
  EXPECT_NEAR(force_at(design("paper_a_silicone_blunt_bevel.toml"), 1230.0), 0.107392, 1e-6);
  EXPECT_NEAR(force_at(design("paper_a_silicone_cylinder.toml"), 2000.0), 0.184703, 1e-6);
}

TEST_F(ForceCommand, ForceJsonNamesEachLayersPressureScaleAndItsSource) {
  const CommandRun run = run_mneedle("force '" + design("human_skin.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto layers = nlohmann::json::parse(run.out)["loads"]["layers"];
  ASSERT_EQ(layers.size(), 3u);
  EXPECT_EQ(layers[0]["name"], "stratum_corneum");
  EXPECT_NEAR(layers[0]["wall_pressure_cap_Pa"].get<double>(), 21.6e6, 1.0);
  EXPECT_NE(layers[1]["source"].get<std::string>().find("not fitted"), std::string::npos);
}

// `force` runs no pre-puncture model, so it cannot continue the curve while a broken stiff top
// layer grips the shaft, as `simulate` does (docs/model.md, "The broken top layer"): in skin
// its stratum corneum loads read 88 mN at 200 um where `simulate` reads 19.6 mN. It says so, in
// the table, the CSV and the JSON; a single-layer silicone has no such layer and no note, nor has
// a skin scene that asks for the force curve alone (`simulate` then runs no pre-puncture model
// and prints the same loads).
TEST_F(ForceCommand, LoadsLeavingOutABrokenLayersGripSaySo) {
  const CommandRun table = run_mneedle("force '" + design("human_skin.toml") + "' --step 100um");
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("note: layer 'stratum_corneum' is stiffer than the one below"),
            std::string::npos)
      << table.out;
  const CommandRun skin = run_mneedle("force '" + design("human_skin.toml") + "' --json");
  ASSERT_EQ(skin.exit_code, 0) << skin.err;
  const auto notes = nlohmann::json::parse(skin.out)["notes"];
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].get<std::string>().find("The broken top layer"), std::string::npos);
  const CommandRun silicone =
      run_mneedle("force '" + design("silicone_phantom.toml") + "' --json --step 500um");
  ASSERT_EQ(silicone.exit_code, 0) << silicone.err;
  EXPECT_TRUE(nlohmann::json::parse(silicone.out)["notes"].empty());
  const CommandRun csv = run_mneedle("force '" + design("human_skin.toml") + "' --csv");
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_NE(csv.out.find("\n# note: layer 'stratum_corneum'"), std::string::npos);
  std::string text = mneedle::test::file_text(design("human_skin.toml"));
  const std::string outputs = "outputs = [\"puncture\", \"force_curve\"]";
  ASSERT_NE(text.find(outputs), std::string::npos);
  text.replace(text.find(outputs), outputs.size(), "outputs = [\"force_curve\"]");
  const auto curve_only = std::filesystem::temp_directory_path() /
                          ("skin_curve_only_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(curve_only) << text;
  const CommandRun plain = run_mneedle("force '" + curve_only.string() + "' --json --step 500um");
  std::filesystem::remove(curve_only);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(nlohmann::json::parse(plain.out)["notes"].empty());
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

TEST_F(ForceCommand, PlotHasOneCurvePerNeedle) {
  const auto svg = std::filesystem::temp_directory_path() /
                   ("mneedle_force_plot_" + std::to_string(::getpid()) + ".svg");
  const CommandRun run = run_mneedle("force '" + scene_asset("stl_needle.toml") +
                                     "' --step 100um --plot '" + svg.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string text = mneedle::test::read_svg(svg);
  std::filesystem::remove(svg);
  EXPECT_FALSE(mneedle::test::polyline(text, "#1F77B4").empty());
  EXPECT_FALSE(mneedle::test::texts(text).empty());
}

}  // namespace
