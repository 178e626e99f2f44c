#include "mneedle/strength/section_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mneedle/base/error.h"

namespace {

constexpr double kPi = std::numbers::pi;
using Loop = std::vector<std::array<double, 2>>;

Loop rectangle(double x0, double y0, double w, double h) {
  return {{x0, y0}, {x0 + w, y0}, {x0 + w, y0 + h}, {x0, y0 + h}};
}

Loop circle(double r, int n, bool clockwise = false) {
  Loop loop;
  for (int i = 0; i < n; ++i) {
    const double t = (clockwise ? -2.0 : 2.0) * kPi * i / n;
    loop.push_back({r * std::cos(t), r * std::sin(t)});
  }
  return loop;
}

// Closed cylinder (radius r, height h, n segments), outward, in the needle frame; with
// cone_height > 0 its lower end is a cone of that height with its point at the origin.
mneedle::TriangleMesh cylinder(double r, double h, int n, double cone_height = 0.0) {
  mneedle::TriangleMesh m;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < n; ++i)
      m.vertices.push_back({r * std::cos(2 * kPi * i / n), r * std::sin(2 * kPi * i / n),
                            ring == 0 ? cone_height : h});
  const auto un = static_cast<std::uint32_t>(n);
  m.vertices.push_back({0, 0, 0});
  m.vertices.push_back({0, 0, h});
  for (std::uint32_t i = 0; i < un; ++i) {
    const std::uint32_t j = (i + 1) % un;
    m.triangles.push_back({i, j, j + un});
    m.triangles.push_back({i, j + un, i + un});
    m.triangles.push_back({2 * un, j, i});
    m.triangles.push_back({2 * un + 1, i + un, j + un});
  }
  return m;
}

TEST(SectionTable, RectangleMinimumSecondMomentIsAboutItsLongAxis) {
  // 4 × 1 rectangle away from the origin: I_min = b h³ / 12 = 4/12 about its centroid.
  const auto s = mneedle::polygon_section_properties({rectangle(3.0, -2.0, 4.0, 1.0)});
  EXPECT_NEAR(s.area_m2, 4.0, 1e-12);
  EXPECT_NEAR(s.i_min_m4, 4.0 / 12.0, 1e-12);
  EXPECT_NEAR(s.extreme_fibre_m, std::hypot(2.0, 0.5), 1e-12);
}

TEST(SectionTable, RotatedSquareKeepsItsSecondMoment) {
  const double c = std::cos(0.3), s = std::sin(0.3);
  Loop square;
  for (const auto& p : rectangle(-0.5, -0.5, 1.0, 1.0))
    square.push_back({c * p[0] - s * p[1] + 7.0, s * p[0] + c * p[1] - 2.0});
  const auto props = mneedle::polygon_section_properties({square});
  EXPECT_NEAR(props.i_min_m4, 1.0 / 12.0, 1e-12);
}

TEST(SectionTable, BoreIsSubtractedWhateverTheLoopOrientation) {
  const double r_out = 115e-6, r_in = 45e-6;
  const int n = 4096;
  for (bool clockwise : {false, true}) {
    const auto s =
        mneedle::polygon_section_properties({circle(r_out, n), circle(r_in, n, clockwise)});
    EXPECT_NEAR(s.area_m2 / (kPi * (r_out * r_out - r_in * r_in)), 1.0, 1e-5);
    EXPECT_NEAR(s.i_min_m4 / (kPi / 4 * (std::pow(r_out, 4) - std::pow(r_in, 4))), 1.0, 1e-5);
  }
}

TEST(SectionTable, SlicedCylinderMatchesTheCircle) {
  const double r = 115e-6, length = 1e-3;
  const auto table = mneedle::SectionTable::from_mesh(cylinder(r, length, 256), 20);
  EXPECT_NEAR(table.length_m(), length, 1e-15);
  EXPECT_NEAR(table.tip_length_m(), 0.0, 1e-15);
  const auto s = table.at(0.4 * length);
  EXPECT_NEAR(s.area_m2 / (kPi * r * r), 1.0, 1e-3);
  EXPECT_NEAR(s.i_min_m4 / (kPi * std::pow(r, 4) / 4), 1.0, 2e-3);
}

TEST(SectionTable, TheSameConeTipOnAShortAndALongShaftHasTheSameTipLength) {
  // 99 % of the shaft's area on a cone of height c: c sqrt(0.99), between the samples of a
  // 600 um and a 1 mm needle's grids (3 and 5 um) and next to the kink at c, where a chord
  // between the samples read 0.75 um apart.
  const double r = 100e-6, cone = 374e-6, expected = cone * std::sqrt(0.99);
  for (const double length : {600e-6, 1e-3}) {
    const auto table = mneedle::SectionTable::from_mesh(cylinder(r, length, 64, cone), 200);
    // The bisection's 1e-9 of the grid's spacing.
    EXPECT_NEAR(table.tip_length_m(), expected, 1e-9 * length / 200) << length;
  }
}

TEST(SectionTable, InterpolatesBetweenHeightsAndRejectsBadTables) {
  mneedle::SectionTable table({0.0, 1.0}, {{0.0, 0.0, 0.0}, {2.0, 4.0, 1.0}});
  EXPECT_DOUBLE_EQ(table.at(0.25).area_m2, 0.5);
  EXPECT_DOUBLE_EQ(table.at(5.0).i_min_m4, 4.0);
  EXPECT_DOUBLE_EQ(table.tip_length_m(0.5), 0.5);  // no exact section: the chord
  EXPECT_THROW(mneedle::SectionTable({1.0, 0.0}, {{}, {}}), mneedle::InputError);
  EXPECT_THROW(mneedle::SectionTable({0.0}, {{}}), mneedle::InputError);
}

}  // namespace
