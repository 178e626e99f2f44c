#include "mneedle/measurement/energy_balance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/measurement/toughness.h"
#include "refdata.h"

namespace {

using mneedle::ForceCurve;
using mneedle::InputError;

// A made-up through insertion whose energies are known exactly: straight pieces between corners
// that lie on the 0.1 mm sampling grid (paper C sampled every 0.1 mm), so the trapezoidal rule is
// exact. A rises to 0.30 N at 10 mm; B relaxes to 0.15 N at 11 mm; C cuts up to 1.30 N at 96 mm
// (86 mm, one block depth, after the puncture); D falls to the sliding force in two samples;
// E slides at 0.90 N to 130 mm.
struct Corner {
  double x_mm, f_N;
};
ForceCurve piecewise(const std::vector<Corner>& corners, double end_mm) {
  ForceCurve c;
  c.source = "made-up.csv";
  const int n = static_cast<int>(std::lround(end_mm / 0.1));
  for (int i = 0; i <= n; ++i) {
    const double x = i * 0.1;
    std::size_t k = 1;
    while (k + 1 < corners.size() && x > corners[k].x_mm + 1e-9) ++k;
    const double t = (x - corners[k - 1].x_mm) / (corners[k].x_mm - corners[k - 1].x_mm);
    c.depth_m.push_back(x * 1e-3);
    c.force_N.push_back(corners[k - 1].f_N +
                        std::clamp(t, 0.0, 1.0) * (corners[k].f_N - corners[k - 1].f_N));
    c.line.push_back(static_cast<std::size_t>(i) + 2);
  }
  return c;
}

ForceCurve through_insertion(double sliding_N = 0.90) {
  return piecewise({{0, 0},
                    {10, 0.30},
                    {11, 0.15},
                    {96, 1.30},
                    {96.1, 1.10},
                    {96.2, sliding_N},
                    {130, sliding_N}},
                   130);
}

constexpr double kDepth = 0.086;     // paper C's block
constexpr double kWidth = 0.015;     // its mean crack width
constexpr double kStrain = 73.2e-3;  // its U_eps, J/m

std::string message_of(auto&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SplitStages, FindsTheFiveStagesOfAThroughInsertionAtTheirCorners) {
  const auto s = mneedle::split_stages(through_insertion());
  EXPECT_EQ(s.puncture_index, 100u);
  EXPECT_EQ(s.relaxed_index, 110u);
  EXPECT_EQ(s.peak_index, 960u);
  ASSERT_TRUE(s.through);
  EXPECT_EQ(s.sliding_index, 962u);
  EXPECT_EQ(s.sliding_samples, 1301u - 962u);
  EXPECT_NEAR(s.sliding_force_N, 0.90, 1e-12);
}

TEST(SplitStages, StageWorksAreTheAreasUnderTheStraightPieces) {
  const auto s = mneedle::split_stages(through_insertion());
  // Exact areas of the pieces (J); the tolerance is round-off of ~1300 sums.
  EXPECT_NEAR(s.stage_work_J[0], 0.5 * 0.30 * 0.010, 1e-12);
  EXPECT_NEAR(s.stage_work_J[1], 0.5 * (0.30 + 0.15) * 0.001, 1e-12);
  EXPECT_NEAR(s.stage_work_J[2], 0.5 * (0.15 + 1.30) * 0.085, 1e-12);
  EXPECT_NEAR(s.stage_work_J[3], 0.5 * (1.30 + 1.10) * 1e-4 + 0.5 * (1.10 + 0.90) * 1e-4, 1e-12);
  EXPECT_NEAR(s.stage_work_J[4], 0.90 * 0.0338, 1e-12);
}

TEST(SplitStages, ARecordThatEndsWhileCuttingHasNoExitOrSliding) {
  const auto c = piecewise({{0, 0}, {10, 0.30}, {11, 0.15}, {50, 0.80}}, 50);
  const auto s = mneedle::split_stages(c);
  EXPECT_FALSE(s.through);
  EXPECT_EQ(s.peak_index, c.force_N.size() - 1);
  EXPECT_EQ(s.stage_work_J[3], 0.0);
  EXPECT_EQ(s.stage_work_J[4], 0.0);
}

TEST(SplitStages, ADipBelowTheExitThresholdIsNotAnExit) {
  // 1.30 N falling to 1.10 N is a 15 % dip, below the 20 % that marks the tip leaving the block.
  const auto c =
      piecewise({{0, 0}, {10, 0.30}, {11, 0.15}, {96, 1.30}, {97, 1.10}, {110, 1.10}}, 110);
  EXPECT_FALSE(mneedle::split_stages(c).through);
}

TEST(SplitStages, ACurveWithoutAPunctureDropIsRefusedSayingHowFarItFell) {
  const auto c = piecewise({{0, 0}, {10, 0.30}, {11, 0.29}, {50, 0.80}}, 50);
  const std::string m = message_of([&] { mneedle::split_stages(c); });
  EXPECT_NE(m.find("made-up.csv: no puncture"), std::string::npos) << m;
  EXPECT_NE(m.find("at most 3.3"), std::string::npos) << m;
}

TEST(SplitStages, ASmallEarlyDipIsNotThePuncture) {
  // 0.50 -> 0.42 N is 16 % of its peak but 3 % of the record's 2.6 N: a layer giving way under a
  // fraction of the load; the puncture is the 2.6 -> 1.2 N drop.
  const auto c = piecewise({{0, 0}, {3, 0.50}, {3.2, 0.42}, {12, 2.6}, {12.2, 1.2}, {30, 2.4}}, 30);
  const auto s = mneedle::split_stages(c);
  EXPECT_EQ(s.puncture_index, 120u);
  EXPECT_EQ(s.relaxed_index, 122u);
}

TEST(SplitStages, AForceThatClimbsAgainAfterADropIsNotSliding) {
  // A second puncture (2.6 -> 1.2 N) followed by more cutting back up to 2.4 N: the spread after
  // the drop is half the peak, far from a flat sliding force.
  const auto c = piecewise({{0, 0}, {3, 0.50}, {3.2, 0.30}, {12, 2.6}, {12.2, 1.2}, {30, 2.4}}, 30);
  mneedle::StageOptions o;
  o.min_drop_of_max_fraction = 0.0;  // let the early dip be the puncture
  const auto s = mneedle::split_stages(c, o);
  EXPECT_EQ(s.puncture_index, 30u);
  EXPECT_EQ(s.peak_index, 120u);
  EXPECT_FALSE(s.through);
}

TEST(SplitStages, ADropWithinTheNoiseIsNotAPuncture) {
  const auto c = piecewise({{0, 0}, {10, 0.30}, {11, 0.15}, {50, 0.80}}, 50);
  mneedle::StageOptions o;
  o.noise_N = 0.04;  // 5 deviations = 0.2 N > the 0.15 N drop
  EXPECT_THROW(mneedle::split_stages(c, o), InputError);
}

TEST(EnergyBalance, MadeUpRecordGivesItsKnownEnergiesAndToughness) {
  const auto c = through_insertion();
  const auto s = mneedle::split_stages(c);
  const auto e = mneedle::energy_balance(c, s, {kDepth, kWidth, kStrain, std::nullopt});
  // Cutting stretch [96 - 86, 96] mm = [10, 96] mm: B's piece plus C's piece, exactly.
  const double w_ext = 0.5 * (0.30 + 0.15) * 0.001 + 0.5 * (0.15 + 1.30) * 0.085;
  const double w_f = 0.90 * kDepth / 2;
  const double w_eps = kStrain * kDepth;
  EXPECT_NEAR(e.cut_start_m, 0.010, 1e-15);
  EXPECT_NEAR(e.cut_end_m, 0.096, 1e-15);
  EXPECT_NEAR(e.external_work_J, w_ext, 1e-12);
  EXPECT_TRUE(e.friction_from_record);
  EXPECT_NEAR(e.friction_force_N, 0.90, 1e-12);
  EXPECT_NEAR(e.friction_work_J, w_f, 1e-15);
  EXPECT_NEAR(e.strain_work_J, w_eps, 1e-15);
  EXPECT_NEAR(e.crack_work_J, w_ext - w_f - w_eps, 1e-12);
  EXPECT_NEAR(e.toughness_J_per_m2, (w_ext - w_f - w_eps) / (kWidth * kDepth), 1e-9);
}

TEST(EnergyBalance, PaperCsMeansGiveItsToughness) {
  // Paper C §5: W_f 39.99 mJ, W_eps 6.30 mJ, W_Gc 22.48 mJ over d = 86 mm, w = 15 mm give
  // G_c = 17.43 J/m^2. A record whose stretch holds W_ext = 68.77 mJ with F_max = 2 W_f / d
  // reproduces it; the tolerance is the paper's rounding to 4 digits (0.005 J/m^2).
  const double w_f = 39.99e-3, w_gc = 22.48e-3, u = 6.30e-3 / kDepth;
  const double f_max = 2 * w_f / kDepth;
  const double w_ext = w_f + u * kDepth + w_gc;
  // Cutting force linear from f0 at 10 mm to 1.30 N at 96 mm with the area w_ext.
  const double f0 = 2 * w_ext / kDepth - 1.30;
  const auto c =
      piecewise({{0, 0}, {9.9, 2 * f0}, {10, f0}, {96, 1.30}, {96.1, f_max}, {130, f_max}}, 130);
  const auto e = mneedle::energy_balance(c, mneedle::split_stages(c), {kDepth, kWidth, u, {}});
  EXPECT_NEAR(e.crack_work_J, w_gc, 1e-9);
  EXPECT_NEAR(e.toughness_J_per_m2, 17.43, 0.005);
}

TEST(EnergyBalance, GivenFrictionForceReplacesTheSlidingStage) {
  const auto c = through_insertion();
  const auto e = mneedle::energy_balance(c, mneedle::split_stages(c), {kDepth, kWidth, 0.0, 0.5});
  EXPECT_FALSE(e.friction_from_record);
  EXPECT_NEAR(e.friction_work_J, 0.5 * kDepth / 2, 1e-15);
}

TEST(EnergyBalance, RecordEndingWhileCuttingNeedsAFrictionForce) {
  const auto c = piecewise({{0, 0}, {10, 0.30}, {11, 0.15}, {100, 0.80}}, 100);
  const auto s = mneedle::split_stages(c);
  const std::string m = message_of([&] {
    mneedle::energy_balance(c, s, {kDepth, kWidth, kStrain, {}});
  });
  EXPECT_NE(m.find("give --friction-force"), std::string::npos) << m;
  EXPECT_NO_THROW(mneedle::energy_balance(c, s, {kDepth, kWidth, kStrain, 0.5}));
}

TEST(EnergyBalance, BlockDeeperThanThePeakIsRefused) {
  const auto c = through_insertion();
  const auto s = mneedle::split_stages(c);
  const std::string m = message_of([&] {
    mneedle::energy_balance(c, s, {0.100, kWidth, kStrain, {}});
  });
  EXPECT_NE(m.find("did not cut through the block"), std::string::npos) << m;
}

TEST(EnergyBalance, NonPositiveInputsAreRefusedByName) {
  const auto c = through_insertion();
  const auto s = mneedle::split_stages(c);
  EXPECT_NE(message_of([&] {
              mneedle::energy_balance(c, s, {0.0, kWidth, kStrain, {}});
            }).find("--depth"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              mneedle::energy_balance(c, s, {kDepth, -1.0, kStrain, {}});
            }).find("crack width"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              mneedle::energy_balance(c, s, {kDepth, kWidth, NAN, {}});
            }).find("strain energy"),
            std::string::npos);
  EXPECT_NE(message_of([&] {
              mneedle::energy_balance(c, s, {kDepth, kWidth, kStrain, 0.0});
            }).find("--friction-force"),
            std::string::npos);
}

