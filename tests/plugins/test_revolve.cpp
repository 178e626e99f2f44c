#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "shape_kit.h"
#include "shape_kit_test_support.h"

namespace mneedle::shape_kit {
namespace {

constexpr double kPi = std::numbers::pi;

double polygon_area(double r, int n) {
  return n / 2.0 * r * r * std::sin(2 * kPi / n);
}

TEST(ShapeKitRevolve, RevolvedRectangleIsAClosedPolygonPrism) {
  const MeshBuilder mesh = build_revolved({{0, 0}, {1, 0}, {1, 2}, {0, 2}}, 16);
  EXPECT_TRUE(closed_and_consistent(mesh));
  EXPECT_NEAR(mesh.signed_volume(), polygon_area(1, 16) * 2, 1e-12);
  EXPECT_EQ(mesh.vertices().size(), 2u + 2 * 16);  // one vertex per axis point
}

TEST(ShapeKitRevolve, OrientedOutwardWhicheverWayTheProfileRuns) {
  const MeshBuilder forward = build_revolved({{0, 0}, {1, 1}, {1, 2}, {0, 2}}, 24);
  const MeshBuilder backward = build_revolved({{0, 2}, {1, 2}, {1, 1}, {0, 0}}, 24);
  EXPECT_GT(forward.signed_volume(), 0);
  EXPECT_NEAR(forward.signed_volume(), backward.signed_volume(), 1e-12);
}

TEST(ShapeKitRevolve, ProfileOffTheAxisMakesAClosedTube) {
  const MeshBuilder mesh = build_revolved({{0.5, 0}, {1, 0}, {1, 3}, {0.5, 3}}, 20);
  EXPECT_TRUE(closed_and_consistent(mesh));
  EXPECT_NEAR(mesh.signed_volume(), (polygon_area(1, 20) - polygon_area(0.5, 20)) * 3, 1e-12);
}

TEST(ShapeKitRevolve, RefusesTooFewSegments) {
  EXPECT_THROW(build_revolved({{0, 0}, {1, 0}, {0, 1}}, 2), ParameterError);
}

}  // namespace
}  // namespace mneedle::shape_kit
