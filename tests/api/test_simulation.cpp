// simulate as a library call: settings checked with one-line errors, the run's JSON tree with
// the keys the CLI and Python print, its numbers the run's own.
#include "mneedle/api/simulation.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

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

// A scene simulated with default settings, as the CLI does: the run and its JSON tree.
struct Simulated {
  InsertionRun run;
  nlohmann::json tree;
};

Simulated simulate_scene(const std::string& path) {
  Scene scene = load_scene(path);
  const SimulateSettings s;
  apply_simulate_settings(scene, s);
  const PluginRegistry registry = PluginRegistry::discover({});
  const auto needles = prepare_needles(registry, scene, s.max_needles);
  InsertionRun run = run_insertion(scene, needles, simulate_run_options(scene, s));
  nlohmann::json tree = simulation_json(run, scene, needles, s);
  return {std::move(run), std::move(tree)};
}

TEST(Simulation, TreeCarriesTheRunsPunctureCurveAndMeshHash) {
  const auto [run, tree] = simulate_scene(kPunch);
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

// Where the time went: every FE run's wall time, the 3-D phases inside the 3-D runs' time, all of
// it inside the run's own wall time (clocks nested, so no tolerance).
TEST(Simulation, SecondsByStageLieWithinTheRunsWallTime) {
  const auto [run, tree] =
      simulate_scene(std::string(MNEEDLE_TEST_ASSETS) + "/scenes/bevel_3d_linear.toml");
  const nlohmann::json& t = tree["seconds_by_stage"];
  ASSERT_TRUE(t.is_object());
  EXPECT_GT(t["fe_3d_s"].get<double>(), 0.0);
  EXPECT_GE(t["fe_runs"].get<int>(), 1);
  EXPECT_GE(t["factorizations"].get<int>(), 1);
  const double phases = t["meshing_s"].get<double>() + t["assembly_s"].get<double>() +
                        t["factorization_s"].get<double>() + t["contact_s"].get<double>() +
                        t["stress_s"].get<double>();
  EXPECT_GT(t["factorization_s"].get<double>(), 0.0);
  EXPECT_LE(phases, t["fe_3d_s"].get<double>());
  EXPECT_LE(t["fe_3d_s"].get<double>() + t["axisymmetric_fe_s"].get<double>(),
            tree["seconds"].get<double>());
  EXPECT_EQ(t["fe_3d_s"].get<double>(), run.seconds_by_stage.fe_3d_s);
}

// The energy criterion's crack faces stay free on the paths where their contact is not modelled
// (docs/model.md, "Crack faces in contact"): an overlap above 1 nm is one warning line naming the
// scene and the needle; round-off overlap (faces in contact) and other criteria say nothing.
TEST(Simulation, OverlappingCrackFacesAreOneWarningNamingTheNeedle) {
  Scene scene;
  scene.source_name = "phantom.toml";
  InsertionRun run;
  run.criterion = PunctureCriterion::Energy;
  NeedleRun needle;
  needle.name = "sharp_bevel";
  RunPoint point;
  point.crack_face_overlap_m = 3e-20;  // in contact: round-off
  needle.curve.push_back(point);
  run.needles.push_back(needle);
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
  run.needles[0].curve[0].crack_face_overlap_m = 4.2e-6;
  const std::vector<std::string> warnings = criterion_warnings(run, scene);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("phantom.toml"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("'sharp_bevel'"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("4.2 um"), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].find('\n'), std::string::npos);
  run.criterion = PunctureCriterion::Pressure;
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
}

// A stress probe that read 0 at every loaded step (its strength length below the mesh: the
// silicone scenes' 0.15 um) is one warning naming the scene, the layer and the length; one
// nonzero reading, or no load at all, says nothing.
TEST(Simulation, StressThatReadZeroUnderLoadIsOneWarningNamingTheLength) {
  Scene scene;
  scene.source_name = "phantom.toml";
  TissueLayer top;
  top.name = "silicone";
  top.strength = LayerStrength{3.3e6, 0.15e-6};
  scene.tissue.layers.push_back(top);
  InsertionRun run;
  run.criterion = PunctureCriterion::Stress;
  NeedleRun needle;
  needle.name = "cylinder";
  RunPoint point;
  point.stage = Stage::Pre;
  needle.curve.push_back(point);  // no load yet
  run.needles.push_back(needle);
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
  run.needles[0].curve[0].force_N = 1e-3;
  const std::vector<std::string> warnings = criterion_warnings(run, scene);
  ASSERT_EQ(warnings.size(), 1u);
  for (const char* part : {"phantom.toml", "'silicone'", "'cylinder'", "150 nm"})
    EXPECT_NE(warnings[0].find(part), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].find('\n'), std::string::npos);
  run.needles[0].curve[0].tip_stress_Pa = 1.0;
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
}