TEST(WorkBetween, InterpolatesTheEndsOfTheStretch) {
  const auto c = piecewise({{0, 0}, {10, 1.0}}, 10);
  // F = 100 x (N, x in m): ∫ from 2.05 mm to 7.05 mm = 50 (x1^2 - x0^2).
  EXPECT_NEAR(mneedle::work_between(c, 2.05e-3, 7.05e-3),
              50 * (7.05e-3 * 7.05e-3 - 2.05e-3 * 2.05e-3), 1e-15);
  EXPECT_THROW(mneedle::work_between(c, 5e-3, 11e-3), InputError);
}

TEST(FitCrackWidth, AQuadraticThroughThreeDepthsIsAveragedExactly) {
  // w(z) = 20 mm - 0.3 z + 2.5 z^2 / m (z in m): through its values at 0, 30 and 50 mm.
  const auto w = [](double z) { return 0.020 - 0.3 * z + 2.5 * z * z; };
  const std::vector<std::pair<double, double>> pairs{
      {0.0, w(0.0)}, {0.030, w(0.030)}, {0.050, w(0.050)}};
  const auto fit = mneedle::fit_crack_width(pairs, kDepth);
  ASSERT_EQ(fit.coefficients.size(), 3u);
  const double mean = 0.020 - 0.3 * kDepth / 2 + 2.5 * kDepth * kDepth / 3;
  EXPECT_NEAR(fit.mean_width_m, mean, 1e-15);
  EXPECT_NEAR(fit.max_residual_m, 0.0, 1e-15);
  // The vertex z = 0.3 / 5 = 60 mm lies inside the block.
  EXPECT_NEAR(fit.min_width_m, w(0.060), 1e-15);
}

