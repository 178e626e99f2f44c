// Puncture criteria: thresholds read from the scene, and the crossing located between depth
// steps (interpolation, bisection) so that the puncture depth varies continuously.

#include "mneedle/insertion/puncture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

Scene scene_with(const std::string& layer_extra, const std::string& tissue_extra) {
  return parse_scene(R"(
[tissue]
size = ["1 mm", "1 mm", "1 mm"]
[[tissue.layers]]
name = "top"
thickness = "0.2 mm"
material = { model = "linear", E = "1 MPa", nu = 0.4 }
)" + layer_extra + R"(
[[tissue.layers]]
name = "bottom"
material = { model = "linear", E = "0.1 MPa", nu = 0.4 }
)" + tissue_extra + R"(
[[needles]]
name = "n"
geometry = { plugin = "cylinder", diameter = "100 um" }
[insertion]
depth = "0.1 mm"
)",
                     "test.toml");
}

TEST(PunctureThreshold, ReadsEachCriterionFromTheTopLayer) {
  const Scene s = scene_with("strength = \"2 MPa\"\nstrength_length = \"15 um\"\n",
                             "[tissue.fracture]\ntoughness = \"19 J/m^2\"\n"
                             "critical_pressure = \"0.663 MPa\"\n");
  EXPECT_TRUE(has_puncture_data(s));
  EXPECT_DOUBLE_EQ(puncture_threshold(s, PunctureCriterion::Pressure).threshold, 0.663e6);
  EXPECT_DOUBLE_EQ(puncture_threshold(s, PunctureCriterion::Energy).threshold, 19.0);
  const PunctureThreshold stress = puncture_threshold(s, PunctureCriterion::Stress);
  EXPECT_DOUBLE_EQ(stress.threshold, 2e6);
  EXPECT_DOUBLE_EQ(stress.average_length_m, 15e-6);
  // The penetration criterion compares F with F_p: dimensionless, fires at 1.
  EXPECT_DOUBLE_EQ(puncture_threshold(s, PunctureCriterion::Penetration).threshold, 1.0);
}

TEST(PunctureThreshold, PenetrationNeedsToughnessAndANonNegativePoissonRatio) {
  // Only a strength on the top layer: no fracture data, so no toughness.
  const Scene without = scene_with("strength = \"2 MPa\"\nstrength_length = \"15 um\"\n", "");
  try {
    puncture_threshold(without, PunctureCriterion::Penetration);
    FAIL() << "no toughness must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("toughness: missing (the penetration criterion"),
              std::string::npos)
        << e.what();
  }
  Scene auxetic = scene_with("",
                             "[tissue.fracture]\ntoughness = \"19 J/m^2\"\n"
                             "critical_pressure = \"0.663 MPa\"\n");
  auxetic.tissue.layers.front().material.poisson_ratio = -0.2;
  try {
    puncture_threshold(auxetic, PunctureCriterion::Penetration);
    FAIL() << "nu < 0 must be refused";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test.toml:"), std::string::npos) << m;
    EXPECT_NE(m.find("material.nu"), std::string::npos) << m;
  }
}

TEST(PunctureThreshold, MissingValueNamesFileLineLayerAndKey) {
  const Scene s = scene_with("", "");
  EXPECT_FALSE(has_puncture_data(s));
  try {
    puncture_threshold(s, PunctureCriterion::Stress);
    FAIL() << "no strength on the top layer must be refused";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test.toml:"), std::string::npos) << m;
    EXPECT_NE(m.find("tissue.layers[0] 'top'"), std::string::npos) << m;
    EXPECT_NE(m.find("strength: missing"), std::string::npos) << m;
  }
  EXPECT_THROW(puncture_threshold(s, PunctureCriterion::Pressure), InputError);
}

TEST(FirstCrossing, InterpolatesLinearlyBetweenTheBracketingSteps) {
  const auto c = first_crossing({1e-6, 2e-6, 3e-6}, {1.0, 3.0, 5.0}, 4.0);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->depth_m, 2.5e-6, 1e-15);
  EXPECT_EQ(c->step, 2u);
  EXPECT_NEAR(c->fraction, 0.5, 1e-12);
}

TEST(FirstCrossing, StartsFromZeroBeforeTheFirstStep) {
  const auto c = first_crossing({10e-6, 20e-6}, {8.0, 9.0}, 2.0);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->depth_m, 2.5e-6, 1e-15);
  EXPECT_EQ(c->step, 0u);
}

TEST(FirstCrossing, TakesTheFirstOfSeveralCrossings) {
  const auto c = first_crossing({1.0, 2.0, 3.0, 4.0}, {0.0, 2.0, 0.5, 3.0}, 1.0);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->depth_m, 1.5, 1e-12);
}

TEST(FirstCrossing, NeverReachedIsEmpty) {
  EXPECT_FALSE(first_crossing({1.0, 2.0}, {0.1, 0.2}, 1.0).has_value());
  EXPECT_FALSE(first_crossing({}, {}, 1.0).has_value());
}

TEST(FirstCrossing, BisectsWhenTheCriterionCanBeReEvaluated) {
  // v = d^2 is far from linear between the steps: interpolation gives 1.5 for threshold 2,
  // bisection the exact sqrt(2).
  const std::vector<double> d{1.0, 2.0}, v{1.0, 4.0};
  const auto linear = first_crossing(d, v, 2.0);
  ASSERT_TRUE(linear.has_value());
  EXPECT_NEAR(linear->depth_m, 1.0 + 1.0 / 3.0, 1e-12);
  const auto bisected = first_crossing(
      d, v, 2.0, [](double x) { return x * x; }, 1e-10);
  ASSERT_TRUE(bisected.has_value());
  EXPECT_NEAR(bisected->depth_m, std::sqrt(2.0), 1e-9);
}

