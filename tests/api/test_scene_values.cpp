// A scene as values: the file's values round-trip to a scene equal to the file's, and what TOML
// cannot hold (null, NaN) or the parser refuses is a one-line error naming the key.
#include "mneedle/api/scene_values.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "error_message.h"
#include "mneedle/base/error.h"

namespace mneedle {
namespace {

const std::string kScenes = std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/";

std::string message_of(const auto& call) {
  return testing::error_message<InputError>(call);
}

TEST(SceneValues, ValuesOfAFileGiveTheFilesScene) {
  for (const char* name : {"silicone_phantom.toml", "human_skin.toml"}) {
    const Scene file = load_scene(kScenes + name);
    const Scene values = scene_from_values(read_scene_values(kScenes + name), name);
    ASSERT_EQ(values.tissue.layers.size(), file.tissue.layers.size()) << name;
    for (std::size_t i = 0; i < file.tissue.layers.size(); ++i) {
      EXPECT_EQ(values.tissue.layers[i].name, file.tissue.layers[i].name);
      EXPECT_EQ(values.tissue.layers[i].thickness, file.tissue.layers[i].thickness);
    }
    ASSERT_EQ(values.needles.size(), file.needles.size());
    for (std::size_t i = 0; i < file.needles.size(); ++i) {
      EXPECT_EQ(values.needles[i].name, file.needles[i].name);
      EXPECT_EQ(values.needles[i].at, file.needles[i].at);
    }
    EXPECT_EQ(values.insertion.depth, file.insertion.depth);
    EXPECT_EQ(values.tissue.size, file.tissue.size);
    EXPECT_EQ(values.model.criterion, file.model.criterion);
    EXPECT_EQ(values.loads.friction_coefficient, file.loads.friction_coefficient);
    EXPECT_EQ(values.requirements.safety_factor, file.requirements.safety_factor);
  }
}

TEST(SceneValues, NullAndNonFiniteNumbersAreNamedByTheirKey) {
  nlohmann::json v = read_scene_values(kScenes + "silicone_phantom.toml");
  v["tissue"]["layers"][0]["material"]["nu"] = nullptr;
  EXPECT_EQ(message_of([&] { scene_values_toml(v, "s"); }),
            "s: tissue.layers[0].material.nu: no value (null/None) — leave the key out instead");
  v["tissue"]["layers"][0]["material"]["nu"] = std::nan("");
  EXPECT_EQ(message_of([&] { scene_values_toml(v, "s"); }),
            "s: tissue.layers[0].material.nu: not a finite number");
  EXPECT_EQ(message_of([] { scene_values_toml(nlohmann::json::array(), "s"); }),
            "s: a scene is a table of values (a dict)");
}

TEST(SceneValues, IntegersStandForNumbersAndHugeOnesAreRefused) {
  nlohmann::json v = read_scene_values(kScenes + "silicone_phantom.toml");
  v["loads"]["friction_coefficient"] = 1;  // an integer where a number is read
  EXPECT_EQ(scene_from_values(v, "s").loads.friction_coefficient, 1.0);
  v["loads"]["friction_coefficient"] = std::uint64_t{1} << 63;  // beyond a TOML integer
  EXPECT_EQ(message_of([&] { scene_values_toml(v, "s"); }),
            "s: loads.friction_coefficient: integer too large for a scene");
}

TEST(SceneValues, TheParserChecksValuesAsItChecksFiles) {
  nlohmann::json v = read_scene_values(kScenes + "silicone_phantom.toml");
  v["tissue"]["layers"][0]["material"]["E"] = "0.2";  // no unit
  const std::string m = message_of([&] { scene_from_values(v, "changed"); });
  EXPECT_EQ(m.rfind("changed:", 0), 0u) << m;
  EXPECT_NE(m.find(": tissue.layers[0].material.E: \"0.2\" needs a unit: a pressure"),
            std::string::npos)
      << m;
}

}  // namespace
}  // namespace mneedle
