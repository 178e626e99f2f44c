// The two-stage insertion run: puncture located on the FE curve, the post-puncture stage after
// it, the planner's decisions, arrays, and each reduction checked against the full model.

#include "mneedle/insertion/insertion_run.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <regex>
#include <string>

#include "fe/needle_meshes.h"
#include "mneedle/base/error.h"
#include "mneedle/geometry/tip_area.h"
#include "mneedle/insertion/penetration_force.h"
#include "mneedle/insertion/puncture.h"
#include "mneedle/insertion/surface_loads.h"

namespace mneedle {
namespace {

PreparedNeedle punch(const std::string& name, double r, double x = 0.0, double y = 0.0) {
  PreparedNeedle n;
  n.name = name;
  n.mesh = test::cylinder_needle(r, 1e-3);
  n.x = x;
  n.y = y;
  n.axisymmetric = fe::AxisymmetricNeedle::flat_punch(r);
  n.mirror_symmetric_y0 = true;
  n.mirror_symmetric_x0 = true;
  return n;
}

std::string scene_text(const std::string& extra_layers, const std::string& fracture,
                       const std::string& needles, const std::string& outputs,
                       const std::string& size = "[\"3000 um\", \"3000 um\", \"1150 um\"]",
                       const std::string& depth = "300 um") {
  return "[tissue]\nsize = " + size +
         "\n[[tissue.layers]]\nname = \"silicone\"\n"
         "material = { model = \"linear\", E = \"0.2 MPa\", nu = 0.45 }\n" +
         extra_layers + fracture + needles + "[insertion]\ndepth = \"" + depth +
         "\"\n[model]\nfidelity = \"fast\"\noutputs = " + outputs + "\n";
}

const std::string kFracture =
    "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"0.3 MPa\"\n";
const std::string kOnePunch =
    "[[needles]]\nname = \"punch\"\ngeometry = { plugin = \"cylinder\", diameter = \"230 um\" }\n";

// Paper A's skin: a 1 GPa stratum corneum with the skin scenes' strength, over soft layers.
const std::string kPaperASkinLayers =
    "[[tissue.layers]]\nname = \"stratum_corneum\"\nthickness = \"20 um\"\n"
    "material = { model = \"linear\", E = \"1 GPa\", nu = 0.4 }\n"
    "strength = \"21.6 MPa\"\nstrength_length = \"10 um\"\n"
    "[[tissue.layers]]\nname = \"epidermis\"\nthickness = \"100 um\"\n"
    "material = { model = \"linear\", E = \"0.134 MPa\", nu = 0.4 }\n"
    "[[tissue.layers]]\nname = \"dermis\"\n"
    "material = { model = \"linear\", E = \"0.08 MPa\", nu = 0.4 }\n";

Scene punch_scene(const std::string& fracture = kFracture,
                  const std::string& outputs = "[\"puncture\", \"force_curve\"]") {
  return parse_scene(scene_text("", fracture, kOnePunch, outputs), "punch.toml");
}

InsertionRunOptions fast() {
  InsertionRunOptions o;
  o.fidelity = fe::Fidelity::Fast;
  return o;
}

TEST(InsertionRun, FlatPunchPuncturesWhereItsLinearPressureReachesTheThreshold) {
  const Scene scene = punch_scene();
  const InsertionRun run = run_insertion(scene, {punch("punch", 115e-6)}, fast());
  ASSERT_EQ(run.needles.size(), 1u);
  EXPECT_EQ(run.models_run, (std::vector<std::string>{"axisymmetric_fe", "surface_loads"}));
  EXPECT_TRUE(run.axisymmetric);
  const NeedleRun& n = run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  // Linear tissue, flat punch: the section's outline is the same at every depth, so P = F / A_sec
  // is linear in depth and the bisected crossing is exact: P(d_p) = P_c (to the bisection's
  // 1e-6 of a step).
  const RunPoint* last_pre = nullptr;
  for (const RunPoint& p : n.curve)
    if (p.stage == Stage::Pre && p.depth_m < n.puncture->depth_m) last_pre = &p;
  ASSERT_NE(last_pre, nullptr);
  const double slope = last_pre->section_pressure_Pa / last_pre->depth_m;
  EXPECT_NEAR(slope * n.puncture->depth_m, 0.3e6, 0.3e6 * 1e-5);
  EXPECT_FALSE(n.puncture->at_first_contact);
  EXPECT_FALSE(n.puncture->flat_tip);  // only the penetration criterion flags a flat end
  // Boussinesq with the bonded layer: P = 2 E* d / (pi a) (1 + ~10 %) -> d_p ~ 200 um.
  EXPECT_GT(n.puncture->depth_m, 150e-6);
  EXPECT_LT(n.puncture->depth_m, 260e-6);
  EXPECT_NEAR(n.puncture->force_N, 0.3e6 * M_PI * 115e-6 * 115e-6, 0.02 * n.puncture->force_N);
}

TEST(InsertionRun, PostStageFollowsThePunctureWithTheSurfaceLoadModel) {
  const Scene scene = punch_scene();
  const PreparedNeedle needle = punch("punch", 115e-6);
  const InsertionRun run = run_insertion(scene, {needle}, fast());
  const NeedleRun& n = run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  const SurfaceLoadModel post(needle.mesh, load_constants(scene));
  EXPECT_NEAR(n.puncture->post_force_N, post.at(n.puncture->depth_m).force_N, 1e-12);
  // Stages: pre points, then the puncture depth twice (pre force, post force), then post only.
  bool seen_post = false;
  int at_puncture = 0;
  for (std::size_t i = 0; i < n.curve.size(); ++i) {
    const RunPoint& p = n.curve[i];
    if (i > 0) {
      EXPECT_GE(p.depth_m, n.curve[i - 1].depth_m);
    }
    if (p.depth_m == n.puncture->depth_m) ++at_puncture;
    if (p.stage == Stage::Post) {
      seen_post = true;
      EXPECT_NEAR(p.force_N, post.at(p.depth_m).force_N, 1e-12);
      EXPECT_NEAR(p.force_N, p.alpha_N + p.beta_N + p.friction_N, 1e-12);
      EXPECT_EQ(p.contact_area_m2, 0.0);
    } else {
      EXPECT_FALSE(seen_post) << "a pre-puncture point after the puncture";
    }
  }
  EXPECT_EQ(at_puncture, 2);
  EXPECT_NEAR(n.curve.back().depth_m, 300e-6, 1e-12);
  double max_force = 0.0;
  for (const RunPoint& p : n.curve) max_force = std::max(max_force, p.force_N);
  EXPECT_EQ(n.max_force_N, max_force);
}

// Paper A's skin (a 1 GPa stratum corneum with a strength over soft layers) under the stress
// criterion: the broken top layer keeps its grip on the shaft (docs/model.md, "The broken top
// layer"). Right after the puncture the force is the pre-puncture one; it then rises at the
// pre-puncture stiffness while the layer's own distributed loads (its grip) can hold it, and is
// the distributed loads of every layer once they cannot (the layer slides): min of the two,
// never below what the layers beneath carry. A flat punch, axisymmetric, fast.
TEST(InsertionRun, ABrokenStiffTopLayerKeepsItsGripUntilItsOwnLoadsAreExceeded) {
  const std::string text = "[tissue]\nsize = [\"3000 um\", \"3000 um\", \"1150 um\"]\n" +
                           kPaperASkinLayers + kOnePunch +
                           "[insertion]\ndepth = \"800 um\"\n[model]\nfidelity = \"fast\"\n"
                           "criterion = \"stress\"\noutputs = [\"puncture\", \"force_curve\"]\n";
  const Scene scene = parse_scene(text, "skin.toml");
  const PreparedNeedle needle = punch("punch", 115e-6);
  InsertionRunOptions options = fast();
  options.criterion = PunctureCriterion::Stress;
  const InsertionRun run = run_insertion(scene, {needle}, options);
  const NeedleRun& n = run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  const double dp = n.puncture->depth_m, fp = n.puncture->force_N;
  EXPECT_NEAR(n.puncture->post_force_N, fp, 1e-12 * fp);
  // The pre-puncture stiffness at the puncture: the slope over the last step before it.
  const RunPoint* last = nullptr;
  for (const RunPoint& p : n.curve)
    if (p.stage == Stage::Pre && p.depth_m < dp) last = &p;
  ASSERT_NE(last, nullptr);
  const double stiffness = (fp - last->force_N) / (dp - last->depth_m);
  const SurfaceLoadModel loads(needle.mesh, load_constants(scene));
  bool gripped = false, slid = false;
  double previous = 0.0;
  for (const RunPoint& p : n.curve) {
    if (p.stage != Stage::Post) continue;
    std::vector<LoadSample> layers;
    const LoadSample all = loads.at(p.depth_m, &layers);
    const double below = all.force_N - layers.front().force_N;
    const double held = fp + stiffness * (p.depth_m - dp);
    EXPECT_NEAR(p.force_N, std::max(below, std::min(held, all.force_N)), 1e-12 * all.force_N)
        << p.depth_m;
    EXPECT_NEAR(p.force_N, p.alpha_N + p.beta_N + p.friction_N + p.collar_N, 1e-12 * p.force_N);
    gripped = gripped || p.collar_N > 0.0;
    slid = slid || (p.collar_N == 0.0 && p.depth_m > dp);
    EXPECT_GE(p.force_N, previous * (1.0 - 1e-12)) << "the force falls at " << p.depth_m;
    previous = p.force_N;
  }
  EXPECT_TRUE(gripped);
  EXPECT_TRUE(slid) << "the layer never slid within 800 um";
}

TEST(InsertionRun, NeedleThatNeverPuncturesReportsItsMaximumForce) {
  const Scene scene =
      punch_scene("[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"50 MPa\"\n");
  const InsertionRun run = run_insertion(scene, {punch("punch", 115e-6)}, fast());
  const NeedleRun& n = run.needles.front();
  EXPECT_FALSE(n.puncture.has_value());
  EXPECT_NEAR(n.curve.back().depth_m, 300e-6, 1e-12);
  for (const RunPoint& p : n.curve) EXPECT_EQ(p.stage, Stage::Pre);
  EXPECT_EQ(n.max_force_N, n.curve.back().force_N);
  EXPECT_EQ(run.models_run, (std::vector<std::string>{"axisymmetric_fe"}));
}

TEST(InsertionRun, SceneWithoutPunctureDataRunsThePreStageToFullDepth) {
  const Scene scene = punch_scene("");
  const InsertionRun run = run_insertion(scene, {punch("punch", 115e-6)}, fast());
  EXPECT_FALSE(run.criterion.has_value());
  EXPECT_FALSE(run.needles.front().puncture.has_value());
  // The rung covering 300 um is 400 um, in 10 steps (fast) of 40 um: seven steps below 300 um
  // and the curve's end at 300 um.
  const auto& curve = run.needles.front().curve;
  ASSERT_EQ(curve.size(), 8u);
  EXPECT_NEAR(curve[6].depth_m, 280e-6, 1e-15);
  EXPECT_NEAR(curve.back().depth_m, 300e-6, 1e-15);
  EXPECT_NEAR(run.horizon_m, 400e-6, 1e-15);
}

// The pre-puncture model is built for the horizon ladder, never for the requested depth
// (docs/model.md, "Pre-puncture horizon"): asking for 300 or 800 um changes nothing before the
// puncture. Identical to round-off (1e-12): the same model, steps and arithmetic.
TEST(InsertionRun, PunctureDoesNotDependOnTheRequestedDepthAxisymmetric) {
  const std::string deep = scene_text("", kFracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                                      "[\"3000 um\", \"3000 um\", \"1150 um\"]", "800 um");
  const InsertionRun a = run_insertion(punch_scene(), {punch("punch", 115e-6)}, fast());
  const InsertionRun b =
      run_insertion(parse_scene(deep, "deep.toml"), {punch("punch", 115e-6)}, fast());
  ASSERT_TRUE(a.needles[0].puncture && b.needles[0].puncture);
  EXPECT_NEAR(a.needles[0].puncture->depth_m, b.needles[0].puncture->depth_m,
              1e-12 * b.needles[0].puncture->depth_m);
  EXPECT_NEAR(a.needles[0].puncture->force_N, b.needles[0].puncture->force_N,
              1e-12 * b.needles[0].puncture->force_N);
  EXPECT_EQ(a.horizon_m, b.horizon_m);
  EXPECT_EQ(a.nodes, b.nodes);
}

// A sharp 30-degree bevel of 230 um and the given length, on the half 3-D model.
PreparedNeedle half_model_bevel(double length_m) {
  PreparedNeedle bevel;
  bevel.name = "bevel";
  bevel.mesh = test::bevel_needle(115e-6, M_PI / 6, length_m);
  bevel.mirror_symmetric_y0 = true;
  return bevel;
}

// The silicone block of scene_text with the pressure criterion at `critical_pressure`.
Scene pressure_scene(const std::string& critical_pressure, const std::string& size,
                     const std::string& depth) {
  const std::string fracture =
      "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"" + critical_pressure +
      "\"\n";
  return parse_scene(
      scene_text("", fracture, kOnePunch, "[\"puncture\", \"force_curve\"]", size, depth),
      "bevel.toml");
}

TEST(InsertionRun, PunctureDoesNotDependOnTheRequestedDepth3d) {
  // A sharp bevel in silicone on the half 3-D model. Its F / A_sec falls from the first step
  // (0.49 MPa at 10 um: the tip node carries the force) to about 0.2 MPa at 60 um and rises
  // past it (0.42 MPa at 400 um): 0.5 MPa is crossed on the rising branch, on the 800 um rung.
  const PreparedNeedle bevel = half_model_bevel(1e-3);
  auto at_depth = [&](const std::string& depth) {
    return run_insertion(
        pressure_scene("0.5 MPa", "[\"1500 um\", \"1500 um\", \"1500 um\"]", depth), {bevel},
        fast());
  };
  const InsertionRun a = at_depth("600 um");
  const InsertionRun b = at_depth("900 um");
  ASSERT_TRUE(a.needles[0].puncture && b.needles[0].puncture);
  EXPECT_FALSE(a.needles[0].puncture->at_first_contact);
  EXPECT_NEAR(a.needles[0].puncture->depth_m, b.needles[0].puncture->depth_m,
              1e-12 * b.needles[0].puncture->depth_m);
  EXPECT_NEAR(a.needles[0].puncture->force_N, b.needles[0].puncture->force_N,
              1e-12 * b.needles[0].puncture->force_N);
}

// The 3-D model's ladder starts on the rung covering the closed form's crossing over its margin
// of 1.5 (docs/model.md, "Pre-puncture horizon"). The rungs it skips are rungs that would not
// have fired: the same puncture, to round-off, as the ladder climbed from rung 0, for fewer
// factorisations. Paper A's sharp bevel (0.663 MPa on F / A_sec) in a 0.2 MPa block at fast: the
// 3-D model runs the 800 um rung alone (1 factorisation) instead of all four; it punctures at
// 601 um on both paths.
TEST(InsertionRun, TheLadderSkipsOnlyRungsBelowTheClosedFormsCrossing) {
  const PreparedNeedle bevel = half_model_bevel(2e-3);
  const Scene scene = pressure_scene("0.663 MPa", "[\"3 mm\", \"3 mm\", \"2 mm\"]", "1 mm");
  InsertionRunOptions from_zero = fast();
  from_zero.start_from_closed_form = false;
  const InsertionRun a = run_insertion(scene, {bevel}, fast());
  const InsertionRun b = run_insertion(scene, {bevel}, from_zero);
  ASSERT_TRUE(a.needles[0].puncture && b.needles[0].puncture);
  EXPECT_EQ(a.needles[0].puncture->depth_m, b.needles[0].puncture->depth_m);
  EXPECT_EQ(a.needles[0].puncture->force_N, b.needles[0].puncture->force_N);
  EXPECT_EQ(a.horizon_m, b.horizon_m);
  EXPECT_LT(a.seconds_by_stage.factorizations, b.seconds_by_stage.factorizations);
  EXPECT_EQ(a.rungs_m, (std::vector<double>{800e-6}));
  EXPECT_EQ(b.rungs_m, (std::vector<double>{100e-6, 200e-6, 400e-6, 800e-6}));
  // The case stays the one described (a regression pin at the printed precision, 601.1 um).
  EXPECT_NEAR(a.needles[0].puncture->depth_m, 601e-6, 1e-6);
}

// The start rung fired within the rung below it (docs/model.md, "Pre-puncture horizon"): the
// rungs skipped might have fired, so the ladder climbs from rung 0 and the answer is the climb's.
// The bevel of PunctureDoesNotDependOnTheRequestedDepth3d at 0.25 MPa: the ladder starts on the
// 400 um rung, which fires below 200 um (the closed form has no dip; this F / A_sec dips to
// 0.2 MPa only at 60 um); rung 0 fires at its first step, 10 um.
TEST(InsertionRun, TheLadderClimbsFromRungZeroWhenItsStartFiresWithinTheRungBelow) {
  const PreparedNeedle bevel = half_model_bevel(1e-3);
  const Scene scene =
      pressure_scene("0.25 MPa", "[\"1500 um\", \"1500 um\", \"1500 um\"]", "900 um");
  InsertionRunOptions from_zero = fast();
  from_zero.start_from_closed_form = false;
  const InsertionRun a = run_insertion(scene, {bevel}, fast());
  const InsertionRun b = run_insertion(scene, {bevel}, from_zero);
  ASSERT_TRUE(a.needles[0].puncture && b.needles[0].puncture);
  EXPECT_EQ(a.rungs_m, (std::vector<double>{400e-6, 100e-6}));
  EXPECT_EQ(a.needles[0].puncture->depth_m, b.needles[0].puncture->depth_m);
  EXPECT_TRUE(a.needles[0].puncture->at_first_contact);
  // Asked 50 um deep, the start rung still runs to 200 um to decide, and decides the same.
  const InsertionRun shallow =
      run_insertion(pressure_scene("0.25 MPa", "[\"1500 um\", \"1500 um\", \"1500 um\"]", "50 um"),
                    {bevel}, fast());
  EXPECT_EQ(shallow.rungs_m, (std::vector<double>{400e-6, 100e-6}));
  ASSERT_TRUE(shallow.needles[0].puncture.has_value());
  EXPECT_EQ(shallow.needles[0].puncture->depth_m, a.needles[0].puncture->depth_m);
}

// A start above the rung covering the requested depth still runs (its run stops at the depth),
// so the rung, and the answer, do not depend on the depth asked. The same bevel at 0.3 MPa starts
// on the 400 um rung: nothing within 50 um, and 238 um asked 300 or 900 um deep. (Climbed from
// rung 0 it fires at first contact, 10 um, on a tip spike of the 100 um rung's mesh: the limit
// docs/model.md states.)
TEST(InsertionRun, AStartAboveTheRequestedDepthStillRunsSoTheAnswerDoesNotDependOnIt) {
  const PreparedNeedle bevel = half_model_bevel(1e-3);
  auto at_depth = [&](const std::string& depth) {
    return run_insertion(
        pressure_scene("0.3 MPa", "[\"1500 um\", \"1500 um\", \"1500 um\"]", depth), {bevel},
        fast());
  };
  const InsertionRun a = at_depth("300 um");
  const InsertionRun b = at_depth("900 um");
  // The 50 um run decides on the 400 um rung's run to 200 um (the rung below reaches that far);
  // what it shows, progress lines and VTU steps, ends where a run asked for 50 um ends.
  InsertionRunOptions shown = fast();
  shown.vtu_directory =
      (std::filesystem::temp_directory_path() / ("mneedle_shown_" + std::to_string(::getpid())))
          .string();
  double deepest_progress = 0.0;
  shown.on_progress = [&](const std::string&, int, int, double depth_m, double) {
    deepest_progress = std::max(deepest_progress, depth_m);
  };
  const InsertionRun shallow =
      run_insertion(pressure_scene("0.3 MPa", "[\"1500 um\", \"1500 um\", \"1500 um\"]", "50 um"),
                    {bevel}, shown);
  EXPECT_EQ(shallow.rungs_m, (std::vector<double>{400e-6}));
  EXPECT_FALSE(shallow.needles[0].puncture.has_value());
  // A run asked for 50 um ends with the first step at or beyond it.
  const double step = shallow.first_step_m;
  const double last_shown = std::ceil(50e-6 / step - 1e-9) * step * (1 + 1e-12);
  ASSERT_GT(step, 0.0);
  EXPECT_LE(deepest_progress, last_shown);
  // ... and reaches it: the progress stops at that step, not before.
  EXPECT_GE(deepest_progress, last_shown * (1 - 1e-9));
  std::ifstream pvd(shown.vtu_directory + "/steps.pvd");
  const std::string collection{std::istreambuf_iterator<char>(pvd),
                               std::istreambuf_iterator<char>()};
  const std::regex timestep("timestep=\"([^\"]+)\"");
  int steps = 0;
  for (auto it = std::sregex_iterator(collection.begin(), collection.end(), timestep);
       it != std::sregex_iterator(); ++it, ++steps)
    EXPECT_LE(std::stod((*it)[1].str()), last_shown) << (*it)[0].str();
  EXPECT_GT(steps, 0);
  std::filesystem::remove_all(shown.vtu_directory);
  ASSERT_TRUE(a.needles[0].puncture && b.needles[0].puncture);
  EXPECT_EQ(a.needles[0].puncture->depth_m, b.needles[0].puncture->depth_m);
  EXPECT_NEAR(a.needles[0].puncture->depth_m, 238e-6, 1e-6);  // measured 238.07 um
}

TEST(InsertionRun, CriterionAboveThresholdAtTheFirstStepIsFlaggedAtFirstContact) {
  // 1 kPa is below the flat punch's F / A_sec at the first step: fired on contact.
  const InsertionRun run = run_insertion(
      punch_scene("[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"1 kPa\"\n"),
      {punch("punch", 115e-6)}, fast());
  const auto& p = run.needles[0].puncture;
  ASSERT_TRUE(p.has_value());
  EXPECT_TRUE(p->at_first_contact);
  EXPECT_DOUBLE_EQ(p->depth_m, run.first_step_m);
}

std::string error_of(const Scene& scene, const std::vector<PreparedNeedle>& needles) {
  try {
    run_insertion(scene, needles, fast());
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(InsertionRun, NeedleWiderThanTheBlockIsAnInputErrorNamingTheUnit) {
  // A 230 um needle read in mm as if it were m would be 230 mm wide: here 4 mm in a 3 mm block.
  const std::string message = error_of(punch_scene(), {punch("punch", 2e-3)});
  EXPECT_NE(message.find("punch.toml:"), std::string::npos) << message;
  EXPECT_NE(message.find("needle 'punch': 4 mm wide"), std::string::npos) << message;
  EXPECT_NE(message.find("is the mesh's unit right?"), std::string::npos) << message;
}

TEST(InsertionRun, OverlappingNeedlesAreAnInputError) {
  const std::string two = kOnePunch + "at = [\"0 um\", \"0 um\"]\n" +
                          "[[needles]]\nname = \"twin\"\ngeometry = { plugin = \"cylinder\", "
                          "diameter = \"230 um\" }\nat = [\"100 um\", \"0 um\"]\n";
  const Scene scene =
      parse_scene(scene_text("", kFracture, two, "[\"puncture\", \"force_curve\"]"), "two.toml");
  const std::string message =
      error_of(scene, {punch("punch", 115e-6), punch("twin", 115e-6, 100e-6, 0.0)});
  EXPECT_NE(message.find("needle 'twin': overlaps needle 'punch'"), std::string::npos) << message;
}

// Puncture depth of a bevel at 15..45 deg in 2 deg steps: each resolved (not at first contact,
// not a flat end), no two adjacent angles tied, and the increment from one step to the next
// changing by at most 5 um (a quarter of the smallest step a jump to the grid would show).
void expect_continuous_over_bevel_angles(const Scene& scene, const InsertionRunOptions& o) {
  std::vector<double> depths;
  for (int degrees = 15; degrees <= 45; degrees += 2) {
    PreparedNeedle bevel;
    bevel.name = "punch";
    bevel.mesh = test::bevel_needle(115e-6, degrees * M_PI / 180.0, 1e-3);
    const InsertionRun run = run_insertion(scene, {bevel}, o);
    ASSERT_TRUE(run.needles[0].puncture.has_value()) << degrees << " deg";
    const Puncture& p = *run.needles[0].puncture;
    EXPECT_FALSE(p.at_first_contact) << degrees << " deg";
    EXPECT_FALSE(p.flat_tip) << degrees << " deg";  // a bevel ends in a point
    depths.push_back(p.depth_m);
  }
  for (std::size_t i = 1; i < depths.size(); ++i)
    EXPECT_GT(std::abs(depths[i] - depths[i - 1]), 1e-9 * depths[i]) << "tie at " << 15 + 2 * i;
  for (std::size_t i = 2; i < depths.size(); ++i) {
    const double change = (depths[i] - depths[i - 1]) - (depths[i - 1] - depths[i - 2]);
    EXPECT_LT(std::abs(change), 5e-6) << "jump at " << 15 + 2 * i << " deg: " << depths[i - 2]
                                      << ", " << depths[i - 1] << ", " << depths[i];
  }
}

TEST(InsertionRun, PunctureDepthMovesContinuouslyWithTheBevelAngle) {
  // Bevel angle 15..45 deg in 2 deg steps on the closed-form model in silicone (P_c 0.15 MPa,
  // crossed on the rising branch of F / A_sec; the depths run 29 -> 230 um, crossing the 100 and
  // 200 um rungs). Every angle has its own depth (no ties, as when the crossing sat on the step
  // grid), and the depth has no jump: from one 2 deg step to the next its increment changes by
  // at most 5 um (3.4 um measured), a quarter of the smallest step a jump to the grid would show
  // (20 um, the 200 um rung at fast).
  const std::string fracture =
      "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"0.15 MPa\"\n";
  const Scene scene =
      parse_scene(scene_text("", fracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                             "[\"3000 um\", \"3000 um\", \"2000 um\"]", "400 um"),
                  "angles.toml");
  InsertionRunOptions o = fast();
  o.model = PreModel::Analytic;
  expect_continuous_over_bevel_angles(scene, o);
}

TEST(InsertionRun, PenetrationCriterionFiresWhereTheForceReachesThePenetrationForce) {
  // Flat punch (axisymmetric FE): its section at the surface is the whole circle from the first
  // step, so F_p is one number, and F is linear in depth: the bisected crossing has F = F_p to
  // the bisection's 1e-6 of a step.
  InsertionRunOptions o = fast();
  o.criterion = PunctureCriterion::Penetration;
  const InsertionRun run = run_insertion(punch_scene(), {punch("punch", 115e-6)}, o);
  ASSERT_TRUE(run.criterion && *run.criterion == PunctureCriterion::Penetration);
  EXPECT_EQ(*run.threshold, 1.0);
  const NeedleRun& n = run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  // The mesh's circle is a 48-gon: F_p is of the radius with its outline's area,
  // r sqrt(48 sin(2 pi / 48) / (2 pi)).
  const double radius = std::sqrt(n.curve.front().section_area_m2 / M_PI);
  EXPECT_NEAR(radius, 115e-6 * std::sqrt(48.0 * std::sin(2.0 * M_PI / 48.0) / (2.0 * M_PI)), 1e-12);
  const double fp = sharp_penetration_force(0.2e6, 0.45, 19.0, radius).force_N;
  EXPECT_NEAR(n.puncture->force_N, fp, 1e-5 * fp);
  for (const RunPoint& p : n.curve) {
    if (p.stage != Stage::Pre) continue;
    EXPECT_NEAR(p.penetration_force_N, fp, 1e-12 * fp) << p.depth_m;
  }
  EXPECT_FALSE(n.puncture->at_first_contact);
  // A flat end: F_p is the sharp mechanism's, and the depth is flagged as a lower bound.
  EXPECT_TRUE(n.puncture->flat_tip);
}

TEST(InsertionRun, PenetrationDepthMovesContinuouslyWithTheBevelAngle) {
  // As PunctureDepthMovesContinuouslyWithTheBevelAngle, with F_p of the bevel's section: depths
  // 239 um at 15 deg, 255 um near 33 deg, 237 um at 45 deg on the closed-form model; no ties, and
  // the increment from one 2 deg step to the next changes by at most 5 um (1.8 um measured).
  const Scene scene =
      parse_scene(scene_text("", kFracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                             "[\"3000 um\", \"3000 um\", \"2000 um\"]", "400 um"),
                  "angles.toml");
  InsertionRunOptions o = fast();
  o.model = PreModel::Analytic;
  o.criterion = PunctureCriterion::Penetration;
  expect_continuous_over_bevel_angles(scene, o);
}

TEST(InsertionRun, ExplicitCriterionWithoutItsDataIsAnInputError) {
  const Scene scene = punch_scene();
  InsertionRunOptions o = fast();
  o.criterion = PunctureCriterion::Stress;
  EXPECT_THROW(run_insertion(scene, {punch("punch", 115e-6)}, o), InputError);
}

// The cohesive criterion (docs/model.md, "The cohesive criterion") on a 200 um flat punch in the
// gel of scene_text: G_c 19 J/m^2 and sigma_c 356 kPa, E G_c / sigma_c^2 = 30 um, as in
// tests/core/fe/test_axisymmetric_outputs.cpp's punch, whose force peaks at 370-380 um.
const std::string kCohesiveFracture =
    "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"0.3 MPa\"\n"
    "cohesive_strength = \"356 kPa\"\n";

Scene cohesive_scene(const std::string& depth = "500 um",
                     const std::string& material = "model = \"linear\"") {
  std::string text = scene_text("", kCohesiveFracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                                "[\"4 mm\", \"4 mm\", \"2 mm\"]", depth);
  text.replace(text.find("model = \"linear\""), 16, material);
  return parse_scene(text, "cohesive.toml");
}

InsertionRunOptions cohesive_fast() {
  InsertionRunOptions o = fast();
  o.criterion = PunctureCriterion::Cohesive;
  return o;
}

// The force rises, the ring crack opens and grows stably, then runs: the puncture is the force's
// peak, located between the steps (a parabola's vertex), with its process zone resolved.
TEST(CohesiveCriterion, PuncturesAtTheForcesPeakWithItsProcessZoneResolved) {
  const InsertionRun run =
      run_insertion(cohesive_scene(), {punch("punch", 100e-6)}, cohesive_fast());
  ASSERT_EQ(run.criterion, PunctureCriterion::Cohesive);
  EXPECT_DOUBLE_EQ(*run.threshold, 19.0);
  // The ring's line: the needle's diameter, within the 2 mm layer.
  EXPECT_NEAR(run.crack_depth_m, 200e-6, 1e-15);
  const NeedleRun& n = run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  EXPECT_FALSE(n.puncture->at_first_contact);
  // The fe test's 25 um cells put the peak at 370 um with 10 um steps; these are 7.4 um (a quarter
  // of 30 um) and the steps 40 um: within a step of it.
  EXPECT_GT(n.puncture->depth_m, 330e-6);
  EXPECT_LT(n.puncture->depth_m, 410e-6);
  // The peak force is at least every step's force before it (the vertex tops its steps), and
  // the fe test's peak: 18.53 / 19.27 / 19.10 mN with 25 / 12.5 / 6.25 um cells; these read
  // 18.64 mN (measured).
  double highest = 0.0, fracture = 0.0;
  for (const RunPoint& p : n.curve)
    if (p.stage == Stage::Pre && p.depth_m < n.puncture->depth_m) {
      highest = std::max(highest, p.force_N);
      fracture = p.fracture_energy_J;
    }
  EXPECT_GE(n.puncture->force_N, highest);
  EXPECT_GT(n.puncture->force_N, 18.0e-3);
  EXPECT_LT(n.puncture->force_N, 19.5e-3);
  EXPECT_GT(fracture, 0.0);  // the crack grew stably before it ran
  // The process zone at the step that tops the peak (the run refuses fewer than 3 cells there).
  const RunPoint& at = *std::find_if(n.curve.begin(), n.curve.end(), [&](const RunPoint& p) {
    return p.depth_m >= n.puncture->depth_m;
  });
  EXPECT_GE(at.process_zone_cells, 3);
  // W = U + W_d over the pre-puncture stage (the ledger with the law's dissipation).
  ASSERT_TRUE(run.energy_check.has_value());
  EXPECT_TRUE(run.energy_check->passes) << run.energy_check->relative_difference;
}

// 1.2 mm, and 360 um just beyond the peak (356 um): the peak lies in the 400 um rung's step from
// 320 to 360 um and is confirmed by the step after, which a run asked for 360 um takes beyond its
// depth. Same rung, same mesh, same steps: the same numbers, to the round-off of a re-run (1e-12).
TEST(CohesiveCriterion, TheRequestedDepthDoesNotMoveThePuncture) {
  const InsertionRun b =
      run_insertion(cohesive_scene("1200 um"), {punch("punch", 100e-6)}, cohesive_fast());
  ASSERT_TRUE(b.needles[0].puncture);
  ASSERT_LT(b.needles[0].puncture->depth_m, 360e-6);
  const InsertionRun a =
      run_insertion(cohesive_scene("360 um"), {punch("punch", 100e-6)}, cohesive_fast());
  ASSERT_TRUE(a.needles[0].puncture);
  EXPECT_EQ(a.horizon_m, b.horizon_m);
  EXPECT_NEAR(a.needles[0].puncture->depth_m, b.needles[0].puncture->depth_m,
              1e-12 * b.needles[0].puncture->depth_m);
  EXPECT_NEAR(a.needles[0].puncture->force_N, b.needles[0].puncture->force_N,
              1e-12 * b.needles[0].puncture->force_N);
  // Asked for less than the peak: no puncture, and no error from the step beyond (the checks
  // look within the requested depth only).
  const InsertionRun c =
      run_insertion(cohesive_scene("340 um"), {punch("punch", 100e-6)}, cohesive_fast());
  EXPECT_FALSE(c.needles[0].puncture);
}

// Paper A's skin under the punch: the ring ends at the 20 um stratum corneum's bottom, and the
// layer punctures where the ring has failed throughout (the force keeps rising: the layers
// beneath carry the plug). l_ch = 1 GPa x 10 J/m^2 / (21.6 MPa)^2 = 21 um: the line's own 20 um
// sets the cells (5 um at fast).
TEST(CohesiveCriterion, ARingThroughAThinTopLayerPuncturesWhereItIsCutThrough) {
  const std::string fracture =
      "[tissue.fracture]\ntoughness = \"10 J/m^2\"\ncritical_pressure = \"3 MPa\"\n"
      "cohesive_strength = \"21.6 MPa\"\n";
  std::string text =
      scene_text(kPaperASkinLayers, fracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                 "[\"3000 um\", \"3000 um\", \"1150 um\"]", "800 um");
  // scene_text's own silicone layer goes first: drop it, the skin's three layers remain.
  const auto from = text.find("[[tissue.layers]]\nname = \"silicone\"");
  text.erase(from, text.find("[[tissue.layers]]", from + 1) - from);
  const InsertionRun run =
      run_insertion(parse_scene(text, "skin.toml"), {punch("punch", 115e-6)}, cohesive_fast());
  EXPECT_NEAR(run.crack_depth_m, 20e-6, 1e-15);  // the layer, not the diameter
  const NeedleRun& n = run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  // Measured 480 um at fast (80 um steps on the 800 um rung); standard and fine read 440 um.
  EXPECT_GT(n.puncture->depth_m, 400e-6);
  EXPECT_LE(n.puncture->depth_m, 480e-6 + 1e-12);
  double last = 0.0;
  for (const RunPoint& p : n.curve)
    if (p.stage == Stage::Pre) {
      EXPECT_GE(p.force_N, last);  // no peak: the cut, not a force drop, fires it
      last = p.force_N;
    }
  const RunPoint& at = *std::find_if(n.curve.begin(), n.curve.end(), [&](const RunPoint& p) {
    return p.depth_m >= n.puncture->depth_m;
  });
  // Interpolated to kCutThrough, 1 - 1e-9 (to the interpolation's round-off).
  EXPECT_NEAR(at.cohesive_failed_fraction, kCutThrough, 1e-12);
}

// optimize fixes the mesh's tip size over a search (25 um here, fast's own for this punch): the
// ring keeps its own cells, so the run is the default's, to the last digit (it was refused, its
// ring given the tip's 25 um cells).
TEST(CohesiveCriterion, AFixedTipSizeKeepsTheRingsOwnCells) {
  InsertionRunOptions o = cohesive_fast();
  o.overrides.tip_size_m = 25e-6;
  const InsertionRun fixed = run_insertion(cohesive_scene(), {punch("punch", 100e-6)}, o);
  const InsertionRun own =
      run_insertion(cohesive_scene(), {punch("punch", 100e-6)}, cohesive_fast());
  ASSERT_TRUE(fixed.needles[0].puncture && own.needles[0].puncture);
  EXPECT_EQ(fixed.nodes, own.nodes);
  EXPECT_EQ(fixed.needles[0].puncture->depth_m, own.needles[0].puncture->depth_m);
}

// Cells of 50 um hold the process zone in one or two: the peak would follow the mesh.
TEST(CohesiveCriterion, AProcessZoneOfFewerThanThreeCellsIsRefused) {
  InsertionRunOptions o = cohesive_fast();
  o.cohesive_cell_m = 50e-6;
  try {
    run_insertion(cohesive_scene(), {punch("punch", 100e-6)}, o);
    FAIL() << "expected a SolverError";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("process zone spans"), std::string::npos) << e.what();
  }
}

TEST(CohesiveCriterion, NeedsTheAxisymmetricModelLinearLayersAndStickingContact) {
  auto message = [](const Scene& scene, const std::vector<PreparedNeedle>& needles,
                    InsertionRunOptions o) {
    try {
      run_insertion(scene, needles, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  InsertionRunOptions o = cohesive_fast();
  o.model = PreModel::Full3d;
  EXPECT_NE(message(cohesive_scene(), {punch("punch", 100e-6)}, o).find("axisymmetric model only"),
            std::string::npos);
  o.model = PreModel::Analytic;
  EXPECT_NE(message(cohesive_scene(), {punch("punch", 100e-6)}, o).find("no crack"),
            std::string::npos);
  EXPECT_NE(message(cohesive_scene("500 um", "model = \"neo_hookean\""), {punch("punch", 100e-6)},
                    cohesive_fast())
                .find("needs linear layers"),
            std::string::npos);
  o = cohesive_fast();
  o.contact = Contact::Frictionless;
  EXPECT_NE(message(cohesive_scene(), {punch("punch", 100e-6)}, o).find("sticking contact"),
            std::string::npos);
}

// Paper A's silicone with its 3.3 MPa strength: E G_c / sigma_c^2 = 0.35 um, thousands of cells
// down the ring. Refused before any mesh is built, naming the law's length.
TEST(CohesiveCriterion, ALawTooShortForTheRingIsRefusedBeforeAnyWork) {
  std::string text = scene_text("", kCohesiveFracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                                "[\"4 mm\", \"4 mm\", \"2 mm\"]", "500 um");
  text.replace(text.find("356 kPa"), 7, "3.3 MPa");
  try {
    run_insertion(parse_scene(text, "strong.toml"), {punch("punch", 100e-6)}, cohesive_fast());
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("strong.toml:"), std::string::npos) << m;
    EXPECT_NE(m.find("tissue.fracture.cohesive_strength"), std::string::npos) << m;
    EXPECT_NE(m.find("348.944 nm"), std::string::npos) << m;
    EXPECT_NE(m.find("above the limit of 150"), std::string::npos) << m;
  }
}

TEST(ScenePlanner, PostPunctureCurveOnlyRunsNoFiniteElements) {
  const Scene scene = punch_scene(kFracture, "[\"force_curve\"]");
  const PreparedNeedle needle = punch("punch", 115e-6);
  const InsertionRun run = run_insertion(scene, {needle}, fast());
  EXPECT_EQ(run.models_run, (std::vector<std::string>{"surface_loads"}));
  EXPECT_EQ(run.nodes, 0);
  ASSERT_FALSE(run.reductions.empty());
  EXPECT_EQ(run.reductions.front().name, "no_fe");
  const SurfaceLoadModel post(needle.mesh, load_constants(scene));
  for (const RunPoint& p : run.needles.front().curve) {
    EXPECT_EQ(p.stage, Stage::Post);
    EXPECT_NEAR(p.force_N, post.at(p.depth_m).force_N, 1e-12);
  }
}

TEST(ScenePlanner, PunctureOnlyStopsTheFiniteElementsAtThePuncture) {
  const Scene full = punch_scene();
  const Scene only = punch_scene(kFracture, "[\"puncture\"]");
  const InsertionRun a = run_insertion(full, {punch("punch", 115e-6)}, fast());
  const InsertionRun b = run_insertion(only, {punch("punch", 115e-6)}, fast());
  ASSERT_TRUE(b.needles.front().puncture.has_value());
  EXPECT_NEAR(b.needles.front().puncture->depth_m, a.needles.front().puncture->depth_m, 1e-12);
  // The curve ends at the puncture: no post stage, no pre point past it.
  EXPECT_EQ(b.needles.front().curve.back().depth_m, b.needles.front().puncture->depth_m);
  for (const RunPoint& p : b.needles.front().curve) EXPECT_EQ(p.stage, Stage::Pre);
  // The post-puncture model runs at the puncture depth only, for post_force_N.
  EXPECT_EQ(b.models_run, (std::vector<std::string>{"axisymmetric_fe", "surface_loads"}));
  EXPECT_GT(b.needles.front().puncture->post_force_N, 0.0);
  const auto& r = b.reductions;
  EXPECT_TRUE(std::any_of(r.begin(), r.end(),
                          [](const Reduction& x) { return x.name == "stop_at_puncture"; }));
}

TEST(ScenePlanner, DeepLayersMergeIntoTheSubstrateWithinTheTolerance) {
  // Influence depth 10 (a + H) = 10 (115 + 100) um = 2150 um, H the first pre-puncture horizon
  // (the one covering the 50 um asked for): the two layers below 2300 um merge.
  const std::string layers =
      "thickness = \"400 um\"\n"
      "[[tissue.layers]]\nname = \"middle\"\nthickness = \"1900 um\"\n"
      "material = { model = \"linear\", E = \"0.25 MPa\", nu = 0.45 }\n"
      "[[tissue.layers]]\nname = \"deep\"\nthickness = \"200 um\"\n"
      "material = { model = \"linear\", E = \"0.1 MPa\", nu = 0.45 }\n"
      "[[tissue.layers]]\nname = \"deeper\"\n"
      "material = { model = \"linear\", E = \"0.4 MPa\", nu = 0.45 }\n";
  const Scene scene =
      parse_scene(scene_text(layers, "", kOnePunch, "[\"puncture\", \"force_curve\"]",
                             "[\"3000 um\", \"3000 um\", \"3000 um\"]", "50 um"),
                  "layers.toml");
  InsertionRunOptions reduced = fast();
  InsertionRunOptions full = fast();
  full.allow_reductions = false;
  const InsertionRun a = run_insertion(scene, {punch("punch", 115e-6)}, reduced);
  const InsertionRun b = run_insertion(scene, {punch("punch", 115e-6)}, full);
  const auto& r = a.reductions;
  ASSERT_TRUE(
      std::any_of(r.begin(), r.end(), [](const Reduction& x) { return x.name == "layer_merge"; }));
  const double fa = a.needles.front().curve.back().force_N;
  const double fb = b.needles.front().curve.back().force_N;
  EXPECT_LT(std::abs(fa - fb) / fb, 0.05) << fa << " vs " << fb;  // fast tolerance 5 %
  EXPECT_LT(a.elements, b.elements);
  // The axisymmetric run measures its own merge against the scene's layers.
  const auto merge =
      std::find_if(r.begin(), r.end(), [](const Reduction& x) { return x.name == "layer_merge"; });
  ASSERT_TRUE(merge->measured_effect.has_value());
  EXPECT_NEAR(*merge->measured_effect, std::abs(fa - fb) / fb, 1e-9);
}

TEST(ScenePlanner, MergeThatChangesTheForceBeyondTheToleranceIsUndone) {
  // Same layers as above with a tolerance far below the merge's measured effect: the run
  // reports the merge as rejected and its result is the full-layer model's.
  const std::string layers =
      "thickness = \"400 um\"\n"
      "[[tissue.layers]]\nname = \"middle\"\nthickness = \"1900 um\"\n"
      "material = { model = \"linear\", E = \"0.25 MPa\", nu = 0.45 }\n"
      "[[tissue.layers]]\nname = \"deep\"\nthickness = \"200 um\"\n"
      "material = { model = \"linear\", E = \"0.1 MPa\", nu = 0.45 }\n"
      "[[tissue.layers]]\nname = \"deeper\"\n"
      "material = { model = \"linear\", E = \"0.4 MPa\", nu = 0.45 }\n";
  const Scene scene =
      parse_scene(scene_text(layers, "", kOnePunch, "[\"puncture\", \"force_curve\"]",
                             "[\"3000 um\", \"3000 um\", \"3000 um\"]", "50 um"),
                  "layers.toml");
  InsertionRunOptions strict = fast();
  strict.reduction_tolerance = 1e-9;
  InsertionRunOptions full = fast();
  full.allow_reductions = false;
  const InsertionRun a = run_insertion(scene, {punch("punch", 115e-6)}, strict);
  const InsertionRun b = run_insertion(scene, {punch("punch", 115e-6)}, full);
  const auto merge = std::find_if(a.reductions.begin(), a.reductions.end(), [](const Reduction& x) {
    return x.name == "layer_merge_rejected";
  });
  ASSERT_NE(merge, a.reductions.end());
  EXPECT_GT(*merge->measured_effect, 1e-9);
  EXPECT_EQ(a.elements, b.elements);
  EXPECT_NEAR(a.needles[0].curve.back().force_N, b.needles[0].curve.back().force_N, 1e-15);
}

// A 12 mm block under a 230 um punch pressed 50 um: on the 100 um rung the planner keeps
// 10 (a + H) = 2150 um around the needle (4.3 mm square) and measures what the cut changes.
Scene wide_block_scene() {
  return parse_scene(scene_text("", "", kOnePunch, "[\"puncture\", \"force_curve\"]",
                                "[\"12 mm\", \"12 mm\", \"1150 um\"]", "50 um"),
                     "wide.toml");
}

const Reduction* find_reduction(const InsertionRun& run, const std::string& name) {
  for (const Reduction& r : run.reductions)
    if (r.name == name) return &r;
  return nullptr;
}

// The reduction's reference run meshes as the run it checks: under the stress criterion a
// pointed tip's axisymmetric mesh is sized from L (docs/model.md, "Mesh"), and a reference run
// without the criterion's data was meshed coarser, so the "measured effect" of a cut held the
// two meshes' difference too (1.3 %, a review's measurement). A 15-degree cone in a 12 mm block
// of paper A's skin, pressed 50 um (before its puncture): the measured effect is the change
// between the cut run and the same run on the whole block, to round-off.
// A 15-degree cone of 230 um in paper A's skin (block side, insertion depth, fidelity, more
// [model] keys), under the stress criterion.
Scene skin_cone_scene(const std::string& side, const std::string& depth,
                      const std::string& fidelity, const std::string& model_keys = "") {
  const std::string text =
      "[tissue]\nsize = [\"" + side + "\", \"" + side + "\", \"1150 um\"]\n" + kPaperASkinLayers +
      "[[needles]]\nname = \"cone\"\ngeometry = { plugin = \"cone\", diameter = \"230 um\" }\n"
      "[insertion]\ndepth = \"" +
      depth + "\"\n[model]\nfidelity = \"" + fidelity +
      "\"\n"
      "criterion = \"stress\"\noutputs = [\"puncture\"]\n" +
      model_keys;
  return parse_scene(text, "cone.toml");
}

PreparedNeedle skin_cone() {
  PreparedNeedle cone;
  cone.name = "cone";
  cone.mesh = test::cone_needle(15.0 * std::numbers::pi / 180.0, 115e-6, 1e-3);
  cone.axisymmetric = fe::AxisymmetricNeedle::cone(15.0 * std::numbers::pi / 180.0, 115e-6);
  return cone;
}

TEST(ScenePlanner, AReductionIsMeasuredOnTheMeshOfTheRunItChecks) {
  const Scene scene = skin_cone_scene("12 mm", "50 um", "fast");
  const PreparedNeedle cone = skin_cone();
  InsertionRunOptions options = fast();
  options.criterion = PunctureCriterion::Stress;
  const InsertionRun cut_run = run_insertion(scene, {cone}, options);
  options.allow_reductions = false;
  const InsertionRun whole = run_insertion(scene, {cone}, options);
  const Reduction* cut = find_reduction(cut_run, "domain_cut");
  ASSERT_NE(cut, nullptr);
  ASSERT_TRUE(cut->measured_effect.has_value());
  ASSERT_FALSE(cut_run.needles.front().puncture.has_value());
  const RunPoint& a = cut_run.needles.front().curve.back();
  const RunPoint& b = whole.needles.front().curve.back();
  ASSERT_DOUBLE_EQ(a.depth_m, b.depth_m);
  EXPECT_NEAR(*cut->measured_effect, std::abs(a.force_N - b.force_N) / b.force_N, 1e-9);
}

// The 3-D model converges under a pointed tip in skin once it resolves what the axisymmetric
// model resolves at standard (docs/validation.md, "The 3-D model under a point load, resolved"):
// the ball under the tip (the convergence study's contact zone, cells of L/2 = 5 um), the tip's
// own contact patch (graded down to 0.3 um toward it) and the stratum corneum's bending away
// from it (fine's growth, 1.35). A 15-degree cone of 230 um in paper A's skin: the
// axisymmetric depth at standard is converged to 1 % (65.4 um against 65.0 at L/32 for the
// plugin's cone); here 64.6 um, and the 3-D quarter model 63.7 um (-1.4 %), 5.61 against
// 5.52 mN (+1.6 %). Bounds: 3 % on the depth (the study's 3-D cone reads 64.0-64.4 um over
// zones of L/2 and L/4 and tip sizes of 0.3-0.6 um, the axisymmetric model's own 1 %, and the
// 48-segment cone here against the bench's 64) and 2.5 % on the force (measured +0.7 to
// +1.6 % over the same zones). The same grid without the tip's grading reads 62.3 um, at
// standard's growth 1.8 58.1 um (-10 %), and standard without a zone 71.2 um (+9 %).
TEST(ScenePlanner, AThreeDConeWithAResolvedTipPuncturesSkinWhereTheAxisymmetricOneDoes) {
  // The zone from the scene's keys (docs/scene.md, [model]), as a user gives it; they reach the
  // 3-D model only (the axisymmetric run ignores them).
  const Scene scene = skin_cone_scene("3000 um", "200 um", "standard",
                                      "contact_zone = \"6 um\"\ncontact_zone_tip = \"0.3 um\"\n");
  PreparedNeedle cone = skin_cone();
  cone.mirror_symmetric_x0 = cone.mirror_symmetric_y0 = true;
  InsertionRunOptions axisymmetric;
  axisymmetric.fidelity = fe::Fidelity::Standard;
  axisymmetric.criterion = PunctureCriterion::Stress;
  InsertionRunOptions three_d = axisymmetric;
  three_d.model = PreModel::Full3d;
  three_d.overrides.growth = 1.35;
  const InsertionRun axi = run_insertion(scene, {cone}, axisymmetric);
  const InsertionRun block = run_insertion(scene, {cone}, three_d);
  ASSERT_TRUE(axi.axisymmetric);
  ASSERT_FALSE(block.axisymmetric);
  const auto& a = axi.needles.front().puncture;
  const auto& b = block.needles.front().puncture;
  ASSERT_TRUE(a && b);
  ASSERT_FALSE(a->at_first_contact || b->at_first_contact);
  EXPECT_NEAR(b->depth_m / a->depth_m, 1.0, 0.03) << a->depth_m << " " << b->depth_m;
  EXPECT_NEAR(b->force_N / a->force_N, 1.0, 0.025) << a->force_N << " " << b->force_N;
}

// A scene's contact zone on a run without refinement levels (here TET4 elements, whose grid has
// none by default) is refused in one line naming the scene and the key, not silently dropped.
TEST(ScenePlanner, ASceneContactZoneWithoutARefinedGridIsRefusedNamingTheScene) {
  const Scene scene = skin_cone_scene("3000 um", "200 um", "fast", "contact_zone = \"6 um\"\n");
  InsertionRunOptions tet4;
  tet4.fidelity = fe::Fidelity::Fast;
  tet4.criterion = PunctureCriterion::Stress;
  tet4.overrides.order = 1;
  try {
    run_insertion(scene, {skin_cone()}, tet4);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("cone.toml: model.contact_zone"), std::string::npos) << message;
  }
}

TEST(ScenePlanner, DomainCutAroundTheNeedleKeepsTheAxisymmetricForceWithinTheTolerance) {
  InsertionRunOptions full = fast();
  full.allow_reductions = false;
  const InsertionRun a = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, fast());
  const InsertionRun b = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, full);
  const Reduction* cut = find_reduction(a, "domain_cut");
  ASSERT_NE(cut, nullptr);
  ASSERT_TRUE(cut->measured_effect.has_value());
  const double fa = a.needles[0].curve.back().force_N;
  const double fb = b.needles[0].curve.back().force_N;
  EXPECT_LT(std::abs(fa - fb) / fb, 0.05) << fa << " vs " << fb;  // fast tolerance 5 %
  EXPECT_NEAR(*cut->measured_effect, std::abs(fa - fb) / fb, 1e-9);
  EXPECT_EQ(find_reduction(b, "domain_cut"), nullptr);
}

TEST(ScenePlanner, DomainCutOfThe3dBlockIsMeasuredAndUndoneAboveTheTolerance) {
  InsertionRunOptions cut3d = fast();
  cut3d.model = PreModel::Full3d;
  InsertionRunOptions strict = cut3d;
  strict.reduction_tolerance = 1e-12;
  const InsertionRun a = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, cut3d);
  const InsertionRun b = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, strict);
  const Reduction* cut = find_reduction(a, "domain_cut");
  ASSERT_NE(cut, nullptr);
  ASSERT_TRUE(cut->measured_effect.has_value());
  EXPECT_LT(*cut->measured_effect, 0.05);
  const Reduction* undone = find_reduction(b, "domain_cut_rejected");
  ASSERT_NE(undone, nullptr);
  EXPECT_GT(b.elements, a.elements);  // the full 12 mm block was meshed
  // The grid is marched out from the needle, so the two meshes agree near it and the forces
  // differ by the truncation: measured +0.82 % (fast), +0.83 % (standard).
  const double fa = a.needles[0].curve.back().force_N;
  const double fb = b.needles[0].curve.back().force_N;
  EXPECT_LT(std::abs(fa - fb) / fb, 0.02) << fa << " vs " << fb;
}

