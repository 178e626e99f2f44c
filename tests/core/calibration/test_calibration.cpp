// Calibration of a scene's tissue constants against a measured curve: constants recovered from
// curves the model itself made (with noise), the refusals, and the held-out comparison.

#include "mneedle/calibration/calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <string>

#include "fe/needle_meshes.h"
#include "mneedle/base/error.h"
#include "mneedle/insertion/surface_loads.h"
#include "needle_shapes.h"

namespace mneedle {
namespace {

constexpr double kPi = 3.14159265358979323846;

Scene silicone_scene(const std::string& fracture = "",
                     const std::string& outputs = "[\"force_curve\"]") {
  const std::string text =
      "[tissue]\nsize = [\"3000 um\", \"3000 um\", \"3000 um\"]\n"
      "[[tissue.layers]]\nname = \"silicone\"\n"
      "material = { model = \"linear\", E = \"0.2 MPa\", nu = 0.45 }\n" +
      fracture +
      "[[needles]]\nname = \"n\"\ngeometry = { plugin = \"cylinder\", diameter = \"230 um\" }\n"
      "[insertion]\ndepth = \"2 mm\"\n[model]\nfidelity = \"fast\"\noutputs = " +
      outputs + "\n";
  return parse_scene(text, "calibrate.toml");
}

PreparedNeedle bevel_needle() {
  PreparedNeedle n;
  n.name = "n";
  test::ShapeOptions o;
  o.length = 2.5e-3;
  n.mesh = test::sharp_bevel(o, kPi / 6.0);
  return n;
}

PreparedNeedle punch_needle() {
  PreparedNeedle n;
  n.name = "n";
  n.mesh = test::cylinder_needle(115e-6, 2.5e-3);
  n.axisymmetric = fe::AxisymmetricNeedle::flat_punch(115e-6);
  n.mirror_symmetric_y0 = true;
  n.mirror_symmetric_x0 = true;
  return n;
}

// 1 % Gaussian noise on each force (fixed seed: the test is deterministic).
ForceCurve noisy(const std::vector<double>& depth, const std::vector<double>& force) {
  ForceCurve c;
  c.source = "synthetic.csv";
  std::mt19937 random(17u);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    c.depth_m.push_back(depth[i]);
    c.force_N.push_back(force[i] * (1.0 + 0.01 * unit(random)));
    c.line.push_back(i + 2);
  }
  return c;
}

TEST(Calibration, RecoversScaleAndFrictionFromANoisyModelCurveWithinTwoStandardErrors) {
  const Scene scene = silicone_scene();
  const PreparedNeedle needle = bevel_needle();
  LoadConstants truth = load_constants(scene);
  const double q0 = layer_pressures(truth)[0].pressure_scale_Pa;
  truth.layers[0].pressure_scale_Pa = 2.5 * q0;
  truth.layers[0].pressure_scale_source = "truth";
  truth.friction_coefficient = 0.35;
  const SurfaceLoadModel model(needle.mesh, truth);
  std::vector<double> depth, force;
  for (int i = 0; i <= 100; ++i) {
    depth.push_back(0.1e-3 + 1.9e-3 * i / 100.0);
    force.push_back(model.at(depth.back()).force_N);
  }
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale, CalibratedConstant::friction_coefficient};
  options.contact_travel_m = 0.0;
  options.puncture_travel_m = 0.1e-3;
  const Calibration c = calibrate(scene, needle, noisy(depth, force), options);
  ASSERT_EQ(c.parameters.size(), 2u);
  EXPECT_TRUE(c.converged);
  EXPECT_LT(std::abs(c.parameters[0].value - 2.5), 2.0 * c.parameters[0].standard_error);
  EXPECT_LT(std::abs(c.parameters[1].value - 0.35), 2.0 * c.parameters[1].standard_error);
  // The errors are those of a 1 % noise: small, not zero.
  EXPECT_GT(c.parameters[0].standard_error, 0.0);
  EXPECT_LT(c.parameters[0].standard_error, 0.05 * 2.5);
  EXPECT_NEAR(c.layer_pressure_scale_Pa[0], c.parameters[0].value * q0, 1e-9 * q0);
  EXPECT_GT(c.fit.r2, 0.99);
}

