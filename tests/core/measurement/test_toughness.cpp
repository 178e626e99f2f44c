#include "mneedle/measurement/toughness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/geometry/tip_area.h"
#include "needle_shapes.h"
#include "refdata.h"

namespace {

using std::numbers::pi;

const std::string kCurves = std::string(MNEEDLE_TEST_ASSETS) + "/curves/";
const std::filesystem::path kRefdata =
    std::filesystem::path(MNEEDLE_SOURCE_ROOT) / ".." / "shared" / "refdata";

// The synthetic pair of the assets (tests/assets/curves/toughness_*.csv): a cone tip of shaft
// radius R and tan(alpha) = 1/2 makes the crack A(z) = pi (z/2)^2 up to pi R^2;
// F = F' + J dA/dz, so ∫(F - F') dz = J A.
constexpr double kJ = 19.0;
constexpr double kRadius = 115e-6;
constexpr double kTan = 0.5;
const double kShaftArea = pi * kRadius * kRadius;

double second_force(double z) {
  return z > 0 ? 1000.0 * std::pow(z, 1.5) : 0.0;
}
double first_force(double z) {
  const double crack = z > 0 && z < kRadius / kTan ? kJ * 2 * pi * kTan * kTan * z : 0.0;
  return second_force(z) + crack;
}

// A clean recording: approach from travel 0, contact at `contact`, loading to `deepest`.
mneedle::ForceCurve recording(double (*force)(double), double contact, double deepest,
                              double step) {
  mneedle::ForceCurve c;
  c.source = "synthetic.csv";
  for (int i = 0; i * step <= deepest + 1e-12; ++i) {
    c.depth_m.push_back(i * step);
    c.force_N.push_back(force(i * step - contact));
    c.line.push_back(static_cast<std::size_t>(i) + 2);
  }
  return c;
}

// Index of the grid point nearest to depth z.
std::size_t at_depth(const mneedle::ForceDifference& d, double z) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < d.depth_m.size(); ++i)
    if (std::abs(d.depth_m[i] - z) < std::abs(d.depth_m[best] - z)) best = i;
  return best;
}

mneedle::InsertionPass pass_from(const std::string& file) {
  return mneedle::prepare_pass(mneedle::read_force_curve_csv(kCurves + file));
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Toughness, SyntheticPairFromAKnownJGivesItBackWithinOnePercent) {
  const auto first = mneedle::prepare_pass(recording(first_force, 100e-6, 500e-6, 1e-6));
  const auto second = mneedle::prepare_pass(recording(second_force, 50e-6, 450e-6, 2e-6));
  const auto d = mneedle::force_difference(first, second);
  EXPECT_NEAR(d.difference_work_J, kJ * kShaftArea, 0.01 * kJ * kShaftArea);
  EXPECT_NEAR(mneedle::toughness_J_per_m2(d, kShaftArea), kJ, 0.01 * kJ);
  EXPECT_NEAR(d.difference_work_J, d.first_work_J - d.second_work_J, 1e-15);
}

TEST(Toughness, PairStartingAtContactGivesTheKnownJ) {
  // Both passes recorded from contact on, as `mneedle force --csv` writes them: no approach to
  // take a baseline from. Reference kJ; 1 % as for the pair with an approach above (trapezoid
  // rule on a 1 um grid, the crack term ending between two samples).
  const auto first = mneedle::prepare_pass(recording(first_force, 0.0, 500e-6, 1e-6));
  const auto second = mneedle::prepare_pass(recording(second_force, 0.0, 450e-6, 2e-6));
  EXPECT_EQ(first.cut.before_contact, 0u);
  EXPECT_EQ(first.cut.baseline_N, 0.0);
  EXPECT_EQ(second.cut.baseline_N, 0.0);
  const auto d = mneedle::force_difference(first, second);
  EXPECT_NEAR(mneedle::toughness_J_per_m2(d, kShaftArea), kJ, 0.01 * kJ);
}

