#include "mneedle/geometry/surface_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mneedle/base/error.h"
#include "mneedle/geometry/tip_area.h"
#include "needle_shapes.h"

namespace {

constexpr double kPi = std::numbers::pi;

TEST(SurfaceReport, DefaultHeightsStopAtTheNeedleLength) {
  mneedle::test::ShapeOptions o;
  o.length = 300e-6;
  const auto heights = mneedle::default_tip_area_heights(mneedle::test::cylinder(o));
  ASSERT_EQ(heights.size(), 6u);
  EXPECT_DOUBLE_EQ(heights.back(), 200e-6);
}

TEST(SurfaceReport, BevelReportHasBetaFacesAndTheSegmentAreas) {
  const double bevel = kPi / 6.0;
  const auto report = mneedle::surface_report(mneedle::test::sharp_bevel({}, bevel));
  EXPECT_GT(report.groups.of(mneedle::SurfaceGroup::beta).count, 0u);
  ASSERT_EQ(report.tip_area.size(), 7u);
  const mneedle::TipGeometry g{mneedle::TipShape::sharp_bevel, 115e-6, 0.0, bevel};
  for (const auto& point : report.tip_area) {
    EXPECT_NEAR(point.area_m2, mneedle::tip_area(g, point.height_m),
                0.01 * mneedle::full_section_area(g));
  }
}

TEST(SurfaceReport, NegativeHeightIsAnInputError) {
  EXPECT_THROW(mneedle::surface_report(mneedle::test::cylinder({}), {-1e-6}), mneedle::InputError);
}

}  // namespace
