#include "mneedle/geometry/footprint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mneedle/geometry/tip_area.h"
#include "needle_shapes.h"

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kR = 115e-6;

TEST(Footprint, CylinderCoversItsEndPolygon) {
  const auto fp = mneedle::footprint(mneedle::test::cylinder({}), 10e-6);
  EXPECT_GE(fp.hull.size(), 64u);
  EXPECT_NEAR(fp.area_m2, 0.5 * 64 * kR * kR * std::sin(2 * kPi / 64), 1e-18);
}

TEST(Footprint, ConeFootprintGrowsWithDepth) {
  const double half = kPi / 12.0;
  const auto needle = mneedle::test::cone({}, half, 8);
  const double depth = 0.5 * kR / std::tan(half);  // on a ring of vertices
  const auto fp = mneedle::footprint(needle, depth);
  const double r = depth * std::tan(half);
  EXPECT_NEAR(fp.area_m2, kPi * r * r, 0.01 * kPi * r * r);
  EXPECT_LT(mneedle::footprint(needle, 0.5 * depth).area_m2, fp.area_m2);
}

TEST(Footprint, SharpBevelFootprintIsTheConvexSegment) {
  const double bevel = kPi / 6.0;
  const double depth = 150e-6;
  const auto fp = mneedle::footprint(mneedle::test::sharp_bevel({}, bevel), depth);
  const mneedle::TipGeometry g{mneedle::TipShape::sharp_bevel, kR, 0.0, bevel};
  EXPECT_NEAR(fp.area_m2, mneedle::tip_area(g, depth), 0.01 * kPi * kR * kR);
}

TEST(Footprint, AboveTheSurfaceItIsEmpty) {
  const auto fp = mneedle::footprint(mneedle::test::cylinder({}), -1e-6);
  EXPECT_TRUE(fp.hull.empty());
  EXPECT_DOUBLE_EQ(fp.area_m2, 0.0);
}

}  // namespace