TEST(Toughness, PassLoadedFromItsFirstStepIsMeasuredFromTravelZero) {
  // The first pass as `mneedle simulate --csv` writes it, from its first step (1 um) on, already
  // loaded there; the second from (0, 0). Reference kJ; 1 %: the trapezoid rule loses about half
  // a step of the crack term where it ends (0.4 % here), while measuring the first pass from its
  // first sample, one step off, would add 1.8 %.
  mneedle::ForceCurve first = recording(first_force, 0.0, 500e-6, 1e-6);
  first.depth_m.erase(first.depth_m.begin());
  first.force_N.erase(first.force_N.begin());
  first.line.erase(first.line.begin());
  const auto pass = mneedle::prepare_pass(first);
  EXPECT_EQ(pass.cut.contact_travel_m, 0.0);
  EXPECT_EQ(pass.curve.depth_m.front(), first.depth_m.front());
  const auto d = mneedle::force_difference(
      pass, mneedle::prepare_pass(recording(second_force, 0.0, 500e-6, 1e-6)));
  EXPECT_NEAR(mneedle::toughness_J_per_m2(d, kShaftArea), kJ, 0.01 * kJ);
}

TEST(Toughness, AssetPairInMillinewtonsMillimetresAndMicrometresGivesTheKnownJ) {
  const auto d = mneedle::force_difference(pass_from("toughness_first.csv"),
                                           pass_from("toughness_second.csv"));
  EXPECT_NEAR(mneedle::toughness_J_per_m2(d, kShaftArea), kJ, 0.01 * kJ);
  // The first file's loading branch ends within 0.2 % of the stroke of its deepest travel.
  EXPECT_NEAR(d.end_depth_m, 399e-6, 1e-9);
  // force_mN with a 0.5 mN offset: removed as the baseline.
  EXPECT_NEAR(d.first.baseline_N, 0.5e-3, 1e-12);
  const std::size_t i = at_depth(d, 204e-6);  // not a merged point of the second file
  ASSERT_NEAR(d.depth_m[i], 204e-6, 1e-12);
  EXPECT_NEAR(d.first_force_N[i], first_force(204e-6), 1e-9);
  EXPECT_NEAR(d.second_force_N[i], second_force(204e-6), 1e-9);
}

TEST(Toughness, HoldAndRetractionAreCutAndCounted) {
  const auto first = pass_from("toughness_first.csv");
  EXPECT_EQ(first.cut.rows, 651u);
  EXPECT_EQ(first.cut.before_contact, 100u);
  EXPECT_NEAR(first.cut.contact_travel_m, 0.1e-3, 1e-12);
  EXPECT_EQ(first.cut.hold, 51u);  // the last loading sample (0.5 mm) and the 50 held
  EXPECT_EQ(first.cut.retraction, 100u);
  EXPECT_EQ(first.cut.points, 400u);
  EXPECT_EQ(first.cut.repeated_depth + first.cut.receding_depth, 0u);
}

TEST(Toughness, RepeatedAndRecedingDepthsAreMergedAndCounted) {
  const auto second = pass_from("toughness_second.csv");
  EXPECT_EQ(second.cut.rows, 282u);
  EXPECT_EQ(second.cut.repeated_depth, 22u);
  // The last step back (449 um after 450 um) lies within 0.2 % of the stroke of the deepest
  // point: it is cut as the hold, not merged.
  EXPECT_EQ(second.cut.receding_depth, 8u);
  EXPECT_EQ(second.cut.hold, 1u);
  for (std::size_t i = 1; i < second.curve.depth_m.size(); ++i)
    ASSERT_GT(second.curve.depth_m[i], second.curve.depth_m[i - 1]);
  const auto d = mneedle::force_difference(pass_from("toughness_first.csv"), second);
  EXPECT_EQ(d.second.beyond_end, 26u);  // 400 .. 450 um every 2 um
}

TEST(Toughness, MaxDepthInsideTheTipGivesTheCrackGrownSoFar) {
  // Paper A eq. 14 in its differential form: ∫_0^z (F - F') dz = J A(z), A(z) = pi (z tan a)^2.
  const auto first = mneedle::prepare_pass(recording(first_force, 50e-6, 550e-6, 1e-6));
  const auto second = mneedle::prepare_pass(recording(second_force, 50e-6, 550e-6, 1e-6));
  mneedle::ToughnessOptions options;
  options.max_depth_m = 150e-6;
  const auto d = mneedle::force_difference(first, second, options);
  EXPECT_DOUBLE_EQ(d.end_depth_m, 150e-6);
  EXPECT_NEAR(d.difference_work_J, kJ * pi * std::pow(150e-6 * kTan, 2), 1e-3 * kJ * kShaftArea);
}

