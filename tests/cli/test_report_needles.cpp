// The needles a report rebuilds from a result (cli/src/report_needles.cpp): each from what the
// result records, checked against the mesh hash the run recorded, and a note instead of a needle
// when that fails.
#include "report_needles.h"

#include <gtest/gtest.h>

#include <string>

#include "mneedle/needle/mesh.h"

namespace {

using nlohmann::json;

const std::vector<std::string> kPlugins{MNEEDLE_PLUGIN_BUILD_DIR};

json screen_of(json row) {
  return {{"designs", json::array({row})}, {"ranking", json::array()}};
}

TEST(RebuildNeedles, PluginRowIsRebuiltFromItsShapeAndParameters) {
  const json optimum = {{"history", json::array()},
                        {"plugin", "cone"},
                        {"best", {{"params", {{"half_angle", 0.3}, {"diameter", 230e-6}}}}}};
  const auto best = mneedle::cli::rebuild_needles(optimum, {}, kPlugins);
  ASSERT_EQ(best.views.size(), 1u) << (best.notes.empty() ? "" : best.notes[0]);
  // The same parameters in a screened row, with the hash of that mesh: rebuilt and accepted.
  json row = {{"design", "c"},
              {"ok", true},
              {"plugin", "cone"},
              {"params", {{"half_angle", 0.3}, {"diameter", 230e-6}}},
              {"mesh_sha256", mneedle::mesh_sha256(best.views[0].mesh)}};
  const auto rebuilt = mneedle::cli::rebuild_needles(screen_of(row), {}, kPlugins);
  ASSERT_EQ(rebuilt.views.size(), 1u);
  EXPECT_TRUE(rebuilt.notes.empty());
  EXPECT_EQ(rebuilt.views[0].name, "c");
}

TEST(RebuildNeedles, MeshThatDiffersFromTheRecordedHashIsANoteNotANeedle) {
  json row = {{"design", "c"},
              {"ok", true},
              {"plugin", "cone"},
              {"params", {{"half_angle", 0.3}}},
              {"mesh_sha256", std::string(64, '0')}};
  const auto rebuilt = mneedle::cli::rebuild_needles(screen_of(row), {}, kPlugins);
  EXPECT_TRUE(rebuilt.views.empty());
  ASSERT_EQ(rebuilt.notes.size(), 1u);
  EXPECT_NE(rebuilt.notes[0].find("design c: not shown in 3-D, its mesh rebuilt today differs"),
            std::string::npos)
      << rebuilt.notes[0];
}

TEST(RebuildNeedles, MissingFilesAndUnknownPluginsAreNotesAndTheRestGoesOn) {
  json missing = {{"design", "gone"}, {"ok", true}, {"source", "/no/such/needle.stl"}};
  json unknown = {
      {"design", "odd"}, {"ok", true}, {"plugin", "no_such_shape"}, {"params", json::object()}};
  json failed = {{"design", "failed"}, {"ok", false}, {"error", "x"}};
  json result = {{"designs", {missing, unknown, failed}}, {"ranking", json::array()}};
  const auto rebuilt = mneedle::cli::rebuild_needles(result, {}, kPlugins);
  EXPECT_TRUE(rebuilt.views.empty());
  ASSERT_EQ(rebuilt.notes.size(), 2u);  // the error row had no needle to show
  EXPECT_NE(rebuilt.notes[0].find("design gone: not shown in 3-D (/no/such/needle.stl"),
            std::string::npos)
      << rebuilt.notes[0];
  EXPECT_NE(rebuilt.notes[1].find("design odd: not shown in 3-D ("), std::string::npos)
      << rebuilt.notes[1];
}

TEST(RebuildNeedles, SimulationWhoseSceneIsGoneIsOneNote) {
  json result = {
      {"needles", json::array()},
      {"total_curve", json::array()},
      {"provenance",
       {{"inputs", {{{"role", "scene"}, {"name", "/no/such/scene.toml"}, {"sha256", "00"}}}}}}};
  const auto rebuilt = mneedle::cli::rebuild_needles(result, {}, kPlugins);
  EXPECT_TRUE(rebuilt.views.empty());
  ASSERT_EQ(rebuilt.notes.size(), 1u);
  EXPECT_EQ(rebuilt.notes[0], "no 3-D view: the scene /no/such/scene.toml is not there any more");
}

}  // namespace