// The 3-D model's cut is decided before its run, at the rung's horizon (docs/model.md, "Scene
// planner"): a rejected cut costs no second 3-D solve, and the rung's mesh does not depend on
// how deep the run was asked to go. A punch 30 or 50 um into the 12 mm block: both requests are
// on the first rung (100 um), so the cut's measured effect is the same number, and the strict
// tolerance's full-block run factorises as often as the cut run.
TEST(ScenePlanner, DomainCutOfThe3dBlockIsDecidedAtTheRungsHorizonBeforeThe3dRun) {
  InsertionRunOptions cut3d = fast();
  cut3d.model = PreModel::Full3d;
  InsertionRunOptions strict = cut3d;
  strict.reduction_tolerance = 1e-12;
  const Scene shallow = parse_scene(scene_text("", "", kOnePunch, "[\"puncture\", \"force_curve\"]",
                                               "[\"12 mm\", \"12 mm\", \"1150 um\"]", "30 um"),
                                    "wide_30um.toml");
  const InsertionRun a = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, cut3d);
  const InsertionRun b = run_insertion(shallow, {punch("punch", 115e-6)}, cut3d);
  const InsertionRun c = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, strict);
  const Reduction* cut_a = find_reduction(a, "domain_cut");
  const Reduction* cut_b = find_reduction(b, "domain_cut");
  ASSERT_NE(cut_a, nullptr);
  ASSERT_NE(cut_b, nullptr);
  ASSERT_TRUE(cut_a->measured_effect && cut_b->measured_effect);
  EXPECT_EQ(*cut_a->measured_effect, *cut_b->measured_effect);
  EXPECT_EQ(a.nodes, b.nodes);
  ASSERT_NE(find_reduction(c, "domain_cut_rejected"), nullptr);
  EXPECT_GT(c.nodes, a.nodes);
  EXPECT_EQ(c.seconds_by_stage.factorizations, a.seconds_by_stage.factorizations);
}

