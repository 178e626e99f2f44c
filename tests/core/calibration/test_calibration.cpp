// Calibration of a scene's tissue constants against a measured curve: constants recovered from
// curves the model itself made (with noise), the refusals, and the held-out comparison.

#include "mneedle/calibration/calibration.h"

#include <gtest/gtest.h>

#include <cmath>
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

// The two-stage curve of a flat punch (axisymmetric FE until P = F / A_sec reaches P_c, surface
// loads after) is made by run_insertion with P_c = 0.3 MPa and q three times the derived one;
// calibrate starts from P_c = 0.6 MPa and the derived q.
TEST(Calibration, RecoversTheCriticalPressureAndScaleOfATwoStageCurve) {
  const std::string made =
      "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"0.3 MPa\"\n";
  Scene truth_scene = silicone_scene(made, "[\"puncture\", \"force_curve\"]");
  const double q0 = layer_pressures(load_constants(truth_scene))[0].pressure_scale_Pa;
  truth_scene.tissue.layers[0].pressure_scale = 3.0 * q0;
  truth_scene.tissue.layers[0].pressure_scale_source = "truth";
  truth_scene.insertion.depth = 0.6e-3;
  InsertionRunOptions run;
  run.fidelity = fe::Fidelity::Fast;
  const InsertionRun made_run = run_insertion(truth_scene, {punch_needle()}, run);
  const NeedleRun& n = made_run.needles.front();
  ASSERT_TRUE(n.puncture.has_value());
  std::vector<double> depth, force;
  for (const RunPoint& p : n.curve) {
    if (p.depth_m <= 0.0 || (!depth.empty() && p.depth_m <= depth.back())) continue;
    depth.push_back(p.depth_m);
    force.push_back(p.force_N);
  }
  const std::string start =
      "[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"0.6 MPa\"\n";
  Scene scene = silicone_scene(start, "[\"puncture\", \"force_curve\"]");
  scene.insertion.depth = 0.6e-3;
  CalibrationOptions options;
  options.fit = {CalibratedConstant::scale, CalibratedConstant::critical_pressure};
  options.contact_travel_m = 0.0;
  options.run = run;
  const Calibration c = calibrate(scene, punch_needle(), noisy(depth, force), options);
  ASSERT_EQ(c.parameters.size(), 2u);
  ASSERT_TRUE(c.critical_pressure_Pa.has_value());
  EXPECT_LT(std::abs(c.parameters[0].value - 3.0), 2.0 * c.parameters[0].standard_error)
      << "scale " << c.parameters[0].value << " +- " << c.parameters[0].standard_error;
  EXPECT_LT(std::abs(*c.critical_pressure_Pa - 0.3e6), 2.0 * c.parameters[1].standard_error)
      << "P_c " << *c.critical_pressure_Pa << " +- " << c.parameters[1].standard_error;
  ASSERT_TRUE(c.puncture_depth_m.has_value());
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
