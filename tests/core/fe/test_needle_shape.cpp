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

// Sticking contact holds a node on the face that swept over it (docs/model.md, "Contact with
// the rigid needle (sticking)"): under a bevel that is the face right below it. A node pressed
// sideways into the shaft, 88 um above the bevel face (paper A's sharp bevel in neo-Hookean
// silicone at 195.8 um), is held where it entered the wall instead of 88 um lower; the node at
// the tip, on the wall, is held at the tip in both readings.
TEST(NeedleShape, ANodeEnteringTheShaftSidewaysIsHeldWhereItEnteredNotOnTheBevelBelow) {
  const double radius = 115e-6;
  const double slope = 1.0 / std::tan(std::numbers::pi / 6.0);
  const NeedleShape bevel(mneedle::test::bevel_needle(radius, std::numbers::pi / 6.0, 1e-3));
  const double tolerance = 1.15e-6;  // the group length of paper A's needles
  // Just above the bevel face: the face below, 0.1 um down (its vertical projection).
  const Eigen::Vector3d over_face(-50e-6, 0.0, 65e-6 * slope + 0.1e-6);
  const Eigen::Vector3d swept = bevel.sticking_anchor(over_face, over_face, tolerance);
  EXPECT_NEAR(swept.x(), over_face.x(), 1e-12);
  EXPECT_NEAR(swept.z(), 65e-6 * slope, 1e-12);  // round-off of the ray and the face (1e-12 m)
  // Inside the wall on a generator (where the 48-gon has the full radius), 88 um above the face.
  const double angle = 2.0 * std::numbers::pi * 3.0 / 48.0;
  const Eigen::Vector3d side(std::cos(angle), std::sin(angle), 0.0);
  const double face = (radius * side.x() + radius) * slope;
  const Eigen::Vector3d pressed = (radius - 0.2e-6) * side + Eigen::Vector3d(0, 0, face + 88e-6);
  const Eigen::Vector3d entered = (radius - 0.01e-6) * side + Eigen::Vector3d(0, 0, face + 87.9e-6);
  const Eigen::Vector3d held = bevel.sticking_anchor(pressed, entered, tolerance);
  EXPECT_NEAR(held.z(), entered.z(), 1e-9);  // on the wall beside where it entered
  EXPECT_LT((held - entered).norm(), 0.02e-6);
  // The old anchor, the bevel face below: the fan of facets lies up to
  // R (1 - cos(pi/48)) slope = 0.43 um off the plane near the rim.
  EXPECT_NEAR(bevel.lower_surface_below(pressed).z(), face, 0.5e-6);
  // The tip's node on the wall, 10 um up after the first step, entered at the tip.
  const Eigen::Vector3d at_tip(-radius, 0.0, 10e-6);
  const Eigen::Vector3d tip_hold =
      bevel.sticking_anchor(at_tip, Eigen::Vector3d(-radius, 0.0, 0.0), tolerance);
  EXPECT_LT((tip_hold - Eigen::Vector3d(-radius, 0.0, 0.0)).norm(), 1e-12);
}
