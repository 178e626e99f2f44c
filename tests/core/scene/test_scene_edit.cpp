// Scene files as edited values: the JSON form of a file's values (Python's read_scene) keeps
// every value as written and makes STL paths absolute, so that the values stand anywhere.
#include "mneedle/scene/scene_edit.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "mneedle/base/error.h"

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