TEST(ScenePlanner, DomainCutOfATet4BlockIsMeasuredByTheAxisymmetricProxyInItsOwnElements) {
  // Linear tetrahedra asked of the 3-D model: the axisymmetric proxy that measures the cut has
  // 6-node triangles only and must not be asked for order 1 (it threw, ending the run).
  InsertionRunOptions tet4 = fast();
  tet4.model = PreModel::Full3d;
  tet4.overrides.order = 1;
  const InsertionRun a = run_insertion(wide_block_scene(), {punch("punch", 115e-6)}, tet4);
  const Reduction* cut = find_reduction(a, "domain_cut");
  ASSERT_NE(cut, nullptr);
  ASSERT_TRUE(cut->measured_effect.has_value());
  EXPECT_LT(*cut->measured_effect, 0.05);  // the same truncation as with TET10 (above)
  EXPECT_FALSE(a.needles[0].curve.empty());
}

TEST(ScenePlanner, HalfModelOfABevelMatchesTheFullModel) {
  PreparedNeedle bevel;
  bevel.name = "bevel";
  bevel.mesh = test::bevel_needle(115e-6, M_PI / 6, 1e-3);
  bevel.mirror_symmetric_y0 = true;
  const Scene scene = parse_scene(scene_text("", "", kOnePunch, "[\"puncture\", \"force_curve\"]",
                                             "[\"1500 um\", \"1500 um\", \"600 um\"]", "100 um"),
                                  "bevel.toml");
  InsertionRunOptions full = fast();
  full.allow_reductions = false;
  const InsertionRun half = run_insertion(scene, {bevel}, fast());
  const InsertionRun whole = run_insertion(scene, {bevel}, full);
  EXPECT_EQ(half.reductions.back().name, "half_model");
  EXPECT_LT(half.elements, whole.elements);
  const RunPoint& a = half.needles.front().curve.back();
  const RunPoint& b = whole.needles.front().curve.back();
  ASSERT_GT(b.force_N, 0.0);
  // Exact by symmetry up to round-off: forces, lateral force along the bevel, contact area.
  EXPECT_NEAR(a.force_N, b.force_N, 1e-9 * b.force_N);
  EXPECT_NEAR(a.lateral_force_N[0], b.lateral_force_N[0], 1e-9 * b.force_N);
  EXPECT_NEAR(a.contact_area_m2, b.contact_area_m2, 1e-9 * b.contact_area_m2);
}