// A fine recording is thinned evenly to max_samples (each costs the post-puncture loads per
// evaluation: 10^5 samples took minutes an iteration): 101 samples at most 25 keep every 5th,
// 21, and the constants come back as from the whole curve (a noise-free curve of the model).
TEST(Calibration, AFineRecordingIsThinnedEvenlyAndGivesTheSameConstants) {
  const Scene scene = silicone_scene();
  const PreparedNeedle needle = bevel_needle();
  LoadConstants truth = load_constants(scene);
  truth.layers[0].pressure_scale_Pa = 2.5 * layer_pressures(truth)[0].pressure_scale_Pa;
  truth.layers[0].pressure_scale_source = "truth";
  const SurfaceLoadModel model(needle.mesh, truth);
  ForceCurve curve;
  curve.source = "fine.csv";
  for (int i = 0; i <= 100; ++i) {
    curve.depth_m.push_back(0.1e-3 + 1.9e-3 * i / 100.0);
    curve.force_N.push_back(model.at(curve.depth_m.back()).force_N);
    curve.line.push_back(i + 2);
  }
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale};
  options.contact_travel_m = 0.0;
  options.puncture_travel_m = 0.1e-3;
  options.max_samples = 25;
  const Calibration c = calibrate(scene, needle, curve, options);
  EXPECT_EQ(c.fit.samples, 21u);
  // The optimiser's tolerance (1e-4 relative), as on the whole curve.
  EXPECT_NEAR(c.parameters[0].value, 2.5, 1e-4 * 2.5);
}

std::string fracture_with(const std::string& critical_pressure) {
  return "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"" + critical_pressure +
         "\"\n";
}

// The silicone scene with a flat punch as its needle, 0.6 mm deep at fast, the given P_c, the
// layer's E times `modulus` and q = `q_factor` times the q the unscaled E derives (given), or
// without a q (derived from the scaled E) when `q_factor` is empty.
Scene punch_scene(const std::string& critical_pressure, double modulus,
                  std::optional<double> q_factor) {
  Scene scene = silicone_scene(fracture_with(critical_pressure), "[\"puncture\", \"force_curve\"]");
  const double q0 = layer_pressures(load_constants(scene))[0].pressure_scale_Pa;
  scene.tissue.layers[0].material.youngs_modulus *= modulus;
  if (q_factor) {
    scene.tissue.layers[0].pressure_scale = *q_factor * q0;
    scene.tissue.layers[0].pressure_scale_source = "test";
  }
  scene.insertion.depth = 0.6e-3;
  return scene;
}

InsertionRunOptions fast_run() {
  InsertionRunOptions run;
  run.fidelity = fe::Fidelity::Fast;
  return run;
}

// A fitted constant within two of its own standard errors of the value the curve was made with.
void expect_within_two_errors(const CalibratedParameter& p, double truth) {
  EXPECT_LT(std::abs(p.value - truth), 2.0 * p.standard_error)
      << to_string(p.constant) << " " << p.value << " +- " << p.standard_error << ", made with "
      << truth;
}

// The two-stage curve run_insertion makes for `truth` (axisymmetric FE until P = F / A_sec
// reaches P_c, surface loads after), one sample per depth.
struct MadeCurve {
  std::vector<double> depth, force;
  double puncture_depth_m = 0.0;
};
MadeCurve made_curve(const Scene& truth) {
  const InsertionRun made_run = run_insertion(truth, {punch_needle()}, fast_run());
  const NeedleRun& n = made_run.needles.front();
  MadeCurve out;
  if (n.puncture) out.puncture_depth_m = n.puncture->depth_m;
  for (const RunPoint& p : n.curve) {
    if (p.depth_m <= 0.0 || (!out.depth.empty() && p.depth_m <= out.depth.back())) continue;
    out.depth.push_back(p.depth_m);
    out.force.push_back(p.force_N);
  }
  return out;
}

// The curve is made with P_c = 0.3 MPa and q three times the derived one; calibrate starts from
// P_c = 0.6 MPa and the derived q.
TEST(Calibration, RecoversTheCriticalPressureAndScaleOfATwoStageCurve) {
  const MadeCurve made = made_curve(punch_scene("0.3 MPa", 1.0, 3.0));
  ASSERT_GT(made.puncture_depth_m, 0.0);
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale, CalibratedConstant::critical_pressure};
  options.contact_travel_m = 0.0;
  options.run = fast_run();
  const Calibration c = calibrate(punch_scene("0.6 MPa", 1.0, std::nullopt), punch_needle(),
                                  noisy(made.depth, made.force), options);
  ASSERT_EQ(c.parameters.size(), 2u);
  ASSERT_TRUE(c.critical_pressure_Pa.has_value());
  expect_within_two_errors(c.parameters[0], 3.0);
  EXPECT_DOUBLE_EQ(c.parameters[1].value, *c.critical_pressure_Pa);
  expect_within_two_errors(c.parameters[1], 0.3e6);
  ASSERT_TRUE(c.puncture_depth_m.has_value());
}

