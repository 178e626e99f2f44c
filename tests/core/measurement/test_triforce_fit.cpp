#include "mneedle/measurement/triforce_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include "mneedle/base/error.h"
#include "mneedle/measurement/force_curve.h"
#include "refdata.h"

namespace {

constexpr double kPerpendicular = std::numbers::pi / 2.0;

mneedle::TriforceParams truth() {
  mneedle::TriforceParams p;
  p.layers[0] = {0.0, 1.5, 400.0, 0.8, 0.6, 5e4};
  return p;
}

// A loading branch of the true model seen through a contact offset and Gaussian noise.
mneedle::FitCurve synthetic(const mneedle::TriforceParams& p, double angle, double offset,
                            double noise, unsigned seed) {
  const mneedle::TriforceModel model(p);
  mneedle::FitCurve c;
  c.name = "synthetic-" + std::to_string(seed);
  c.conditions = {1e-3, angle};
  std::mt19937 random(seed);
  std::normal_distribution<double> gauss(0.0, noise);
  for (int i = 0; i <= 300; ++i) {
    const double d = 20e-3 * i / 300.0;
    c.depth_m.push_back(d);
    c.force_N.push_back(model.loading(d - offset, c.conditions).total_N() + gauss(random));
  }
  return c;
}

double fitted(const mneedle::TriforceFit& fit, const std::string& name, double* stderr_out) {
  for (const auto& p : fit.parameters) {
    if (p.name == name) {
      *stderr_out = p.standard_error;
      return p.value;
    }
  }
  ADD_FAILURE() << "no parameter " << name;
  return 0.0;
}

TEST(TriforceFit, RecoversKnownParametersWithinTheirStandardErrors) {
  const auto p = truth();
  const std::vector<mneedle::FitCurve> curves{synthetic(p, kPerpendicular, 0.4e-3, 0.03, 1),
                                              synthetic(p, 1.0, -0.2e-3, 0.03, 2)};
  const auto fit = mneedle::fit_triforce(curves, {});
  EXPECT_TRUE(fit.converged);
  EXPECT_NEAR(fit.residual_sd_N, 0.03, 0.005);
  for (const auto& [name, value] : mneedle::named_parameters(p)) {
    double se = 0.0;
    const double v = fitted(fit, name, &se);
    if (name == "mu" || name == "radius_m" || name == "ref_length_m" || name == "eta_Ns" ||
        name == "lambda_s") {
      EXPECT_EQ(v, value) << name << " is fixed by default";
      continue;
    }
    ASSERT_TRUE(std::isfinite(se)) << name;
    EXPECT_GT(se, 0.0) << name;
    EXPECT_NEAR(v, value, 4.0 * se) << name << " se " << se;
  }
  EXPECT_NEAR(fit.curves[0].offset_m, 0.4e-3, 4.0 * fit.curves[0].offset_standard_error_m);
  EXPECT_NEAR(fit.curves[1].offset_m, -0.2e-3, 4.0 * fit.curves[1].offset_standard_error_m);
  for (const auto& c : fit.curves) {
    EXPECT_GT(c.metrics.r2, 0.99);
    EXPECT_NEAR(c.metrics.rmse_N, 0.03, 0.006);
    EXPECT_LT(c.metrics.max_error_N, 0.15);
  }
}

TEST(TriforceFit, FixedParameterKeepsItsValueAndIsNotFitted) {
  const auto p = truth();
  mneedle::TriforceFitOptions options;
  options.fixed["kc_per_m"] = 400.0;
  options.starts = 3;
  const auto fit = mneedle::fit_triforce({synthetic(p, kPerpendicular, 0.0, 0.02, 3)}, options);
  double se = -1.0;
  EXPECT_EQ(fitted(fit, "kc_per_m", &se), 400.0);
  EXPECT_EQ(se, 0.0);
  for (const auto& q : fit.parameters) {
    if (q.name == "kc_per_m") {
      EXPECT_FALSE(q.fitted);
    }
    if (q.name == "K0_N") {
      EXPECT_TRUE(q.fitted);
    }
  }
}

TEST(TriforceFit, UnknownParameterNameIsAnInputError) {
  mneedle::TriforceFitOptions options;
  options.fixed["stiffness"] = 1.0;
  EXPECT_THROW(mneedle::fit_triforce({synthetic(truth(), kPerpendicular, 0.0, 0.02, 4)}, options),
               mneedle::InputError);
}

TEST(TriforceFit, TooFewSamplesForTheParametersIsAnInputError) {
  auto c = synthetic(truth(), kPerpendicular, 0.0, 0.02, 5);
  c.depth_m.resize(4);
  c.force_N.resize(4);
  EXPECT_THROW(mneedle::fit_triforce({c}, {}), mneedle::InputError);
}

TEST(TriforceFit, PredictionAtAnotherSpeedUsesTheMaxwellBranch) {
  auto p = truth();
  p.viscosity_Ns = 3.0;
  p.relaxation_time_s = 0.8;
  auto slow = synthetic(p, kPerpendicular, 0.0, 0.0, 6);
  auto fast = slow;
  fast.conditions.speed_m_per_s = 2e-3;
  const mneedle::TriforceModel model(p);
  const auto f_slow = mneedle::predict_loading(model, slow, 0.0);
  const auto f_fast = mneedle::predict_loading(model, fast, 0.0);
  // eta v / L (1 - exp(-z / (v lambda))) at z = 20 mm for both speeds.
  const double expected =
      3.0 * 2e-3 / 10e-3 * -std::expm1(-10.0 / 0.8) - 3.0 * 1e-3 / 10e-3 * -std::expm1(-20.0 / 0.8);
  EXPECT_NEAR(f_fast.back() - f_slow.back(), expected, 1e-12);
}

TEST(TriforceFit, RealPhantomCurveFitsWithPositiveR2) {
  const auto file = mneedle::test::refdata_dir() / "phantom_insertions" /
                    "skin-on-muscle_1_0_3_2_2024-06-19-11-43-49.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto branch = mneedle::extract_loading_branch(mneedle::read_force_curve_csv(file));
  mneedle::FitCurve c{file.filename().string(),
                      branch.curve.depth_m,
                      branch.curve.force_N,
                      {mneedle::loading_speed(branch), kPerpendicular}};
  mneedle::TriforceFitOptions options;
  options.starts = 4;
  const auto fit = mneedle::fit_triforce({c}, options);
  // The smooth model cannot follow the puncture drop: a good but not perfect fit.
  EXPECT_GT(fit.curves[0].metrics.r2, 0.8);
  EXPECT_LT(fit.curves[0].metrics.rmse_N, 0.6);
}

}  // namespace