// [model] mesh_refinement reaches the 3-D mesh through run_insertion (so every command); an
// explicit override in the options wins over it.
TEST(ScenePlanner, SceneMeshRefinementReachesThe3dMeshAndAnOverrideWins) {
  PreparedNeedle bevel;
  bevel.name = "bevel";
  bevel.mesh = test::bevel_needle(115e-6, M_PI / 6, 1e-3);
  bevel.mirror_symmetric_y0 = true;
  const std::string text = scene_text("", "", kOnePunch, "[\"puncture\", \"force_curve\"]",
                                      "[\"1500 um\", \"1500 um\", \"600 um\"]", "100 um");
  const Scene plain = parse_scene(text, "bevel.toml");
  const Scene refined = parse_scene(text + "mesh_refinement = 2\n", "bevel.toml");
  ASSERT_EQ(refined.model.mesh_refinement, 2);
  const InsertionRun a = run_insertion(plain, {bevel}, fast());
  const InsertionRun b = run_insertion(refined, {bevel}, fast());
  InsertionRunOptions grid = fast();
  grid.overrides.refinement_levels = 0;
  const InsertionRun c = run_insertion(refined, {bevel}, grid);
  EXPECT_NE(a.nodes, b.nodes);  // fast's default is the plain grid (0)
  EXPECT_EQ(c.nodes, a.nodes);
  ASSERT_GT(b.needles.front().curve.back().force_N, 0.0);
}