TEST(FitCrackWidth, OneDepthIsAConstantAndTwoALine) {
  const std::vector<std::pair<double, double>> one{{0.0, 0.015}};
  EXPECT_NEAR(mneedle::fit_crack_width(one, kDepth).mean_width_m, 0.015, 1e-15);
  const std::vector<std::pair<double, double>> two{{0.0, 0.018}, {0.086, 0.010}};
  EXPECT_NEAR(mneedle::fit_crack_width(two, kDepth).mean_width_m, 0.014, 1e-15);
}

TEST(FitCrackWidth, BadPairsAreRefusedNamingTheOption) {
  const std::vector<std::pair<double, double>> outside{{0.1, 0.015}};
  EXPECT_NE(
      message_of([&] { mneedle::fit_crack_width(outside, kDepth); }).find("--crack-widths: depth"),
      std::string::npos);
  const std::vector<std::pair<double, double>> negative{{0.0, -0.015}};
  EXPECT_THROW(mneedle::fit_crack_width(negative, kDepth), InputError);
  // A line from 20 mm to 1 mm at 30 mm crosses zero before 86 mm.
  const std::vector<std::pair<double, double>> crossing{{0.0, 0.020}, {0.030, 0.001}};
  EXPECT_NE(message_of([&] { mneedle::fit_crack_width(crossing, kDepth); }).find("falls to"),
            std::string::npos);
  EXPECT_THROW(mneedle::fit_crack_width({}, kDepth), InputError);
}

