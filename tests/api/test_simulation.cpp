// simulate as a library call: settings checked with one-line errors, the run's JSON tree with
// the keys the CLI and Python print, its numbers the run's own.
#include "mneedle/api/simulation.h"

#include <gtest/gtest.h>

#include <string>

#include "error_message.h"
#include "mneedle/base/error.h"
#include "mneedle/design_source.h"
#include "mneedle/plugin_host.h"

namespace mneedle {
namespace {

const std::string kPunch = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/puncture_punch.toml";

std::string message_of(const auto& call) {
  return testing::error_message<InputError>(call);
}

TEST(Simulation, EverySettingOutsideItsListIsOneLineNamingIt) {
  Scene scene = load_scene(kPunch);
  SimulateSettings s;
  s.fidelity = "fst";
  EXPECT_EQ(message_of([&] { apply_simulate_settings(scene, s); }),
            "simulate: fidelity 'fst' is not one of fast, standard, fine");
  s = {};
  s.model = "";
  EXPECT_EQ(message_of([&] { apply_simulate_settings(scene, s); }),
            "simulate: model '' is not one of auto, analytic, axisymmetric, 3d");
  s = {};
  s.max_needles = 0;
  EXPECT_EQ(message_of([&] { apply_simulate_settings(scene, s); }),
            "simulate: max_needles 0 (from 1 to 100000)");
  s = {};
  s.axis = "w";
  EXPECT_NE(message_of([&] { apply_simulate_settings(scene, s); }), "no error");
}

TEST(Simulation, EmptySettingsKeepTheScenesChoicesAndGivenOnesOverrideThem) {
  const Scene scene = load_scene(kPunch);
  SimulateSettings s;
  const InsertionRunOptions kept = simulate_run_options(scene, s);
  EXPECT_EQ(kept.fidelity, scene_run_options(scene).fidelity);
  s.fidelity = "fine";
  s.criterion = "energy";
  s.no_reductions = true;
  const InsertionRunOptions changed = simulate_run_options(scene, s);
  EXPECT_EQ(changed.fidelity, fe::Fidelity::Fine);
  EXPECT_EQ(changed.criterion, PunctureCriterion::Energy);
  EXPECT_FALSE(changed.allow_reductions);
}

TEST(Simulation, TreeCarriesTheRunsPunctureCurveAndMeshHash) {
  Scene scene = load_scene(kPunch);
  const SimulateSettings s;
  apply_simulate_settings(scene, s);
  const PluginRegistry registry = PluginRegistry::discover({});
  const auto needles = prepare_needles(registry, scene, s.max_needles);
  const InsertionRun run = run_insertion(scene, needles, simulate_run_options(scene, s));
  const nlohmann::json tree = simulation_json(run, scene, needles, s);
  ASSERT_EQ(tree["needles"].size(), 1u);
  const auto& needle = tree["needles"][0];
  ASSERT_TRUE(run.needles[0].puncture.has_value());
  EXPECT_EQ(needle["puncture"]["depth_m"].get<double>(), run.needles[0].puncture->depth_m);
  EXPECT_EQ(needle["curve"].size(), run.needles[0].curve.size());
  EXPECT_EQ(needle["mesh_sha256"].get<std::string>().size(), 64u);
  for (const char* key : {"mesh", "total_curve", "models_run", "reductions", "fidelity",
                          "criterion", "loads", "energy_check", "seconds"})
    EXPECT_TRUE(tree.contains(key)) << key;
  EXPECT_FALSE(tree.contains("axis"));  // only when the settings gave one
}

}  // namespace
}  // namespace mneedle