// [model] crack_faces reaches the energy criterion's cracked twin: held faces keep apart (the
// linear path's round-off), free ones pass through each other under the punch (docs/model.md,
// "Crack faces in contact") and release more energy.
TEST(ScenePlanner, SceneCrackFacesReachTheCrackedTwin) {
  const std::string text = scene_text("", kFracture, kOnePunch, "[\"puncture\", \"force_curve\"]",
                                      "[\"3000 um\", \"3000 um\", \"1150 um\"]", "100 um") +
                           "criterion = \"energy\"\n";
  const Scene held = parse_scene(text, "punch.toml");
  const Scene free = parse_scene(text + "crack_faces = \"free\"\n", "punch.toml");
  InsertionRunOptions energy = fast();  // the commands take the criterion from the scene
  energy.criterion = PunctureCriterion::Energy;
  const RunPoint a = run_insertion(held, {punch("punch", 115e-6)}, energy).needles[0].curve.back();
  const RunPoint b = run_insertion(free, {punch("punch", 115e-6)}, energy).needles[0].curve.back();
  ASSERT_EQ(a.depth_m, b.depth_m);
  EXPECT_LE(a.crack_face_overlap_m,
            1e-13);  // as RingCrackFacesUnderAPunchDoNotPassThroughEachOther
  EXPECT_GT(b.crack_face_overlap_m, 1e-6);
  EXPECT_GT(b.energy_release_rate_J_per_m2, a.energy_release_rate_J_per_m2);
}

