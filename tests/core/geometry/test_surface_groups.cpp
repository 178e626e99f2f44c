#include "mneedle/geometry/surface_groups.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/plugin_host.h"
#include "needle_shapes.h"

namespace {

using mneedle::SurfaceGroup;
using mneedle::test::ShapeOptions;
constexpr double kPi = std::numbers::pi;
constexpr double kRadius = 115e-6;

double polygon_area(int n, double r) {
  return 0.5 * n * r * r * std::sin(2.0 * kPi / n);
}

TEST(SurfaceGroups, CylinderEndIsAlphaAndShaftIsSide) {
  const ShapeOptions o;
  const auto groups = mneedle::classify_surface(mneedle::test::cylinder(o));
  EXPECT_NEAR(groups.of(SurfaceGroup::alpha).area_m2, polygon_area(o.segments, kRadius), 1e-15);
  EXPECT_NEAR(groups.of(SurfaceGroup::alpha).area_m2, kPi * kRadius * kRadius,
              0.01 * kPi * kRadius * kRadius);
  EXPECT_EQ(groups.of(SurfaceGroup::alpha).count, 64u);
  EXPECT_EQ(groups.of(SurfaceGroup::beta).count, 0u);
  EXPECT_EQ(groups.of(SurfaceGroup::back).count, 64u);
  EXPECT_EQ(groups.of(SurfaceGroup::side).count, 64u * 8u * 2u);
}

TEST(SurfaceGroups, HollowCylinderEndIsTheAnnulus) {
  ShapeOptions o;
  o.bore = 45e-6;
  const auto groups = mneedle::classify_surface(mneedle::test::cylinder(o));
  const double annulus = polygon_area(o.segments, kRadius) - polygon_area(o.segments, o.bore);
  EXPECT_NEAR(groups.of(SurfaceGroup::alpha).area_m2, annulus, 1e-15);
  EXPECT_EQ(groups.of(SurfaceGroup::beta).count, 0u);
}

TEST(SurfaceGroups, ConeSlopeIsBetaWithAreaPiRTimesSlant) {
  const ShapeOptions o;
  const double half_angle = 15.0 * kPi / 180.0;
  const auto groups = mneedle::classify_surface(mneedle::test::cone(o, half_angle));
  const double slant = kRadius / std::sin(half_angle);
  EXPECT_NEAR(groups.of(SurfaceGroup::beta).area_m2, kPi * kRadius * slant,
              0.01 * kPi * kRadius * slant);
  EXPECT_EQ(groups.of(SurfaceGroup::alpha).count, 0u);
}

TEST(SurfaceGroups, OneDegreeConeStillHasBetaFaces) {
  const ShapeOptions o;
  const auto groups = mneedle::classify_surface(mneedle::test::cone(o, 1.0 * kPi / 180.0));
  // Every slope face: the apex fan and two triangles per band between the four cone rings.
  EXPECT_EQ(groups.of(SurfaceGroup::beta).count, 64u + 3u * 128u);
}

TEST(SurfaceGroups, SharpBevelFaceIsBetaWithTheEllipseArea) {
  const ShapeOptions o;
  const double bevel = 30.0 * kPi / 180.0;
  const auto groups = mneedle::classify_surface(mneedle::test::sharp_bevel(o, bevel));
  const double ellipse = kPi * kRadius * kRadius / std::sin(bevel);
  EXPECT_NEAR(groups.of(SurfaceGroup::beta).area_m2, ellipse, 0.01 * ellipse);
  EXPECT_EQ(groups.of(SurfaceGroup::alpha).count, 0u);
}

TEST(SurfaceGroups, BluntBevelFlatIsAlphaWithTheSegmentArea) {
  const ShapeOptions o;
  const double w = 50e-6;
  const auto groups =
      mneedle::classify_surface(mneedle::test::blunt_bevel(o, 30.0 * kPi / 180.0, w));
  const double b = kRadius - w;
  const double segment =
      kRadius * kRadius * std::acos(b / kRadius) - b * std::sqrt(kRadius * kRadius - b * b);
  EXPECT_NEAR(groups.of(SurfaceGroup::alpha).area_m2, segment, 0.01 * segment);
  EXPECT_GT(groups.of(SurfaceGroup::beta).count, 0u);
}

TEST(SurfaceGroups, FaceExactlyOnTheSideThresholdIsSide) {
  mneedle::GroupTolerances tol;
  tol.side_rad = 0.1;
  const mneedle::Vec3 d{0, 0, -1};
  const mneedle::Vec3 on_threshold{std::cos(0.1), 0.0, -std::sin(0.1)};
  EXPECT_EQ(mneedle::classify_normal(on_threshold, d, tol), SurfaceGroup::side);
  const mneedle::Vec3 beyond{std::cos(0.1001), 0.0, -std::sin(0.1001)};
  EXPECT_EQ(mneedle::classify_normal(beyond, d, tol), SurfaceGroup::beta);
}

TEST(SurfaceGroups, ClassificationIsInvariantUnderRigidMotion) {
  const ShapeOptions o;
  const auto needle = mneedle::test::blunt_bevel(o, 25.0 * kPi / 180.0, 40e-6);
  const mneedle::Vec3 axis{0.6, 0.0, 0.8};
  const double angle = 1.1;
  const auto moved = mneedle::test::moved(needle, axis, angle, {3e-3, -2e-3, 7e-3});
  const auto d = mneedle::test::rigid_motion({0, 0, -1}, axis, angle, {0, 0, 0});
  const auto a = mneedle::classify_surface(needle);
  const auto b = mneedle::classify_surface(moved, d);
  EXPECT_EQ(a.face_group, b.face_group);
  for (std::size_t g = 0; g < 4; ++g) {
    EXPECT_NEAR(a.summary[g].area_m2, b.summary[g].area_m2, 1e-12 * (a.summary[g].area_m2 + 1e-12));
  }
}

// The built-in plugins' meshes, when they are built: the same hand areas as the test meshes.
class PluginShapes : public ::testing::Test {
 protected:
  void SetUp() override {
    registry_ = mneedle::PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
    for (const char* name : {"cylinder", "cone", "sharp_bevel", "blunt_bevel"}) {
      bool found = false;
      for (const auto& shape : registry_.shapes()) found = found || shape.name == name;
      if (!found) GTEST_SKIP() << "built-in plugin '" << name << "' not built";
    }
  }
  mneedle::SurfaceGroups groups(const std::string& shape, std::map<std::string, double> p) {
    p["diameter"] = 2.0 * kRadius;
    return mneedle::classify_surface(registry_.generate(shape, p));
  }
  mneedle::PluginRegistry registry_;
};

TEST_F(PluginShapes, HollowCylinderEndIsTheAnnulus) {
  const auto g = groups("cylinder", {{"bore", 90e-6}});
  const double annulus = kPi * (kRadius * kRadius - 45e-6 * 45e-6);
  EXPECT_NEAR(g.of(SurfaceGroup::alpha).area_m2, annulus, 0.01 * annulus);
  EXPECT_EQ(g.of(SurfaceGroup::beta).count, 0u);
}

TEST_F(PluginShapes, ConeSlopeIsBetaWithAreaPiRTimesSlant) {
  const double half_angle = 15.0 * kPi / 180.0;
  const auto g = groups("cone", {{"half_angle", half_angle}, {"tip_radius", 0.0}});
  const double lateral = kPi * kRadius * kRadius / std::sin(half_angle);
  EXPECT_NEAR(g.of(SurfaceGroup::beta).area_m2, lateral, 0.01 * lateral);
  EXPECT_NEAR(g.of(SurfaceGroup::alpha).area_m2, 0.0, 1e-3 * lateral);
}

TEST_F(PluginShapes, SharpBevelFaceIsTheEllipse) {
  const double bevel = 30.0 * kPi / 180.0;
  const auto g = groups("sharp_bevel", {{"bevel_angle", bevel}});
  const double ellipse = kPi * kRadius * kRadius / std::sin(bevel);
  EXPECT_NEAR(g.of(SurfaceGroup::beta).area_m2, ellipse, 0.01 * ellipse);
  EXPECT_EQ(g.of(SurfaceGroup::alpha).count, 0u);
}

TEST_F(PluginShapes, BluntBevelFlatIsAlpha) {
  const double w = 50e-6;
  const auto g = groups("blunt_bevel", {{"bevel_angle", 30.0 * kPi / 180.0}, {"flat_width", w}});
  const double b = kRadius - w;
  const double segment =
      kRadius * kRadius * std::acos(b / kRadius) - b * std::sqrt(kRadius * kRadius - b * b);
  EXPECT_NEAR(g.of(SurfaceGroup::alpha).area_m2, segment, 0.01 * segment);
}

TEST(SurfaceGroups, ZeroDirectionIsAnInputError) {
  EXPECT_THROW(mneedle::classify_surface(mneedle::test::cylinder({}), {0, 0, 0}),
               mneedle::InputError);
}

}  // namespace
