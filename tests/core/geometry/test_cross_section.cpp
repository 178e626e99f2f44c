#include "mneedle/geometry/cross_section.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "mneedle/geometry/tip_area.h"
#include "mneedle/plugin_host.h"
#include "needle_shapes.h"

namespace {

using mneedle::TipGeometry;
using mneedle::TipShape;
using mneedle::test::ShapeOptions;
constexpr double kPi = std::numbers::pi;
constexpr double kR = 115e-6;
constexpr double kBevel = kPi / 6.0;

// Largest |sliced - analytic| over a set of heights, as a fraction of the full section.
double worst_error(const mneedle::TriangleMesh& mesh, const TipGeometry& g) {
  const mneedle::CrossSectionSlicer slicer(mesh);
  const double heel = 2.0 * kR / std::tan(kBevel);
  double worst = 0.0;
  for (double fraction : {0.07, 0.23, 0.41, 0.58, 0.77, 0.93, 1.3}) {
    const double h = fraction * heel;
    worst = std::max(worst, std::abs(slicer.slice(h).area_m2 - mneedle::tip_area(g, h)));
  }
  return worst / mneedle::full_section_area(g);
}

TEST(CrossSection, NestedLoopsSubtractTheHole) {
  const std::vector<std::vector<mneedle::Point2>> loops{{{0, 0}, {4, 0}, {4, 4}, {0, 4}},
                                                        {{1, 1}, {1, 2}, {2, 2}, {2, 1}}};
  EXPECT_DOUBLE_EQ(mneedle::nested_polygon_area(loops), 15.0);
}

TEST(CrossSection, OutlineAreaIsTheConvexHullOfTheLoops) {
  const std::vector<std::vector<mneedle::Point2>> loops{{{0, 0}, {4, 0}, {4, 4}, {0, 4}},
                                                        {{1, 1}, {1, 2}, {2, 2}, {2, 1}},
                                                        {{5, 0}, {6, 0}, {6, 1}, {5, 1}}};
  EXPECT_DOUBLE_EQ(mneedle::outline_area(loops), 21.0);  // hull (0,0) (6,0) (6,1) (4,4) (0,4)
}

TEST(CrossSection, HollowBevelOutlineIsTheOuterSegment) {
  // A hollow sharp bevel's outline at height h is the solid bevel's segment: the bore is filled.
  ShapeOptions hollow;
  hollow.bore = 45e-6;
  const double h = 0.4 * 2.0 * kR / std::tan(kBevel);
  const auto with_bore = mneedle::cross_section(mneedle::test::sharp_bevel(hollow, kBevel), h);
  const auto solid = mneedle::cross_section(mneedle::test::sharp_bevel({}, kBevel), h);
  EXPECT_LT(with_bore.area_m2, solid.area_m2);
  // Same outer facets in both meshes: equal to round-off.
  EXPECT_NEAR(with_bore.outline_area_m2, solid.area_m2, 1e-9 * solid.area_m2);
}

TEST(CrossSection, ThinnestWallOfATubeIsOuterMinusBoreRadius) {
  ShapeOptions o;
  o.bore = 45e-6;
  o.segments = 256;
  const auto tube = mneedle::cross_section(mneedle::test::cylinder(o), 500e-6);
  // Two aligned 256-gons: a bore vertex lies (R - r) cos(pi/256) from the outer edges beside it.
  EXPECT_NEAR(mneedle::thinnest_wall(tube.polygons), (kR - 45e-6) * std::cos(kPi / 256), 1e-12);
  const auto solid = mneedle::cross_section(mneedle::test::cylinder({}), 500e-6);
  EXPECT_NEAR(mneedle::thinnest_wall(solid.polygons), kR * std::cos(kPi / 64), 1e-12);
  EXPECT_EQ(mneedle::thinnest_wall({}), 0.0);
}

TEST(CrossSection, CylinderSectionIsThePolygonArea) {
  const auto section = mneedle::cross_section(mneedle::test::cylinder({}), 333e-6);
  EXPECT_EQ(section.polygons.size(), 1u);
  EXPECT_NEAR(section.area_m2, 0.5 * 64 * kR * kR * std::sin(2 * kPi / 64), 1e-18);
}

TEST(CrossSection, HollowCylinderSectionIsAnAnnulus) {
  ShapeOptions o;
  o.bore = 45e-6;
  const auto section = mneedle::cross_section(mneedle::test::cylinder(o), 333e-6);
  EXPECT_EQ(section.polygons.size(), 2u);
  const TipGeometry g{TipShape::cylinder, kR, 45e-6};
  EXPECT_NEAR(section.area_m2, mneedle::full_section_area(g), 0.01 * mneedle::full_section_area(g));
}

TEST(CrossSection, SharpBevelMatchesTheSegmentWithinOnePercentAndConverges) {
  const TipGeometry g{TipShape::sharp_bevel, kR, 0.0, kBevel};
  ShapeOptions coarse;
  ShapeOptions fine;
  fine.segments = 256;
  const double e_coarse = worst_error(mneedle::test::sharp_bevel(coarse, kBevel), g);
  const double e_fine = worst_error(mneedle::test::sharp_bevel(fine, kBevel), g);
  EXPECT_LT(e_coarse, 0.01);
  EXPECT_LT(e_fine, e_coarse);
}

TEST(CrossSection, HollowSharpBevelMatchesWithinOnePercentAndConverges) {
  const TipGeometry g{TipShape::sharp_bevel, kR, 45e-6, kBevel};
  ShapeOptions coarse;
  coarse.bore = 45e-6;
  ShapeOptions fine = coarse;
  fine.segments = 256;
  const double e_coarse = worst_error(mneedle::test::sharp_bevel(coarse, kBevel), g);
  const double e_fine = worst_error(mneedle::test::sharp_bevel(fine, kBevel), g);
  EXPECT_LT(e_coarse, 0.01);
  EXPECT_LT(e_fine, e_coarse);
}

TEST(CrossSection, BluntBevelMatchesWithinOnePercent) {
  TipGeometry g{TipShape::blunt_bevel, kR, 0.0, kBevel};
  g.flat_width_m = 50e-6;
  EXPECT_LT(worst_error(mneedle::test::blunt_bevel({}, kBevel, 50e-6), g), 0.01);
}

TEST(CrossSection, ConeMatchesWithinOnePercentAndConverges) {
  TipGeometry g{TipShape::cone, kR};
  g.half_angle_rad = kPi / 12.0;
  ShapeOptions fine;
  fine.segments = 256;
  const double e_coarse = worst_error(mneedle::test::cone({}, kPi / 12.0), g);
  const double e_fine = worst_error(mneedle::test::cone(fine, kPi / 12.0), g);
  EXPECT_LT(e_coarse, 0.01);
  EXPECT_LT(e_fine, e_coarse);
}

// The built-in plugins' meshes at their default resolution against the same closed forms.
class PluginSections : public ::testing::Test {
 protected:
  void SetUp() override {
    registry_ = mneedle::PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
    for (const char* name : {"cylinder", "cone", "sharp_bevel", "blunt_bevel"}) {
      bool found = false;
      for (const auto& shape : registry_.shapes()) found = found || shape.name == name;
      if (!found) GTEST_SKIP() << "built-in plugin '" << name << "' not built";
    }
  }
  double error(const std::string& shape, std::map<std::string, double> p, const TipGeometry& g) {
    p["diameter"] = 2.0 * kR;
    p["bore"] = 2.0 * g.bore_radius_m;
    return worst_error(registry_.generate(shape, p), g);
  }
  mneedle::PluginRegistry registry_;
};

TEST_F(PluginSections, EveryBuiltInShapeMatchesItsClosedFormWithinOnePercent) {
  EXPECT_LT(error("cylinder", {}, {TipShape::cylinder, kR, 45e-6}), 0.01);
  EXPECT_LT(
      error("sharp_bevel", {{"bevel_angle", kBevel}}, {TipShape::sharp_bevel, kR, 0.0, kBevel}),
      0.01);
  EXPECT_LT(
      error("sharp_bevel", {{"bevel_angle", kBevel}}, {TipShape::sharp_bevel, kR, 45e-6, kBevel}),
      0.01);
  EXPECT_LT(error("blunt_bevel", {{"bevel_angle", kBevel}, {"flat_width", 50e-6}},
                  {TipShape::blunt_bevel, kR, 0.0, kBevel, 50e-6}),
            0.01);
  TipGeometry cone{TipShape::cone, kR};
  cone.half_angle_rad = kPi / 12.0;
  EXPECT_LT(error("cone", {{"half_angle", kPi / 12.0}, {"tip_radius", 0.0}}, cone), 0.01);
}

TEST(CrossSection, AboveTheNeedleThereIsNothing) {
  EXPECT_DOUBLE_EQ(mneedle::cross_section(mneedle::test::cylinder({}), 5e-3).area_m2, 0.0);
}

}  // namespace