// The domain cut of a 3-D run is measured on the needle's body of revolution; for a bevel in
// neo-Hookean silicone that proxy's Newton stalls (docs/validation.md, "Is the linear tissue why
// our forces are ≈ 3× below paper A's?"). The run must not end there: the cut is left unmeasured
// and undone, and the 3-D model, which does solve, runs on the full block. Should that proxy ever
// solve, this test fails on the first assertion and needs another proxy that does not.
TEST(ScenePlanner, DomainCutWhoseProxyCannotBeSolvedIsUndoneInsteadOfEndingTheRun) {
  PreparedNeedle bevel;
  bevel.name = "bevel";
  bevel.mesh = test::bevel_needle(115e-6, M_PI / 6, 2.5e-3);
  bevel.mirror_symmetric_y0 = true;
  const Scene scene = parse_scene(
      "[tissue]\nsize = [\"6 mm\", \"6 mm\", \"2 mm\"]\n[[tissue.layers]]\n"
      "name = \"silicone\"\nmaterial = { model = \"neo_hookean\", E = \"0.2 MPa\", nu = 0.49 }\n" +
          kOnePunch +
          "[insertion]\ndepth = \"30 um\"\n[model]\nfidelity = \"fast\"\n"
          "outputs = [\"puncture\", \"force_curve\"]\n",
      "neo_hookean_bevel.toml");
  // At the default tolerance (1e-5) the proxy's stall was a knife edge: 1.4e-5 on one machine,
  // converged on another (a fresh Debian 12 install, 2026-12-04), so the test asks 1e-7. The
  // proxy then stalls at its first steps (relative residual 3.3e-5 at 1.05 um, 330 x the
  // tolerance) while the 3-D model's Newton, quadratic to round-off, still solves.
  InsertionRunOptions options = fast();
  options.overrides.tolerance = 1e-7;
  const InsertionRun run = run_insertion(scene, {bevel}, options);
  const Reduction* undone = find_reduction(run, "domain_cut_rejected");
  ASSERT_NE(undone, nullptr);
  EXPECT_NE(undone->detail.find("could not be measured"), std::string::npos) << undone->detail;
  EXPECT_FALSE(undone->measured_effect.has_value());
  EXPECT_EQ(find_reduction(run, "domain_cut"), nullptr);
  // The full 6 mm block ran to the requested depth.
  ASSERT_FALSE(run.needles[0].curve.empty());
  EXPECT_NEAR(run.needles[0].curve.back().depth_m, 30e-6, 1e-12);
  EXPECT_GT(run.needles[0].curve.back().force_N, 0.0);
}