TEST(Toughness, NonPositiveMaxDepthIsAnInputErrorNamingTheOption) {
  const auto first = mneedle::prepare_pass(recording(first_force, 50e-6, 550e-6, 1e-6));
  for (double bad : {0.0, -1e-3, std::nan("")}) {
    mneedle::ToughnessOptions options;
    options.max_depth_m = bad;
    const auto msg = error_of([&] { mneedle::force_difference(first, first, options); });
    EXPECT_NE(msg.find("--max-depth"), std::string::npos) << msg;
    EXPECT_NE(msg.find("must be a positive length"), std::string::npos) << msg;
  }
}

TEST(Toughness, MaxDepthKeepingFewerThanThreeSamplesSaysHowManyRemain) {
  const auto first = mneedle::prepare_pass(recording(first_force, 50e-6, 550e-6, 1e-6));
  mneedle::ToughnessOptions options;
  options.max_depth_m = 1e-15;  // only the contact sample, at depth 0
  const auto msg = error_of([&] { mneedle::force_difference(first, first, options); });
  EXPECT_NE(msg.find("--max-depth"), std::string::npos) << msg;
  EXPECT_NE(msg.find("keeps 1 sample of synthetic.csv and 1 of synthetic.csv"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("at least 3 of each are needed"), std::string::npos) << msg;
  options.max_depth_m = 2e-6;  // samples at 0, 1 and 2 um: enough
  EXPECT_NEAR(mneedle::force_difference(first, first, options).end_depth_m, 2e-6, 1e-18);
}

TEST(Toughness, TravelAlignmentKeepsTheSecondPassAtItsOwnTravel) {
  // Second pass touches 40 um later on the same stage zero: with travel alignment it has no
  // force over the first 40 um of the first pass's depth.
  const auto first = mneedle::prepare_pass(recording(first_force, 100e-6, 500e-6, 1e-6));
  const auto second = mneedle::prepare_pass(recording(second_force, 140e-6, 500e-6, 1e-6));
  mneedle::ToughnessOptions travel;
  travel.alignment = mneedle::DepthAlignment::Travel;
  const auto by_travel = mneedle::force_difference(first, second, travel);
  const auto by_contact = mneedle::force_difference(first, second);
  EXPECT_NEAR(by_travel.second_force_N[at_depth(by_travel, 30e-6)], 0.0, 1e-15);
  EXPECT_NEAR(by_travel.second_force_N[at_depth(by_travel, 100e-6)], second_force(60e-6), 1e-9);
  EXPECT_NEAR(by_contact.second_force_N[at_depth(by_contact, 100e-6)], second_force(100e-6), 1e-9);
  EXPECT_GT(by_travel.difference_work_J, by_contact.difference_work_J);
  EXPECT_EQ(mneedle::parse_depth_alignment("travel"), mneedle::DepthAlignment::Travel);
  EXPECT_NE(error_of([] { mneedle::parse_depth_alignment("surface"); }).find("contact or travel"),
            std::string::npos);
}

TEST(Toughness, NonPositiveCrackAreaIsAnInputError) {
  const auto first = mneedle::prepare_pass(recording(first_force, 50e-6, 550e-6, 1e-6));
  const auto d = mneedle::force_difference(first, first);
  EXPECT_DOUBLE_EQ(mneedle::toughness_J_per_m2(d, kShaftArea), 0.0);
  EXPECT_THROW(mneedle::toughness_J_per_m2(d, 0.0), mneedle::InputError);
  EXPECT_THROW(mneedle::toughness_J_per_m2(d, std::nan("")), mneedle::InputError);
}

TEST(Toughness, CrackAreaOfASharpBevelIsPaperAsCircularSegmentUpToTheShaftSection) {
  const double bevel = 30 * pi / 180;
  mneedle::test::ShapeOptions o;
  o.segments = 128;
  o.rings = 40;
  const auto mesh = mneedle::test::sharp_bevel(o, bevel);
  const mneedle::TipGeometry tip{mneedle::TipShape::sharp_bevel, o.radius, 0.0, bevel};
  for (double depth : {50e-6, 200e-6}) {
    const auto a = mneedle::needle_crack_area(mesh, depth);
    EXPECT_NEAR(a.area_m2, mneedle::tip_area(tip, depth), 0.01 * kShaftArea) << depth;
  }
  const auto full = mneedle::needle_crack_area(mesh, 600e-6);
  EXPECT_NEAR(full.area_m2, kShaftArea, 0.005 * kShaftArea);
  // The tip's length: where the section first holds 99 % of the shaft's, the chord at c with
  // the outer segment x <= c of the circle 0.99 of its area, h = (R + c) / tan(bevel) =
  // 385.29 um (the heel is at 2 R / tan(bevel) = 398.37 um). Within 0.2 %: the 128-gon's
  // sections against the circle's.
  const double R = o.radius;
  const auto share = [R](double c) {
    return 1.0 - (R * R * std::acos(c / R) - c * std::sqrt(R * R - c * c)) / (pi * R * R);
  };
  double lo = -R, hi = R;
  for (int i = 0; i < 100; ++i) (share(0.5 * (lo + hi)) < 0.99 ? lo : hi) = 0.5 * (lo + hi);
  EXPECT_NEAR(full.tip_length_m, (R + lo) / std::tan(bevel), 0.002 * full.tip_length_m);
  // Deeper than the needle: its top section.
  EXPECT_NEAR(mneedle::needle_crack_area(mesh, 5e-3).area_m2, full.area_m2, 1e-3 * kShaftArea);
}

TEST(Toughness, CrackAreaOfAHollowNeedleExcludesTheBore) {
  mneedle::test::ShapeOptions o;
  o.bore = 45e-6;
  o.segments = 128;
  const auto a = mneedle::needle_crack_area(mneedle::test::cylinder(o), 300e-6);
  EXPECT_NEAR(a.area_m2, pi * (o.radius * o.radius - o.bore * o.bore), 0.005 * kShaftArea);
}

TEST(Toughness, AreaTextTakesASquaredLengthUnit) {
  EXPECT_NEAR(mneedle::parse_area_m2("0.0415mm^2"), 0.0415e-6, 1e-15);
  EXPECT_NEAR(mneedle::parse_area_m2("41500 um2"), 0.0415e-6, 1e-15);
  EXPECT_NEAR(mneedle::parse_area_m2("4e-8 m^2"), 4e-8, 1e-20);
  EXPECT_NEAR(mneedle::parse_area_m2("1 cm^2"), 1e-4, 1e-16);
  for (const char* bad : {"3 mm", "1 N^2", "-1mm^2", "0", "mm^2", "abc", "4e-8", "0.0415"}) {
    const auto msg = error_of([bad] { mneedle::parse_area_m2(bad); });
    EXPECT_NE(msg.find("area '" + std::string(bad) + "'"), std::string::npos) << msg;
  }
  // Beyond a double: said so (it said "must be positive").
  EXPECT_NE(error_of([] { mneedle::parse_area_m2("1e400mm^2"); }).find("not a finite number"),
            std::string::npos);
}

// A bare number would be m^2 (0.0415 read so is 10^6 times the 0.0415 mm^2 meant, and J 10^6
// too small): it is refused and the message asks for the unit.
TEST(Toughness, AnAreaWithoutItsUnitIsAnErrorThatAsksForIt) {
  const auto msg = error_of([] { mneedle::parse_area_m2("0.0415"); });
  EXPECT_NE(msg.find("area '0.0415': needs its unit (expected a length unit squared"),
            std::string::npos)
      << msg;
}

TEST(Toughness, MissingColumnTextInANumberAndNoLoadingBranchNameFileAndLine) {
  const auto missing = error_of([] { pass_from("missing_column.csv"); });
  EXPECT_NE(missing.find("missing_column.csv:1: no force column"), std::string::npos) << missing;
  const auto text = error_of([] { pass_from("text_in_number.csv"); });
  EXPECT_NE(text.find("text_in_number.csv:4: column 'fz_N': 'abc'"), std::string::npos) << text;
  const auto flat = error_of([] { pass_from("no_loading_branch.csv"); });
  EXPECT_NE(flat.find("no_loading_branch.csv:10: no loading branch"), std::string::npos) << flat;
}

TEST(Toughness, LargestForceDropIsThePunctureAndTheTailPassCancelsAfterIt) {
  const auto first = mneedle::prepare_pass(recording(first_force, 50e-6, 550e-6, 1e-6));
  mneedle::ForceDrop drop;
  const auto second = mneedle::second_pass_from_tail(first, &drop);
  // The crack term J dA/dz vanishes once the tip is in (z = R / tan a = 230 um).
  EXPECT_NEAR(drop.peak_depth_m, 229e-6, 1.5e-6);
  EXPECT_NEAR(drop.bottom_depth_m, 230e-6, 1.5e-6);
  const auto d = mneedle::force_difference(first, second);
  for (std::size_t i = 0; i < d.depth_m.size(); ++i) {
    if (d.depth_m[i] >= drop.bottom_depth_m) {
      ASSERT_DOUBLE_EQ(d.first_force_N[i], d.second_force_N[i]);
    }
  }
  // Hump above the chord from 0 to the post-puncture force: ∫F - F_b z_b / 2 up to z_b.
  double hump = 0.0;
  for (std::size_t i = 1; i < d.depth_m.size() && d.depth_m[i] <= drop.bottom_depth_m; ++i)
    hump += 0.5 * (d.first_force_N[i] + d.first_force_N[i - 1]) * (d.depth_m[i] - d.depth_m[i - 1]);
  hump -= 0.5 * drop.bottom_force_N * drop.bottom_depth_m;
  EXPECT_NEAR(d.difference_work_J, hump, 1e-3 * hump);
}

TEST(Toughness, CurveWithoutADropHasNoTailToBuildASecondPassFrom) {
  const auto second = mneedle::prepare_pass(recording(second_force, 50e-6, 550e-6, 1e-6));
  const auto msg = error_of([&] { mneedle::second_pass_from_tail(second); });
  EXPECT_NE(msg.find("synthetic.csv: no puncture"), std::string::npos) << msg;
}

TEST(Toughness, RetractionPassIsTheFrictionMetOnTheWayOut) {
  const auto raw = mneedle::read_force_curve_csv(kCurves + "toughness_first.csv");
  const auto first = mneedle::prepare_pass(raw);
  const auto second = mneedle::second_pass_from_retraction(raw, first);
  ASSERT_GE(second.curve.depth_m.size(), 80u);
  EXPECT_NEAR(second.curve.depth_m.front(), 0.0, 1e-12);  // the last sample inside the tissue
  EXPECT_NEAR(second.curve.force_N[10], 2e-3, 1e-9);      // 2 mN pulling back, sign flipped
  EXPECT_NEAR(second.curve.depth_m.back(), 0.395e-3, 1e-9);
  const auto d = mneedle::force_difference(first, second);
  EXPECT_NEAR(d.second_work_J, 2e-3 * d.end_depth_m, 0.02 * 2e-3 * d.end_depth_m);
}

TEST(Toughness, FlatRecordingHasNoRetractionPass) {
  const auto first = mneedle::prepare_pass(recording(first_force, 100e-6, 500e-6, 1e-6));
  mneedle::ForceCurve raw = recording(first_force, 100e-6, 500e-6, 1e-6);
  const auto msg = error_of([&] { mneedle::second_pass_from_retraction(raw, first); });
  EXPECT_NE(msg.find("no retraction"), std::string::npos) << msg;
}

TEST(Toughness, PhantomRecordingGivesAFinitePositiveJFromBothConstructions) {
  const auto file =
      kRefdata / "phantom_insertions" / "skin-on-muscle_2_0_3_1_2024-06-19-11-35-16.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto raw = mneedle::read_force_curve_csv(file);
  const auto first = mneedle::prepare_pass(raw);
  mneedle::ForceDrop drop;
  const auto tail = mneedle::force_difference(first, mneedle::second_pass_from_tail(first, &drop));
  // Puncture near 14.7 mm travel: 4.2 N -> 2.1 N (docs/validation.md, "Fracture toughness from
  // two insertions", real recordings).
  EXPECT_NEAR(drop.peak_depth_m + first.cut.contact_travel_m, 14.7e-3, 0.3e-3);
  EXPECT_GT(drop.peak_force_N - drop.bottom_force_N, 1.5);
  EXPECT_GT(tail.difference_work_J, 0.0);
  const auto out =
      mneedle::force_difference(first, mneedle::second_pass_from_retraction(raw, first));
  EXPECT_GT(out.difference_work_J, tail.difference_work_J);
}

TEST(Toughness, DigitisedLiverCurveMergesItsRunsAtOneDepth) {
  const auto file = kRefdata / "okamura_liver" / "depth_force_curveA_mm.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto first = mneedle::prepare_pass(mneedle::read_force_curve_csv(file));
  EXPECT_GT(first.cut.repeated_depth, 20u);  // the drop at 19.15 mm is a run at one depth
  EXPECT_GT(first.cut.receding_depth, 0u);
  mneedle::ForceDrop drop;
  const auto d = mneedle::force_difference(first, mneedle::second_pass_from_tail(first, &drop));
  EXPECT_NEAR(drop.peak_force_N, 1.41, 0.05);
  EXPECT_GT(d.difference_work_J, 0.0);
}

}  // namespace
