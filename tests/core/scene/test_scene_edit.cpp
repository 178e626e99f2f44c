// Scene files as edited values: the JSON form of a file's values (Python's read_scene) keeps
// every value as written and makes STL paths absolute, so that the values stand anywhere; a
// scene written back with fitted constants (calibrate --out) carries them.
#include "mneedle/scene/scene_edit.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/scene/scene.h"

namespace mneedle {
namespace {

TEST(SceneEdit, ValuesJsonKeepsValuesAsWrittenAndMakesStlPathsAbsolute) {
  const std::filesystem::path file = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/stl_needle.toml";
  const auto j = nlohmann::json::parse(scene_values_json(file));
  const std::filesystem::path stl = j["needles"][0]["geometry"]["stl"].get<std::string>();
  EXPECT_TRUE(stl.is_absolute()) << stl;
  EXPECT_TRUE(std::filesystem::exists(stl)) << stl;
  EXPECT_TRUE(j["tissue"]["layers"][0]["material"]["E"].is_string());
}

// calibrate's modulus factor: every stiffness constant of every layer, E of a linear layer (here
// a plain number, which the scene reads as Pa) and C10, C01 and K of a Mooney-Rivlin one (with
// units), written times the factor (nu is a ratio: kept).
TEST(SceneEdit, AModulusFactorScalesEveryLayersStiffnessConstants) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("scene_edit_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "two_layers.toml";
  std::ofstream(file) << "[tissue]\nsize = [\"5 mm\", \"5 mm\", \"4 mm\"]\n"
                         "[[tissue.layers]]\nname = \"gel\"\nthickness = \"1 mm\"\n"
                         "material = { model = \"linear\", E = \"200 kPa\", nu = 0.45 }\n"
                         "[[tissue.layers]]\nname = \"liver\"\n"
                         "material = { model = \"mooney_rivlin\", C10 = \"1 kPa\", C01 = 0, "
                         "K = \"100 kPa\" }\n"
                         "[[needles]]\nname = \"n\"\n"
                         "geometry = { plugin = \"cone\", diameter = \"200 um\", tip_angle = "
                         "\"30 deg\" }\n"
                         "[insertion]\ndepth = \"1 mm\"\n";
  const Scene before = load_scene(file);
  SceneConstantEdits edits;
  edits.modulus_factor = 2.5;
  const std::filesystem::path out = dir / "fitted.toml";
  std::ofstream(out) << edited_scene_text(file, edits, out);
  const Scene after = load_scene(out);
  ASSERT_EQ(after.tissue.layers.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const TissueMaterial& a = after.tissue.layers[i].material;
    const TissueMaterial& b = before.tissue.layers[i].material;
    EXPECT_NEAR(a.youngs_modulus, 2.5 * b.youngs_modulus, 1e-9 * b.youngs_modulus) << i;
    EXPECT_NEAR(a.poisson_ratio, b.poisson_ratio, 1e-12) << i;
    EXPECT_NEAR(a.c10, 2.5 * b.c10, 1e-9 * (b.c10 + 1.0)) << i;
    EXPECT_NEAR(a.c01, 2.5 * b.c01, 1e-9 * (b.c01 + 1.0)) << i;
  }
  std::filesystem::remove_all(dir);
}

TEST(SceneEdit, ValuesJsonOfAMissingOrBrokenFileNamesIt) {
  EXPECT_THROW(scene_values_json("/nonexistent/scene.toml"), InputError);
  const std::filesystem::path bad = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/syntax_error.toml";
  try {
    scene_values_json(bad);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(bad.string() + ":", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace mneedle
