#include "mneedle/measurement/triforce_model.h"

#include <gtest/gtest.h>
#include <boost/math/quadrature/gauss_kronrod.hpp>

#include <cmath>
#include <numbers>

#include "mneedle/base/error.h"

namespace {

constexpr double kPerpendicular = std::numbers::pi / 2.0;

mneedle::TriforceParams liver_like() {
  mneedle::TriforceParams p;
  p.layers[0] = {0.0, 1.5, 400.0, 0.8, 0.6, 5e4};
  return p;
}

mneedle::TriforceParams two_layers() {
  auto p = liver_like();
  p.layers.push_back({8e-3, 0.5, 900.0, 2.0, -0.3, 1.2e5});
  return p;
}

// F_f(z) = integral_0^z mu c F_s(xi) 2 pi r dxi by adaptive quadrature of the model's own F_s.
double friction_by_quadrature(const mneedle::TriforceModel& m, double z, double angle) {
  const auto& p = m.params();
  const auto stiffness_times_c = [&](double xi) {
    const auto& layers = p.layers;
    std::size_t j = 0;
    while (j + 1 < layers.size() && xi >= layers[j + 1].start_m) ++j;
    return layers[j].normal_stress_per_m2 * m.quasi_static(xi, angle).stiffness_N;
  };
  double total = 0.0, a = 0.0;
  for (const auto& layer : p.layers) {
    if (layer.start_m > a && layer.start_m < z) {
      total += boost::math::quadrature::gauss_kronrod<double, 61>::integrate(
          stiffness_times_c, a, layer.start_m, 15, 1e-12);
      a = layer.start_m;
    }
  }
  total += boost::math::quadrature::gauss_kronrod<double, 61>::integrate(stiffness_times_c, a, z,
                                                                         15, 1e-12);
  return 2.0 * std::numbers::pi * p.needle_radius_m * p.friction_coefficient * total;
}

TEST(TriforceModel, CuttingSaturatesAtItsMaximum) {
  const mneedle::TriforceModel m(liver_like());
  EXPECT_NEAR(m.quasi_static(1e-3, kPerpendicular).cutting_N, 1.5 * (1.0 - std::exp(-0.4)), 1e-12);
  EXPECT_NEAR(m.quasi_static(0.1, kPerpendicular).cutting_N, 1.5, 1e-9);
}

TEST(TriforceModel, StiffnessIsExponentialInStrainFromDepthAndAngle) {
  const mneedle::TriforceModel m(liver_like());
  const double angle = std::numbers::pi / 6.0;  // 30 deg to the surface
  const double eps = 12e-3 * 0.5 / 10e-3;
  EXPECT_NEAR(mneedle::effective_strain(12e-3, angle, 10e-3), eps, 1e-15);
  EXPECT_NEAR(m.quasi_static(12e-3, angle).stiffness_N, 0.8 * eps * std::exp(0.6 * eps), 1e-12);
  EXPECT_GT(m.quasi_static(12e-3, kPerpendicular).stiffness_N,
            m.quasi_static(12e-3, angle).stiffness_N);
}

TEST(TriforceModel, FrictionClosedFormMatchesQuadrature) {
  const mneedle::TriforceModel m(liver_like());
  for (double z : {0.5e-3, 5e-3, 20e-3}) {
    for (double angle : {kPerpendicular, 0.4}) {
      EXPECT_NEAR(m.quasi_static(z, angle).friction_N, friction_by_quadrature(m, z, angle), 1e-10)
          << "z " << z << " angle " << angle;
    }
  }
}

TEST(TriforceModel, FrictionClosedFormHoldsWithoutStiffening) {
  auto p = liver_like();
  p.layers[0].stiffening = 0.0;
  const mneedle::TriforceModel m(p);
  // beta = 0: F_f = 2 pi r mu c K0 a z^2 / 2 with a = 1/L.
  const double expected =
      2.0 * std::numbers::pi * 0.6e-3 * 0.2 * 5e4 * 0.8 * 100.0 * 0.01 * 0.01 / 2.0;
  EXPECT_NEAR(m.quasi_static(0.01, kPerpendicular).friction_N, expected, 1e-12);
}

TEST(TriforceModel, LayeredFrictionMatchesQuadratureAndForceIsContinuous) {
  const mneedle::TriforceModel m(two_layers());
  for (double z : {4e-3, 8e-3, 15e-3}) {
    EXPECT_NEAR(m.quasi_static(z, kPerpendicular).friction_N,
                friction_by_quadrature(m, z, kPerpendicular), 1e-9)
        << z;
  }
  const double below = m.quasi_static(8e-3 - 1e-9, kPerpendicular).total_N();
  const double above = m.quasi_static(8e-3 + 1e-9, kPerpendicular).total_N();
  EXPECT_NEAR(below, above, 1e-6);
}

TEST(TriforceModel, LayerBoundaryChangesTheSlope) {
  const mneedle::TriforceModel m(two_layers());
  const auto slope = [&](double z) {
    return (m.quasi_static(z + 1e-5, kPerpendicular).stiffness_N -
            m.quasi_static(z - 1e-5, kPerpendicular).stiffness_N) /
           2e-5;
  };
  EXPECT_GT(std::abs(slope(8.1e-3) - slope(7.9e-3)), 0.3 * slope(7.9e-3));
}

TEST(TriforceModel, MaxwellBranchMakesFasterInsertionStiffer) {
  auto p = liver_like();
  p.viscosity_Ns = 2.0;
  p.relaxation_time_s = 0.5;
  const mneedle::TriforceModel m(p);
  mneedle::InsertionConditions slow{1e-3, kPerpendicular}, fast{2e-3, kPerpendicular};
  const auto f_slow = m.loading(10e-3, slow);
  const auto f_fast = m.loading(10e-3, fast);
  // eta eps_dot (1 - exp(-t / lambda)), t = z / v.
  EXPECT_NEAR(f_slow.viscous_N, 2.0 * 1e-3 / 10e-3 * (1.0 - std::exp(-10.0 / 0.5)), 1e-12);
  EXPECT_NEAR(f_fast.viscous_N, 2.0 * 2e-3 / 10e-3 * (1.0 - std::exp(-5.0 / 0.5)), 1e-12);
  EXPECT_GT(f_fast.total_N(), f_slow.total_N());
}

TEST(TriforceModel, ProtocolAboveTheSampleLimitIsRefusedBeforeAnyWork) {
  // --hold 1e9s once ran into bad_alloc; paper C's 86 mm at 1 mm/s (17 200 samples) stays in.
  const mneedle::TriforceModel m(liver_like());
  mneedle::InsertionProtocol protocol;
  protocol.conditions = {1e-3, kPerpendicular};
  protocol.max_depth_m = 86e-3;
  protocol.time_step_s = 0.01;
  EXPECT_NO_THROW(m.simulate(protocol));
  protocol.hold_s = 1e9;
  try {
    m.simulate(protocol);
    FAIL() << "expected an InputError";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "is 1e+11 samples, above the limit of 1000000 (raise it with --max-samples)"),
              std::string::npos)
        << e.what();
  }
}

