#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "shape_kit.h"
#include "shape_kit_test_support.h"

namespace mneedle::shape_kit {
namespace {

constexpr double kPi = std::numbers::pi;

CutPrism creased_prism(double bore) {
  CutPrism p;
  p.outer_radius_m = 1.0;
  p.bore_radius_m = bore;
  p.segments = 32;
  p.top_z_m = 10.0;
  p.creases_x_m = {0.3};
  p.bottom_z_m = [](double x) { return std::max(0.0, 0.3 - x); };
  return p;
}

double polygon_area(double r, int n) {
  return n / 2.0 * r * r * std::sin(2 * kPi / n);
}

TEST(ShapeKitCutPrism, FlatPrismIsClosedWithThePolygonVolume) {
  CutPrism p;
  p.outer_radius_m = 2.0;
  p.bore_radius_m = 1.0;
  p.segments = 12;
  p.top_z_m = 3.0;
  p.bottom_z_m = [](double) { return 0.0; };
  const MeshBuilder mesh = build_cut_prism(p);
  EXPECT_TRUE(closed_and_consistent(mesh));
  EXPECT_NEAR(mesh.signed_volume(), (polygon_area(2, 12) - polygon_area(1, 12)) * 3, 1e-12);
}

TEST(ShapeKitCutPrism, CreasedBottomIsClosedSolidAndHollow) {
  for (const double bore : {0.0, 0.2, 0.6}) {
    const MeshBuilder mesh = build_cut_prism(creased_prism(bore));
    EXPECT_TRUE(closed_and_consistent(mesh)) << "bore " << bore;
    EXPECT_GT(mesh.signed_volume(), 0) << "bore " << bore;
  }
}

// No bottom triangle may straddle the crease, or it would not lie on the cut surface.
TEST(ShapeKitCutPrism, EveryBottomTriangleLiesOnOneSideOfTheCrease) {
  const MeshBuilder mesh = build_cut_prism(creased_prism(0.6));
  const auto& v = mesh.vertices();
  for (const auto& t : mesh.triangles()) {
    if (v[t[0]].z >= 10 || v[t[1]].z >= 10 || v[t[2]].z >= 10) continue;
    const bool low = std::all_of(t.begin(), t.end(), [&](auto i) { return v[i].x <= 0.3 + 1e-9; });
    const bool high = std::all_of(t.begin(), t.end(), [&](auto i) { return v[i].x >= 0.3 - 1e-9; });
    EXPECT_TRUE(low || high);
  }
}

TEST(ShapeKitCutPrism, CreaseMeetsTheRimAtACorner) {
  const MeshBuilder mesh = build_cut_prism(creased_prism(0));
  const double y = std::sqrt(1 - 0.09);
  const auto& v = mesh.vertices();
  const bool found = std::any_of(v.begin(), v.end(), [&](const Point3& p) {
    return std::abs(p.x - 0.3) < 1e-9 && std::abs(p.y - y) < 1e-9 && std::abs(p.z) < 1e-9;
  });
  EXPECT_TRUE(found);
}

TEST(ShapeKitCutPrism, RefusesABoreAsWideAsTheNeedleAndACutAboveTheTop) {
  CutPrism wide = creased_prism(1.0);
  EXPECT_THROW(build_cut_prism(wide), ParameterError);
  CutPrism tall = creased_prism(0);
  tall.top_z_m = 1.0;  // bottom reaches 1.3 at x = -1
  EXPECT_THROW(build_cut_prism(tall), ParameterError);
}

}  // namespace
}  // namespace mneedle::shape_kit