std::string two_by_two_punches() {
  std::string text;
  const char* names[] = {"a", "b", "c", "d"};
  const char* at[] = {"[\"-250 um\", \"-250 um\"]", "[\"250 um\", \"-250 um\"]",
                      "[\"-250 um\", \"250 um\"]", "[\"250 um\", \"250 um\"]"};
  for (int k = 0; k < 4; ++k)
    text += std::string("[[needles]]\nname = \"") + names[k] +
            "\"\ngeometry = { plugin = \"cylinder\", diameter = \"150 um\" }\nat = " + at[k] + "\n";
  return text;
}

std::vector<PreparedNeedle> two_by_two(double x0 = 0.0) {
  return {punch("a", 75e-6, x0 - 250e-6, -250e-6), punch("b", 75e-6, x0 + 250e-6, -250e-6),
          punch("c", 75e-6, x0 - 250e-6, 250e-6), punch("d", 75e-6, x0 + 250e-6, 250e-6)};
}

TEST(ScenePlanner, QuarterModelOfATwoByTwoArrayMatchesTheFullModel) {
  const Scene scene = parse_scene(scene_text("", kFracture, two_by_two_punches(), "[\"puncture\"]",
                                             "[\"1500 um\", \"1500 um\", \"600 um\"]", "60 um"),
                                  "array.toml");
  InsertionRunOptions full = fast();
  full.allow_reductions = false;
  const InsertionRun quarter = run_insertion(scene, two_by_two(), fast());
  const InsertionRun whole = run_insertion(scene, two_by_two(), full);
  ASSERT_NE(find_reduction(quarter, "quarter_model"), nullptr);
  EXPECT_LT(4 * quarter.elements, whole.elements + whole.elements / 10);
  ASSERT_EQ(quarter.needles.size(), 4U);
  for (std::size_t n = 0; n < 4; ++n) {
    const RunPoint& a = quarter.needles[n].curve.back();
    const RunPoint& b = whole.needles[n].curve.back();
    ASSERT_GT(b.force_N, 0.0);
    EXPECT_NEAR(a.force_N, b.force_N, 1e-6 * b.force_N) << n;
    EXPECT_NEAR(a.lateral_force_N[0], b.lateral_force_N[0], 1e-6 * b.force_N) << n;
    EXPECT_NEAR(a.lateral_force_N[1], b.lateral_force_N[1], 1e-6 * b.force_N) << n;
  }
  EXPECT_NEAR(quarter.total_curve.back().force_N, whole.total_curve.back().force_N,
              1e-6 * whole.total_curve.back().force_N);
}