// The tissue of the made curve is 2.5 times stiffer than the scene's: the forces before the
// puncture, and the pressure that fires it, are 2.5 times the scene's at every depth (linear
// tissue, sticking contact: the captured nodes do not depend on the modulus). With the scene's
// own P_c the puncture moves with the fitted modulus; calibrate settles both and the scale. The
// scene's q is derived from its E, so it follows the modulus: the made q, 3 q0, is 1.2 times
// the 2.5 q0 the fitted E derives, and the scale's error carries the modulus's.
TEST(Calibration, RecoversTheModulusAndScaleOfATwoStageCurveWithTheScenesCriticalPressure) {
  const MadeCurve made = made_curve(punch_scene("0.3 MPa", 2.5, 3.0));
  ASSERT_GT(made.puncture_depth_m, 0.0);
  CalibrationOptions options;
  options.fit = {CalibratedConstant::modulus, CalibratedConstant::scale};
  options.contact_travel_m = 0.0;
  options.run = fast_run();
  const Calibration c = calibrate(punch_scene("0.3 MPa", 1.0, std::nullopt), punch_needle(),
                                  noisy(made.depth, made.force), options);
  ASSERT_EQ(c.parameters.size(), 2u);
  expect_within_two_errors(c.parameters[0], 2.5);
  EXPECT_GT(c.parameters[0].standard_error, 0.0);
  expect_within_two_errors(c.parameters[1], 1.2);
  EXPECT_LT(c.correlation[0][1], 0.0);
  const double q0 = layer_pressures(load_constants(punch_scene("0.3 MPa", 1.0, std::nullopt)))[0]
                        .pressure_scale_Pa;
  EXPECT_NEAR(c.layer_pressure_scale_Pa[0], c.parameters[0].value * c.parameters[1].value * q0,
              1e-9 * q0);
  EXPECT_DOUBLE_EQ(c.modulus_factor, c.parameters[0].value);
  EXPECT_NEAR(c.layer_youngs_modulus_Pa[0], c.parameters[0].value * 0.2e6, 1e-6);
  // The puncture is where the made curve's was, within what the modulus's error moves it: a
  // flat punch's section pressure grows in proportion to the depth, so d_p goes as 1 / k.
  ASSERT_TRUE(c.puncture_depth_m.has_value());
  const double relative = c.parameters[0].standard_error / c.parameters[0].value;
  EXPECT_NEAR(*c.puncture_depth_m, made.puncture_depth_m, 2.0 * relative * made.puncture_depth_m);
}

// Fitting P_c too, each candidate puncture (a gap between samples) gets the modulus of the
// samples before it and the P_c that modulus gives the criterion there.
TEST(Calibration, RecoversTheModulusAndTheCriticalPressureOfATwoStageCurveTogether) {
  const MadeCurve made = made_curve(punch_scene("0.3 MPa", 2.5, 3.0));
  CalibrationOptions options;
  options.fit = {CalibratedConstant::modulus, CalibratedConstant::critical_pressure,
                 CalibratedConstant::scale};
  options.contact_travel_m = 0.0;
  options.run = fast_run();
  const Calibration c = calibrate(punch_scene("0.6 MPa", 1.0, 1.0), punch_needle(),
                                  noisy(made.depth, made.force), options);
  ASSERT_EQ(c.parameters.size(), 3u);
  ASSERT_TRUE(c.critical_pressure_Pa.has_value());
  expect_within_two_errors(c.parameters[0], 2.5);
  EXPECT_DOUBLE_EQ(c.parameters[1].value, *c.critical_pressure_Pa);
  expect_within_two_errors(c.parameters[1], 0.3e6);
  expect_within_two_errors(c.parameters[2], 3.0);
}

// Without noise the fitted factor is the made one to round-off: the pre-puncture force scales
// with the modulus exactly (the property the closed-form fit rests on). Measured 1.5e-14
// relative (linear tissue, one direct solve per step); 1e-12 leaves room for the summation
// order of another BLAS, not for a modulus-dependent result.
TEST(Calibration, ANoiseFreeCurveGivesTheModulusItWasMadeWithToRoundOff) {
  const MadeCurve made = made_curve(punch_scene("0.3 MPa", 2.5, 1.0));
  ForceCurve curve;
  curve.source = "made.csv";
  for (std::size_t i = 0; i < made.depth.size(); ++i) {
    curve.depth_m.push_back(made.depth[i]);
    curve.force_N.push_back(made.force[i]);
    curve.line.push_back(i + 2);
  }
  CalibrationOptions options;
  options.fit = {CalibratedConstant::modulus};
  options.contact_travel_m = 0.0;
  options.puncture_travel_m = made.puncture_depth_m;
  options.run = fast_run();
  const Calibration c = calibrate(punch_scene("0.3 MPa", 1.0, 1.0), punch_needle(), curve, options);
  ASSERT_EQ(c.parameters.size(), 1u);
  EXPECT_NEAR(c.parameters[0].value, 2.5, 1e-12 * 2.5) << c.parameters[0].value - 2.5;
  EXPECT_LT(c.parameters[0].standard_error, 1e-12 * 2.5) << c.parameters[0].standard_error;
}