TEST(FirstCrossing, DepthMovesContinuouslyWithTheValues) {
  // A design change that scales the criterion by (1 + e) moves the crossing by O(e): no jump
  // to the next step, which the optimiser would see as a discontinuity.
  const std::vector<double> d{1.0, 2.0, 3.0};
  double previous = first_crossing(d, {1.0, 2.0, 3.0}, 2.5)->depth_m;
  for (int k = 1; k <= 50; ++k) {
    const double s = 1.0 + 0.002 * k;
    const double now = first_crossing(d, {s, 2.0 * s, 3.0 * s}, 2.5)->depth_m;
    EXPECT_LT(now, previous);
    EXPECT_LT(previous - now, 0.01);
    previous = now;
  }
}

TEST(FirstCrossing, RefusesBadSequences) {
  EXPECT_THROW(first_crossing({1.0, 2.0}, {1.0}, 1.0), InputError);
  EXPECT_THROW(first_crossing({2.0, 1.0}, {1.0, 2.0}, 1.0), InputError);
  EXPECT_THROW(first_crossing({1.0}, {NAN}, 1.0), InputError);
  EXPECT_THROW(first_crossing({1.0}, {1.0}, 0.0), InputError);
}

TEST(InterpolateAt, IsLinearBetweenStepsZeroBeforeAndHeldAfter) {
  const std::vector<double> d{1.0, 3.0}, v{2.0, 6.0};
  EXPECT_DOUBLE_EQ(interpolate_at(d, v, 0.5), 1.0);
  EXPECT_DOUBLE_EQ(interpolate_at(d, v, 2.0), 4.0);
  EXPECT_DOUBLE_EQ(interpolate_at(d, v, 5.0), 6.0);
}

TEST(CriterionValue, PicksTheCriterionsQuantity) {
  CriterionSample s;
  s.contact_pressure_Pa = 1.0;
  s.tip_stress_Pa = 2.0;
  s.energy_release_rate_J_per_m2 = 3.0;
  s.penetration_ratio = 4.0;
  s.force_N = 5.0;
  EXPECT_EQ(criterion_value(PunctureCriterion::Penetration, s), 4.0);
  EXPECT_EQ(criterion_value(PunctureCriterion::Cohesive, s), 0.0);  // it reads the force's peak
  EXPECT_EQ(criterion_value(PunctureCriterion::Pressure, s), 1.0);
  EXPECT_EQ(criterion_value(PunctureCriterion::Stress, s), 2.0);
  EXPECT_EQ(criterion_value(PunctureCriterion::Energy, s), 3.0);
}

// A force sampled from a parabola F = 5 - (d - 3.3)^2 peaks where the parabola does: the vertex
// of the three steps around the highest is exact (to round-off) wherever the peak lies between
// the steps, and so moves continuously with it.
TEST(ForcePeak, TheVertexOfASampledParabolaIsItsPeak) {
  for (double peak : {2.6, 3.0, 3.3, 3.9}) {
    std::vector<double> d, f;
    for (int k = 1; k <= 6; ++k) {
      d.push_back(k);
      f.push_back(5.0 - (k - peak) * (k - peak));
    }
    double force = 0.0;
    const auto c = force_peak(d, f, &force);
    ASSERT_TRUE(c) << peak;
    EXPECT_NEAR(c->depth_m, peak, 1e-12) << peak;
    EXPECT_NEAR(force, 5.0, 1e-12) << peak;
    EXPECT_LT(d[c->step] - 1.0, peak);  // the step's interval holds the peak
    EXPECT_GE(d[c->step], peak);
  }
}

TEST(ForcePeak, AForceThatNeverFallsHasNoPeakAndRoundOffIsNoFall) {
  EXPECT_FALSE(force_peak({1.0, 2.0, 3.0}, {1.0, 2.0, 2.5}));
  // A plateau's round-off (1e-12 of the force) is not a drop; 1e-6 is.
  EXPECT_FALSE(force_peak({1.0, 2.0, 3.0}, {1.0, 2.0, 2.0 * (1.0 - 1e-12)}));
  EXPECT_EQ(force_drop_step({1.0, 2.0, 2.0 * (1.0 - 1e-6)}), std::optional<std::size_t>(2));
  EXPECT_THROW(force_peak({1.0, 2.0}, {1.0}), InputError);
}

TEST(ForcePeak, APeakInTheFirstStepIsPlacedWithTheOrigin) {
  // F = 4 d - 2 d^2 peaks at d = 1 (2), sampled at 1.5 and 3: through (0, 0) the vertex is exact.
  double force = 0.0;
  const auto c = force_peak({1.5, 3.0}, {4 * 1.5 - 2 * 2.25, 4 * 3.0 - 2 * 9.0}, &force);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->depth_m, 1.0, 1e-12);
  EXPECT_NEAR(force, 2.0, 1e-12);
  EXPECT_EQ(c->step, 0u);
}

// G is a secant over its crack, so the crack must not follow the mesh: paper A's 115 um needle
// gets the same 230 um crack at the TET10 tip sizes of fast, standard and fine (2R/2.5, 2R/3.5,
// 2R/5.5); only a tip element over a radius (a user's override) deepens it.
TEST(CrackDepth, IsTheNeedleDiameterButAtLeastTwoTipElements) {
  const double R = 115e-6;
  for (double spacings : {2.5, 3.5, 5.5})
    EXPECT_DOUBLE_EQ(crack_depth_for(R, 2 * R / spacings), 2 * R) << spacings;
  EXPECT_DOUBLE_EQ(crack_depth_for(10e-6, 20e-6), 40e-6);
}

}  // namespace
}  // namespace mneedle