// A linear top layer 7463 times stiffer than the layer beneath (paper A's stratum corneum over
// its epidermis), pushed deeper than its 20 um thickness before the needle punctures it, is one
// warning naming the scene, the layer, the needle and the ratio; a finite-strain layer, a
// puncture within the thickness or a contrast below kStiffTopLayerContrast say nothing, and a
// needle that never punctures is judged by its deepest pre-puncture depth; a closed-form run
// (small strain whatever the layer's model) says nothing.
TEST(Simulation, ALinearStiffTopLayerPushedBeyondItsThicknessIsOneWarning) {
  Scene scene;
  scene.source_name = "skin.toml";
  TissueLayer top, below;
  top.name = "stratum_corneum";
  top.thickness = 20e-6;
  top.material.youngs_modulus = 1e9;
  below.name = "epidermis";
  below.thickness = 100e-6;
  below.material.youngs_modulus = 0.134e6;
  scene.tissue.layers = {top, below};
  InsertionRun run;
  run.criterion = PunctureCriterion::Stress;
  NeedleRun needle;
  needle.name = "cylinder";
  RunPoint point;
  point.stage = Stage::Pre;
  point.depth_m = 140.9e-6;
  needle.curve.push_back(point);
  Puncture puncture;
  puncture.depth_m = 140.9e-6;
  needle.puncture = puncture;
  run.needles.push_back(needle);
  std::vector<std::string> warnings = criterion_warnings(run, scene);
  ASSERT_EQ(warnings.size(), 1u);
  for (const char* part : {"skin.toml", "'stratum_corneum'", "'cylinder'", "140.9 um",
                           "before it punctures", "7.0 times", "7463 times softer", "svk"})
    EXPECT_NE(warnings[0].find(part), std::string::npos) << part << ": " << warnings[0];
  EXPECT_EQ(warnings[0].find('\n'), std::string::npos);
  // No puncture: the deepest pre-puncture depth, 50 um.
  run.needles[0].puncture.reset();
  run.needles[0].curve[0].depth_m = 50e-6;
  warnings = criterion_warnings(run, scene);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2.5 times"), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].find("before it punctures"), std::string::npos) << warnings[0];
  // The closed-form path is small strain whatever the layer: no advice to give.
  run.models_run = {"analytic", "surface_loads"};
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
  run.models_run = {"axisymmetric_fe", "surface_loads"};
  // Within the thickness, a finite-strain layer, a weak contrast: nothing.
  run.needles[0].curve[0].depth_m = 19e-6;
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
  run.needles[0].curve[0].depth_m = 50e-6;
  scene.tissue.layers[0].material.model = MaterialModel::StVenantKirchhoff;
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
  scene.tissue.layers[0].material.model = MaterialModel::Linear;
  scene.tissue.layers[0].material.youngs_modulus = 0.9 * kStiffTopLayerContrast * 0.134e6;
  EXPECT_TRUE(criterion_warnings(run, scene).empty());
}

}  // namespace
}  // namespace mneedle
