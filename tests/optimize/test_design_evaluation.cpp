// evaluate_design on what an optimisation meets first: every built-in plugin's defaults and the
// corners of the parameter boxes the README and docs/cli.md vary. Each must evaluate, or be
// refused by its plugin as no valid shape (which a search counts as infeasible, not a failure):
// the cone's default sharp point once failed every evaluation ("tip_size_m must be > 0 m").
#include "mneedle/design_evaluation.h"

#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "mneedle/design_source.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"

namespace {

using mneedle::PluginRegistry;

struct Walk {
  int evaluated = 0;
  int impossible = 0;
};

// Evaluates one parameter set at fast fidelity, as `optimize` does (axisymmetric model for bodies
// of revolution, half model for mirror-symmetric ones).
void evaluate(const PluginRegistry& registry, const mneedle::Scene& scene, const std::string& shape,
              const std::map<std::string, double>& params, Walk& walk) {
  mneedle::NeedleSource n;
  try {
    n = mneedle::needle_from_plugin(registry, shape, params);
  } catch (const mneedle::InvalidShapeError&) {
    ++walk.impossible;
    return;
  }
  mneedle::EvaluationOptions o;
  o.symmetry = mneedle::needle_symmetry(registry, n, shape);
  std::string where = shape;
  for (const auto& [k, v] : params) where += " " + k + "=" + std::to_string(v);
  EXPECT_NO_THROW({
    const auto e = mneedle::evaluate_design(n.mesh, scene, "silicon", o);
    EXPECT_GT(e.peak_force_n, 0.0) << where;
  }) << where;
  ++walk.evaluated;
}

TEST(DesignEvaluation, EveryPluginsDefaultsAndTheDocumentedBoxCornersEvaluateInSkin) {
  const auto start = std::chrono::steady_clock::now();
  const auto registry = PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
  const auto scene =
      mneedle::load_scene(std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/human_skin.toml");
  Walk walk;
  for (const char* shape : {"sharp_bevel", "blunt_bevel", "cylinder", "cone"})
    evaluate(registry, scene, shape, {}, walk);
  // The boxes varied in the README (sharp_bevel: bevel_angle over the plugin's range, diameter
  // 150-300 um) and docs/cli.md (cone: half_angle over the plugin's range): every corner.
  struct Range {
    std::string name;
    double low = -1.0, high = -1.0;  // negative: the plugin's own bound
  };
  const std::map<std::string, std::vector<Range>> boxes = {
      {"sharp_bevel", {{"bevel_angle"}, {"diameter", 150e-6, 300e-6}}}, {"cone", {{"half_angle"}}}};
  for (const auto& [shape, ranges] : boxes) {
    const auto& info = registry.shape(shape);
    for (unsigned corner = 0; corner < (1u << ranges.size()); ++corner) {
      std::map<std::string, double> params;
      for (std::size_t i = 0; i < ranges.size(); ++i)
        for (const auto& p : info.parameters)
          if (p.name == ranges[i].name) {
            const bool high = (corner >> i) & 1u;
            const double own = high ? ranges[i].high : ranges[i].low;
            params[p.name] = own >= 0.0 ? own : (high ? p.max : p.min);
          }
      evaluate(registry, scene, shape, params, walk);
    }
  }
  EXPECT_EQ(walk.evaluated + walk.impossible, 4 + 4 + 2);
  // The walk is a smoke test of the optimiser's first hour: it must stay cheap.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 60.0);
}

TEST(DesignEvaluation, FlatEndedNeedleSaysItsPenetrationDepthIsALowerBound) {
  // A flat end punctures by a ring crack at a higher force than the sharp mechanism of the
  // penetration criterion: the row a screen or an optimisation reports must say so.
  const auto registry = PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
  auto scene =
      mneedle::load_scene(std::string(MNEEDLE_TEST_ASSETS) + "/scenes/puncture_punch.toml");
  scene.model.criterion = mneedle::PunctureCriterion::Penetration;
  const mneedle::NeedleSource n = mneedle::needle_from_plugin(registry, "cylinder", {});
  mneedle::EvaluationOptions o;
  o.symmetry = mneedle::needle_symmetry(registry, n, "cylinder");
  const auto e = mneedle::evaluate_design(n.mesh, scene, "silicon", o);
  ASSERT_TRUE(e.puncture.has_value());
  EXPECT_EQ(e.puncture->criterion, "penetration");
  EXPECT_TRUE(e.puncture->lower_bound);
  bool said = false;
  for (const std::string& note : e.notes) said = said || note.find("lower bound") != note.npos;
  EXPECT_TRUE(said);
}

// The puncture depth an optimisation minimises must be a continuous function of the design.
// Reported before the fixes of the puncture issue: diameters 184.397 and 184.477 um (0.04 % apart)
// punctured at 161 and 100 um. On the optimiser's mesh (tip element fixed from the start design,
// as `optimize` fixes it) the two must now read within 0.5 % (a mesh jump is the 3-D model's mesh
// error in skin, 5-10 %: docs/validation.md, "The stress criterion in skin"), and a diameter 3 %
// larger must move it smoothly, by far less than that error (2 % allowed).
TEST(DesignEvaluation, OnTheOptimisersMeshThePunctureDepthMovesContinuouslyWithTheDiameter) {
  const auto registry = PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
  const auto scene =
      mneedle::load_scene(std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/human_skin.toml");
  mneedle::EvaluationOptions o;
  o.fidelity = mneedle::fe::Fidelity::Fast;
  o.overrides.tip_size_m = mneedle::fe::mesh_sizing(o.fidelity, 2, 184.397e-6 / 2, 3000e-6, {},
                                                    scene.tissue.layers.front().strength->length)
                               .fine_size;
  auto depth_at = [&](double diameter) {
    const auto n = mneedle::needle_from_plugin(registry, "sharp_bevel",
                                               {{"diameter", diameter}, {"bevel_angle", 0.5236}});
    o.symmetry = mneedle::needle_symmetry(registry, n, "sharp_bevel");
    const auto e = mneedle::evaluate_design(n.mesh, scene, "silicon", o);
    EXPECT_TRUE(e.puncture.has_value()) << diameter;
    return e.puncture ? e.puncture->depth_m : 0.0;
  };
  const double d0 = depth_at(184.397e-6);
  const double d1 = depth_at(184.477e-6);
  const double d2 = depth_at(190e-6);
  // Measured 2026-12-05: 62.249, 62.251 and 62.377 um (0.002 % and 0.2 % apart).
  EXPECT_NEAR(d1, d0, 0.005 * d0);
  EXPECT_NEAR(d2, d0, 0.02 * d0);
}

}  // namespace