TEST(Calibration, AModulusWithFewerThanTwoSamplesBeforeTheGivenPunctureIsRefused) {
  CalibrationOptions options;
  options.fit = {CalibratedConstant::modulus};
  options.contact_travel_m = 0.0;
  options.puncture_travel_m = 0.15e-3;
  options.run = fast_run();
  const ForceCurve curve = noisy({1e-4, 2e-4, 3e-4, 4e-4}, {1e-3, 2e-3, 3e-3, 4e-3});
  try {
    calibrate(punch_scene("0.3 MPa", 1.0, 1.0), punch_needle(), curve, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("synthetic.csv: 1 fitted samples before the puncture"),
              std::string::npos)
        << e.what();
  }
}

TEST(Calibration, OneCurveCannotFixBothCriticalPressureAndToughness) {
  CalibrationOptions options;
  options.fit = {CalibratedConstant::critical_pressure, CalibratedConstant::toughness};
  options.contact_travel_m = 0.0;
  const ForceCurve curve = noisy({1e-4, 2e-4, 3e-4, 4e-4}, {1e-3, 2e-3, 3e-3, 4e-3});
  try {
    calibrate(silicone_scene(), bevel_needle(), curve, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not both"), std::string::npos) << e.what();
  }
}

TEST(Calibration, PenetrationCriterionWithoutAGivenPunctureIsRefused) {
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale};
  options.contact_travel_m = 0.0;
  options.run.criterion = PunctureCriterion::Penetration;
  const ForceCurve curve = noisy({1e-4, 2e-4, 3e-4, 4e-4}, {1e-3, 2e-3, 3e-3, 4e-3});
  try {
    calibrate(silicone_scene(), bevel_needle(), curve, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("penetration criterion is not supported"),
              std::string::npos)
        << e.what();
  }
}

// Its crack softens the force before the puncture: the criterion-free run calibrate fits on is
// not the run that punctures.
TEST(Calibration, CohesiveCriterionIsRefused) {
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale};
  options.contact_travel_m = 0.0;
  options.run.criterion = PunctureCriterion::Cohesive;
  const ForceCurve curve = noisy({1e-4, 2e-4, 3e-4, 4e-4}, {1e-3, 2e-3, 3e-3, 4e-3});
  try {
    calibrate(silicone_scene(), bevel_needle(), curve, options);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cohesive criterion is not supported"), std::string::npos)
        << e.what();
  }
}

TEST(Calibration, FrictionCoefficientWithoutCoulombFrictionIsRefused) {
  Scene scene = silicone_scene();
  scene.loads.friction = FrictionLaw::None;
  CalibrationOptions options;
  options.fit = {CalibratedConstant::friction_coefficient};
  options.contact_travel_m = 0.0;
  options.puncture_travel_m = 0.0;
  const ForceCurve curve = noisy({1e-4, 2e-4, 3e-4, 4e-4}, {1e-3, 2e-3, 3e-3, 4e-3});
  EXPECT_THROW(calibrate(scene, bevel_needle(), curve, options), InputError);
}

TEST(Calibration, HeldOutSamplesAreReportedBesideAStraightLine) {
  const Scene scene = silicone_scene();
  const PreparedNeedle needle = bevel_needle();
  const SurfaceLoadModel model(needle.mesh, load_constants(scene));
  std::vector<double> depth, force;
  for (int i = 0; i <= 60; ++i) {
    depth.push_back(0.05e-3 + 1.95e-3 * i / 60.0);
    force.push_back(model.at(depth.back()).force_N);
  }
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale};
  options.contact_travel_m = 0.0;
  options.puncture_travel_m = 0.05e-3;
  options.fit_to_travel_m = 1.2e-3;
  const Calibration c = calibrate(scene, needle, noisy(depth, force), options);
  ASSERT_TRUE(c.held_out.has_value());
  ASSERT_TRUE(c.straight_line_held_out.has_value());
  EXPECT_EQ(c.fit.samples + c.held_out->samples, depth.size());
  // The model made the curve: its held-out error is the noise, far below a line's.
  EXPECT_LT(c.held_out->rmse_N, 0.5 * c.straight_line_held_out->rmse_N);
}

}  // namespace
}  // namespace mneedle
