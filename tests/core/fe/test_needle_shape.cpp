// The rigid needle's surface queries (core/src/fe/needle_shape.cpp): where it first touches a
// flat surface.
#include "fe/needle_shape.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "needle_meshes.h"

namespace {

using mneedle::fe::NeedleShape;

// Twice the signed area of a closed polygon: positive when counter-clockwise.
double twice_signed_area(const std::vector<Eigen::Vector2d>& p) {
  double sum = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector2d& a = p[i];
    const Eigen::Vector2d& b = p[(i + 1) % p.size()];
    sum += a.x() * b.y() - a.y() * b.x();
  }
  return sum;
}

TEST(NeedleShape, APointedTipFirstTouchesAtOnePoint) {
  const double radius = 115e-6;
  const NeedleShape cone(mneedle::test::cone_needle(15.0 * std::numbers::pi / 180.0, radius, 1e-3));
  const auto at_apex = cone.first_contact_outline(1e-9);
  ASSERT_EQ(at_apex.size(), 1u);
  EXPECT_LT(at_apex.front().norm(), 1e-15);
  // A bevel's tip lies on its rim, where the first-contact point says it is.
  const NeedleShape bevel(mneedle::test::bevel_needle(radius, std::numbers::pi / 6.0, 1e-3));
  const auto at_rim = bevel.first_contact_outline(1e-9);
  ASSERT_EQ(at_rim.size(), 1u);
  EXPECT_NEAR(at_rim.front().x(), -radius, 1e-12);
  EXPECT_NEAR(at_rim.front().y(), 0.0, 1e-12);
  EXPECT_LT((at_rim.front() - bevel.first_contact_xy(1e-9)).norm(), 1e-15);
}

// A flat end touches over its whole face: the hull of its lowest vertices is the rim's polygon
// (48 segments), counter-clockwise, with the polygon's area.
TEST(NeedleShape, AFlatEndFirstTouchesOverItsRimPolygon) {
  const double radius = 115e-6;
  const int segments = 48;
  const NeedleShape cylinder(mneedle::test::cylinder_needle(radius, 1e-3, segments));
  const auto outline = cylinder.first_contact_outline(1e-9);
  ASSERT_EQ(outline.size(), static_cast<std::size_t>(segments));
  for (const Eigen::Vector2d& p : outline) EXPECT_NEAR(p.norm(), radius, 1e-15);
  const double polygon =
      0.5 * segments * radius * radius * std::sin(2 * std::numbers::pi / segments);
  EXPECT_NEAR(0.5 * twice_signed_area(outline), polygon, 1e-12 * polygon);
}

// A flat end has faces among its lowest vertices; a point (cone, bevel) has none: the 3-D
// planner takes a narrow set of lowest vertices without a face for one rounded point
// (docs/model.md, "Tissue block and mesh").
TEST(NeedleShape, OnlyAFlatEndHasAFaceAtItsFirstContact) {
  const double radius = 115e-6;
  EXPECT_TRUE(
      NeedleShape(mneedle::test::cylinder_needle(radius, 1e-3, 48)).first_contact_has_a_face(1e-9));
  EXPECT_FALSE(
      NeedleShape(mneedle::test::cone_needle(15.0 * std::numbers::pi / 180.0, radius, 1e-3))
          .first_contact_has_a_face(1e-9));
  EXPECT_FALSE(NeedleShape(mneedle::test::bevel_needle(radius, std::numbers::pi / 6.0, 1e-3))
                   .first_contact_has_a_face(1e-9));
}

}  // namespace