TEST(ScenePlanner, ArrayOffTheCentreOrWithOddNeedlesKeepsTheFullModel) {
  const Scene scene = parse_scene(scene_text("", kFracture, two_by_two_punches(), "[\"puncture\"]",
                                             "[\"1500 um\", \"1500 um\", \"600 um\"]", "20 um"),
                                  "array.toml");
  const InsertionRun shifted = run_insertion(scene, two_by_two(10e-6), fast());
  EXPECT_NE(find_reduction(shifted, "half_model"), nullptr);  // still symmetric about y = 0
  EXPECT_EQ(find_reduction(shifted, "quarter_model"), nullptr);
  std::vector<PreparedNeedle> odd = two_by_two();
  odd[0] = punch("a", 60e-6, -250e-6, -250e-6);  // a differs from its images
  const InsertionRun mixed = run_insertion(scene, odd, fast());
  EXPECT_EQ(find_reduction(mixed, "half_model"), nullptr);
  EXPECT_EQ(find_reduction(mixed, "quarter_model"), nullptr);
}

TEST(ScenePlanner, AxisymmetricModelAgreesWithThe3dBlockWithinTheFastTolerance) {
  const Scene scene = punch_scene("");
  InsertionRunOptions three_d = fast();
  three_d.model = PreModel::Full3d;
  const InsertionRun axi = run_insertion(scene, {punch("punch", 115e-6)}, fast());
  const InsertionRun block = run_insertion(scene, {punch("punch", 115e-6)}, three_d);
  EXPECT_TRUE(axi.axisymmetric);
  EXPECT_FALSE(block.axisymmetric);
  // Cylinder of equal cross-section area against the square block, each at fast fidelity:
  // measured 4.3 % apart at 50 um (3.4 % at the former standard level), within the 5 % fast
  // tolerance.
  for (std::size_t i = 0; i < axi.needles[0].curve.size(); ++i) {
    const double fa = axi.needles[0].curve[i].force_N;
    const double fb = block.needles[0].curve[i].force_N;
    EXPECT_NEAR(axi.needles[0].curve[i].depth_m, block.needles[0].curve[i].depth_m, 1e-12);
    EXPECT_LT(std::abs(fa - fb) / fb, 0.05) << "at " << axi.needles[0].curve[i].depth_m;
  }
}

TEST(Arrays, EachNeedlePuncturesOnItsOwnAndTheTotalIsTheirSum) {
  const std::string needles =
      "[[needles]]\nname = \"left\"\ngeometry = { plugin = \"cylinder\", diameter = \"230 um\" }\n"
      "at = [\"-300 um\", \"0 um\"]\n"
      "[[needles]]\nname = \"right\"\ngeometry = { plugin = \"cylinder\", diameter = \"150 um\" }\n"
      "at = [\"300 um\", \"0 um\"]\n";
  const Scene scene = parse_scene(scene_text("",
                                             "[tissue.fracture]\ntoughness = \"19 J/m^2\"\n"
                                             "critical_pressure = \"0.15 MPa\"\n",
                                             needles, "[\"puncture\", \"force_curve\"]",
                                             "[\"1800 um\", \"1200 um\", \"600 um\"]", "150 um"),
                                  "array.toml");
  const InsertionRun run =
      run_insertion(scene, {punch("left", 115e-6, -300e-6), punch("right", 75e-6, 300e-6)}, fast());
  EXPECT_EQ(run.models_run.front(), "fe_3d");
  ASSERT_EQ(run.needles.size(), 2u);
  ASSERT_TRUE(run.needles[0].puncture && run.needles[1].puncture);
  // The smaller punch has the higher pressure at a given depth (P ~ d / a): it punctures first.
  EXPECT_LT(run.needles[1].puncture->depth_m, run.needles[0].puncture->depth_m);
  int compared = 0;
  for (const RunPoint& t : run.total_curve) {
    double sum = 0.0, sections = 0.0;
    std::size_t found = 0;
    for (const NeedleRun& n : run.needles) {
      int here = 0;
      for (const RunPoint& p : n.curve)
        if (p.depth_m == t.depth_m && here++ == 0) sum += p.force_N, sections += p.section_area_m2;
      found += here == 1 ? 1 : 0;  // a puncture depth (two points) is checked by the curve tests
    }
    if (found != run.needles.size()) continue;
    EXPECT_NEAR(t.force_N, sum, 1e-12 + 1e-9 * sum) << "at " << t.depth_m;
    // The sections add up too (the total's were 0); before any puncture the total's section
    // pressure is the total force over them.
    EXPECT_NEAR(t.section_area_m2, sections, 1e-9 * sections) << "at " << t.depth_m;
    if (t.stage == Stage::Pre && t.depth_m < run.needles[1].puncture->depth_m) {
      EXPECT_NEAR(t.section_pressure_Pa, sum / sections, 1e-9 * sum / sections) << t.depth_m;
    }
    ++compared;
  }
  EXPECT_GE(compared, 3);
}

// A sharp 15-degree cone on paper A's skin with a finite-strain stratum corneum (its strength
// raised so that the criterion never fires) stops on an inverted element under its point
// between 30 and 40 um at fast (docs/validation.md, "Finite strain in a stiff top layer"): the
// run throws unless keep_reached asks for what it reached, and what it keeps is what a run asked
// for exactly that depth gives, step for step.
TEST(InsertionRun, AnFeRunThatStopsKeepsWhatItReachedOnlyWhenAsked) {
  std::string layers = kPaperASkinLayers;
  const std::string linear = "model = \"linear\", E = \"1 GPa\"";
  layers.replace(layers.find(linear), linear.size(), "model = \"svk\", E = \"1 GPa\"");
  layers.replace(layers.find("21.6 MPa"), 8, "10 GPa");
  const auto text = [&](const std::string& depth) {
    return "[tissue]\nsize = [\"3000 um\", \"3000 um\", \"1150 um\"]\n" + layers +
           "[[needles]]\nname = \"cone\"\ngeometry = { plugin = \"cone\", diameter = \"230 um\" "
           "}\n[insertion]\ndepth = \"" +
           depth +
           "\"\n[model]\nfidelity = \"fast\"\ncriterion = \"stress\"\n"
           "outputs = [\"puncture\", \"force_curve\"]\n";
  };
  const double half_angle = 15.0 * std::numbers::pi / 180.0;
  PreparedNeedle cone;
  cone.name = "cone";
  cone.mesh = test::cone_needle(half_angle, 115e-6, 1e-3, 64);
  cone.axisymmetric = fe::AxisymmetricNeedle::cone(half_angle, 115e-6);
  cone.mirror_symmetric_y0 = cone.mirror_symmetric_x0 = true;
  InsertionRunOptions options = fast();
  options.criterion = PunctureCriterion::Stress;
  const Scene deep = parse_scene(text("800 um"), "skin.toml");
  try {
    run_insertion(deep, {cone}, options);
    FAIL() << "expected the run to stop";
  } catch (const OutOfMemoryError&) {
    FAIL() << "not a memory stop";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("inverted element"), std::string::npos) << e.what();
  }
  options.keep_reached = true;
  const InsertionRun stopped = run_insertion(deep, {cone}, options);
  ASSERT_TRUE(stopped.stopped.has_value());
  EXPECT_NEAR(stopped.stopped->depth_m, 30e-6, 1e-12);  // fast: 10 um steps on the 100 um rung
  EXPECT_NE(stopped.stopped->reason.find("inverted element"), std::string::npos);
  const NeedleRun& reached = stopped.needles.front();
  EXPECT_FALSE(reached.puncture.has_value());
  ASSERT_EQ(reached.curve.size(), 3u);  // 10, 20, 30 um, the last once
  EXPECT_NEAR(reached.curve.back().depth_m, 30e-6, 1e-12);

  // The same needle and tissue asked for 30 um: a finished run with the same steps.
  const InsertionRun asked =
      run_insertion(parse_scene(text("30 um"), "skin.toml"), {cone}, options);
  ASSERT_FALSE(asked.stopped.has_value());
  EXPECT_EQ(stopped.nodes, asked.nodes);  // the mesh it stopped on is the one it ran on
  EXPECT_EQ(stopped.elements, asked.elements);
  const NeedleRun& full = asked.needles.front();
  ASSERT_EQ(full.curve.size(), reached.curve.size());
  // Equal to round-off: the asked run cuts its last step (3 x 10 um = 30.000000000000004 um) at
  // the 30 um it was asked for, 4e-21 m away, by linear interpolation.
  for (std::size_t i = 0; i < full.curve.size(); ++i) {
    const RunPoint &a = full.curve[i], &b = reached.curve[i];
    EXPECT_NEAR(a.depth_m, b.depth_m, 1e-15) << i;
    EXPECT_NEAR(a.force_N, b.force_N, 1e-12 * b.force_N) << i;
    EXPECT_NEAR(a.tip_stress_Pa, b.tip_stress_Pa, 1e-12 * b.tip_stress_Pa) << i;
  }
}

TEST(InsertionRun, MoreNeedlesThanTheFiniteElementLimitIsRefusedBeforeAnyWork) {
  InsertionRunOptions o = fast();
  o.max_fe_needles = 3;
  const Scene scene = parse_scene(
      scene_text("", kFracture, two_by_two_punches(), "[\"puncture\", \"force_curve\"]"),
      "array.toml");
  try {
    run_insertion(scene, two_by_two(), o);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("4 needles in one finite element model, above the limit "
                                         "of 3 (raise it with --max-needles"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mneedle