TEST(SplitStages, PhantomRecordingsShowPunctureRelaxationAndCuttingButNoExit) {
  // The skin-on-muscle phantom (../shared/refdata/README.md) is held and retracted, never pushed
  // through: every loading branch has A, B and C, and no D or E.
  const auto dir = mneedle::test::refdata_dir() / "phantom_insertions";
  const auto file = dir / "skin-on-muscle_1_0_2_1_2024-06-14-15-35-44.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto pass = mneedle::prepare_pass(mneedle::read_force_curve_csv(file));
  mneedle::StageOptions o;
  o.noise_N = pass.branch.noise_N;
  const auto s = mneedle::split_stages(pass.curve, o);
  const auto& c = pass.curve;
  // Read off the file: contact near 4.6 mm travel, puncture 5.1 N near 17 mm travel (12.5 mm
  // after contact), relaxation to about 2 N, cutting back up to about 4.4 N.
  EXPECT_GT(c.force_N[s.puncture_index], 5.0);
  EXPECT_NEAR(c.depth_m[s.puncture_index], 12.5e-3, 0.5e-3);
  EXPECT_LT(c.force_N[s.relaxed_index], 2.2);
  EXPECT_GT(c.depth_m[s.peak_index], c.depth_m[s.relaxed_index]);
  EXPECT_FALSE(s.through);
}

}  // namespace
