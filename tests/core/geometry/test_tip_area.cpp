#include "mneedle/geometry/tip_area.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mneedle/base/error.h"

namespace {

using mneedle::TipGeometry;
using mneedle::TipShape;
constexpr double kPi = std::numbers::pi;
constexpr double kR = 115e-6;

TEST(TipArea, SegmentRunsFromZeroToTheFullDisc) {
  EXPECT_DOUBLE_EQ(mneedle::circular_segment_area(kR, kR), 0.0);
  EXPECT_NEAR(mneedle::circular_segment_area(kR, 0.0), 0.5 * kPi * kR * kR, 1e-20);
  EXPECT_NEAR(mneedle::circular_segment_area(kR, -kR), kPi * kR * kR, 1e-20);
  EXPECT_NEAR(mneedle::circular_segment_area(kR, -5.0 * kR), kPi * kR * kR, 1e-20);
}

TEST(TipArea, PaperBluntFormIsTheComplementarySegment) {
  // Paper A's blunt form pi R^2 - segment(b) measures b from the other side: segment(-b).
  for (double b : {-0.7 * kR, 0.1 * kR, 0.5 * kR}) {
    EXPECT_NEAR(kPi * kR * kR - mneedle::circular_segment_area(kR, b),
                mneedle::circular_segment_area(kR, -b), 1e-20);
  }
}

TEST(TipArea, SharpBevelGrowsToTheFullSectionAtTheHeel) {
  TipGeometry g{TipShape::sharp_bevel, kR, 0.0, kPi / 6.0};
  const double heel = 2.0 * kR / std::tan(kPi / 6.0);
  EXPECT_DOUBLE_EQ(mneedle::tip_area(g, 0.0), 0.0);
  EXPECT_NEAR(mneedle::tip_area(g, 0.5 * heel), 0.5 * kPi * kR * kR, 1e-20);
  EXPECT_NEAR(mneedle::tip_area(g, 2.0 * heel), kPi * kR * kR, 1e-20);
}

TEST(TipArea, BluntBevelIsTheSharpOneShiftedByTheFlat) {
  TipGeometry sharp{TipShape::sharp_bevel, kR, 0.0, kPi / 6.0};
  TipGeometry blunt = sharp;
  blunt.shape = TipShape::blunt_bevel;
  blunt.flat_width_m = 50e-6;
  const double shift = 50e-6 / std::tan(kPi / 6.0);
  for (double h : {0.0, 20e-6, 100e-6}) {
    EXPECT_DOUBLE_EQ(mneedle::tip_area(blunt, h), mneedle::tip_area(sharp, h + shift));
  }
  EXPECT_NEAR(mneedle::tip_area(blunt, 0.0), mneedle::circular_segment_area(kR, kR - 50e-6), 1e-20);
}

TEST(TipArea, HollowBevelSubtractsTheBoresSegment) {
  TipGeometry g{TipShape::sharp_bevel, kR, 45e-6, kPi / 6.0};
  const double h = 200e-6;
  const double b = kR - h * std::tan(kPi / 6.0);
  EXPECT_NEAR(mneedle::tip_area(g, h),
              mneedle::circular_segment_area(kR, b) - mneedle::circular_segment_area(45e-6, b),
              1e-20);
  EXPECT_NEAR(mneedle::tip_area(g, 1e-3), mneedle::full_section_area(g), 1e-20);
}

TEST(TipArea, ConeGrowsQuadraticallyUpToTheShaft) {
  TipGeometry g{TipShape::cone, kR};
  g.half_angle_rad = kPi / 12.0;
  const double h = 100e-6;
  EXPECT_NEAR(mneedle::tip_area(g, h), kPi * std::pow(h * std::tan(kPi / 12.0), 2), 1e-20);
  EXPECT_NEAR(mneedle::tip_area(g, 10e-3), kPi * kR * kR, 1e-20);
}

TEST(TipArea, CappedConeIsContinuousAtTheTangentLine) {
  TipGeometry g{TipShape::cone, kR};
  g.half_angle_rad = kPi / 12.0;
  g.tip_radius_m = 10e-6;
  const double tangent = 10e-6 * (1.0 - std::sin(kPi / 12.0));
  const double below = mneedle::tip_area(g, tangent * (1.0 - 1e-9));
  const double above = mneedle::tip_area(g, tangent * (1.0 + 1e-9));
  EXPECT_NEAR(below, above, 1e-8 * above);
  EXPECT_NEAR(above, kPi * std::pow(10e-6 * std::cos(kPi / 12.0), 2), 1e-6 * above);
}

TEST(TipArea, CylinderIsTheAnnulusAtEveryHeight) {
  TipGeometry g{TipShape::cylinder, kR, 45e-6};
  EXPECT_NEAR(mneedle::tip_area(g, 1e-6), kPi * (kR * kR - 45e-6 * 45e-6), 1e-20);
  EXPECT_DOUBLE_EQ(mneedle::tip_area(g, -1e-6), 0.0);
}

TEST(TipArea, BoreWiderThanTheShaftIsAnInputError) {
  TipGeometry g{TipShape::cylinder, kR, 2.0 * kR};
  EXPECT_THROW(mneedle::tip_area(g, 1e-6), mneedle::InputError);
}

}  // namespace