TEST(TriforceModel, HoldRelaxesAndRetractionReversesFriction) {
  auto p = liver_like();
  p.viscosity_Ns = 5.0;
  p.relaxation_time_s = 1.0;
  const mneedle::TriforceModel m(p);
  mneedle::InsertionProtocol protocol;
  protocol.conditions = {1e-3, kPerpendicular};
  protocol.max_depth_m = 10e-3;
  protocol.hold_s = 5.0;
  protocol.time_step_s = 0.05;
  const auto samples = m.simulate(protocol);
  double end_of_insertion = 0.0, end_of_hold = 0.0;
  for (const auto& s : samples) {
    if (s.phase == mneedle::InsertionPhase::Insertion) end_of_insertion = s.force.total_N();
    if (s.phase == mneedle::InsertionPhase::Hold) end_of_hold = s.force.total_N();
  }
  EXPECT_NEAR(end_of_insertion - end_of_hold, 5.0 * 0.1 * (1.0 - std::exp(-5.0)), 1e-3);
  const auto& first_back = *std::find_if(samples.begin(), samples.end(), [](const auto& s) {
    return s.phase == mneedle::InsertionPhase::Retraction;
  });
  EXPECT_LT(first_back.force.friction_N, 0.0);
  EXPECT_EQ(first_back.force.cutting_N, 0.0);
  EXPECT_NEAR(samples.back().depth_m, 0.0, 1e-15);
  EXPECT_NEAR(samples.back().time_s, 10.0 + 5.0 + 10.0, 1e-6);
}

TEST(TriforceModel, VibrationMeanFactorMatchesAveragingTheInstantaneousFactor) {
  const double v = 1e-3, A = 5e-6, f = 1000.0;
  const auto inst = [&](double t) { return mneedle::perturbation_friction_factor(v, A, f, t); };
  const double mean =
      boost::math::quadrature::gauss_kronrod<double, 61>::integrate(inst, 0.0, 1.0 / f, 15, 1e-12) *
      f;
  EXPECT_NEAR(mneedle::mean_perturbation_friction_factor(v, A, f), mean, 1e-9);
  EXPECT_LT(mean, 0.2);  // 2 pi f A = 31 mm/s >> 1 mm/s: friction nearly vanishes axially
  EXPECT_EQ(mneedle::mean_perturbation_friction_factor(v, 0.0, f), 1.0);
}

TEST(TriforceModel, LargerVibrationLowersTheInsertionForce) {
  const mneedle::TriforceModel m(liver_like());
  mneedle::InsertionConditions c{1e-3, kPerpendicular, 0.0, 1000.0};
  const double still = m.loading(15e-3, c).total_N();
  c.perturbation_amplitude_m = 1e-7;
  const double small = m.loading(15e-3, c).total_N();
  c.perturbation_amplitude_m = 1e-5;
  const double large = m.loading(15e-3, c).total_N();
  EXPECT_LT(small, still);
  EXPECT_LT(large, small);
}

TEST(TriforceModel, NamedParametersRoundTripIncludingLayers) {
  auto p = two_layers();
  const auto names = mneedle::named_parameters(p);
  mneedle::TriforceParams q;
  for (const auto& [name, value] : names) mneedle::set_parameter(q, name, value);
  ASSERT_EQ(q.layers.size(), 2u);
  EXPECT_EQ(q.layers[1].start_m, 8e-3);
  EXPECT_EQ(mneedle::get_parameter(q, "K0_N_L2"), 2.0);
  EXPECT_EQ(mneedle::get_parameter(q, "mu"), 0.2);
  EXPECT_THROW(mneedle::get_parameter(q, "kappa"), mneedle::InputError);
}

TEST(TriforceModel, InvalidParametersAreRejectedWithTheirName) {
  auto p = liver_like();
  p.layers[0].cut_max_N = -1.0;
  try {
    mneedle::TriforceModel m(p);
    FAIL() << "negative cutting force accepted";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Fc_max_N"), std::string::npos) << e.what();
  }
}

}  // namespace
