#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "shape_kit.h"

namespace mneedle::shape_kit {
namespace {

constexpr double kPi = std::numbers::pi;

// Midpoint-rule integrals over the region x >= b of a disc: an independent check of the
// closed forms.
SegmentMoments numeric_segment(double r, double b, int n = 2000) {
  SegmentMoments m{0, 0, 0, 0};
  const double step = 2 * r / n;
  for (int i = 0; i < n; ++i) {
    const double x = -r + (i + 0.5) * step;
    if (x < b) continue;
    for (int j = 0; j < n; ++j) {
      const double y = -r + (j + 0.5) * step;
      if (x * x + y * y > r * r) continue;
      const double da = step * step;
      m.area += da;
      m.sx += x * da;
      m.ixx += x * x * da;
      m.iyy += y * y * da;
    }
  }
  return m;
}

TEST(ShapeKitSections, DiscSegmentMatchesNumericIntegration) {
  const double r = 1.0;
  for (const double b : {-0.8, -0.3, 0.0, 0.4, 0.9}) {
    const SegmentMoments exact = disc_segment(r, b);
    const SegmentMoments numeric = numeric_segment(r, b);
    EXPECT_NEAR(exact.area, numeric.area, 2e-3) << "b " << b;
    EXPECT_NEAR(exact.sx, numeric.sx, 2e-3) << "b " << b;
    EXPECT_NEAR(exact.ixx, numeric.ixx, 2e-3) << "b " << b;
    EXPECT_NEAR(exact.iyy, numeric.iyy, 2e-3) << "b " << b;
  }
}

TEST(ShapeKitSections, DiscSegmentIsEmptyBeyondTheRimAndWholeBeforeIt) {
  const SegmentMoments none = disc_segment(2.0, 2.5);
  EXPECT_EQ(none.area, 0);
  const SegmentMoments whole = disc_segment(2.0, -3.0);
  EXPECT_NEAR(whole.area, kPi * 4, 1e-12);
  EXPECT_NEAR(whole.sx, 0, 1e-12);
  EXPECT_NEAR(whole.ixx, kPi * 16 / 4, 1e-12);
  EXPECT_NEAR(whole.iyy, kPi * 16 / 4, 1e-12);
}

TEST(ShapeKitSections, HalfAnnulusIMinIsAboutTheAxisParallelToTheCut) {
  const double ro = 2.0, ri = 1.0;
  const SectionProperties s = annulus_segment_properties(ro, ri, 0.0);
  const double area = kPi * (ro * ro - ri * ri) / 2;
  const double centroid = 4 * (std::pow(ro, 3) - std::pow(ri, 3)) / (3 * kPi * (ro * ro - ri * ri));
  const double about_cut =
      kPi * (std::pow(ro, 4) - std::pow(ri, 4)) / 8 - area * centroid * centroid;
  EXPECT_NEAR(s.area_m2, area, 1e-12);
  EXPECT_NEAR(s.i_min_m4, about_cut, 1e-12);
}

TEST(ShapeKitSections, AnnulusPropertiesOfATube) {
  const SectionProperties s = annulus_properties(2.0, 1.0);
  EXPECT_NEAR(s.area_m2, 3 * kPi, 1e-12);
  EXPECT_NEAR(s.i_min_m4, kPi / 4 * 15, 1e-12);
}

}  // namespace
}  // namespace mneedle::shape_kit
