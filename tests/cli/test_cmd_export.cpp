// `mneedle export` (docs/cli.md): what it reports and what it refuses. The numbers against
// CalculiX are checked by tests/cli/check_ccx.py.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::run_mneedle;

const std::string kBevel = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/bevel_3d_linear.toml";

fs::path work() {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_export_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ExportCommand, WritesTheDeckAndReportsItsReaction) {
  const fs::path deck = work() / "bevel.inp";
  const auto run = run_mneedle("export '" + kBevel + "' --format inp -o '" + deck.string() +
                               "' --depth 30um --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["file"], deck.string());
  // the fast steps are 10 um: 30 um is one of them (3 x 100 um / 10, to round-off)
  EXPECT_NEAR(j["depth_m"].get<double>(), 30e-6, 1e-18);
  EXPECT_GT(j["prescribed_nodes"].get<int>(), 0);
  EXPECT_LT(j["reaction_N"][2].get<double>(), 0.0);  // the tissue pushed down
  EXPECT_EQ(j["reductions"][0], "half_model");
  EXPECT_EQ(j["provenance"]["inputs"][0]["role"], "scene");
  const std::string text = text_of(deck);
  EXPECT_EQ(text.rfind("*HEADING\n", 0), 0u);
  EXPECT_NE(text.find("** provenance: {"), std::string::npos);
  EXPECT_NE(text.find("NMIRRORY, 2, 2"), std::string::npos);
  fs::remove_all(deck.parent_path());
}

// A --depth past the puncture: the deck is the pre-puncture model's last step and the run says
// so (it wrote a shallower deck without a word); the JSON carries both depths.
TEST(ExportCommand, ADeckShallowerThanAskedSaysWhy) {
  const fs::path deck = work() / "deep.inp";
  const std::string skin = std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/human_skin.toml";
  const auto run = run_mneedle("export '" + skin + "' --format inp -o '" + deck.string() +
                               "' --fidelity fast --depth 300um --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_NEAR(j["requested_depth_m"].get<double>(), 300e-6, 1e-18);
  EXPECT_LT(j["depth_m"].get<double>(), 100e-6);
  EXPECT_NE(run.err.find("not 300 um: needle 'sharp_bevel' punctures at"), std::string::npos)
      << run.err;
  fs::remove_all(deck.parent_path());
}

TEST(ExportCommand, NonlinearSceneIsRefusedInOneLine) {
  const fs::path dir = work();
  std::string scene = text_of(kBevel);
  scene.replace(scene.find("model = \"linear\""), 16, "model = \"neo_hookean\"");
  std::ofstream(dir / "nonlinear.toml") << scene;
  const auto run = run_mneedle("export '" + (dir / "nonlinear.toml").string() +
                               "' --format inp -o '" + (dir / "x.inp").string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err,
            "mneedle: error: export: layer 'silicone' is not linear: the .inp deck holds linear "
            "elastic layers only\n");
  fs::remove_all(dir);
}

TEST(ExportCommand, FormatOtherThanInpIsACommandLineError) {
  const auto run = run_mneedle("export '" + kBevel + "' --format vtk -o x.vtk");
  EXPECT_EQ(run.exit_code, 2);
}

}  // namespace
