// The jump in cross-section where a needle's holder begins, and the cut that keeps the needle.

#include "mneedle/geometry/holder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fe/needle_meshes.h"
#include "mneedle/geometry/cross_section.h"
#include "needle_shapes.h"

namespace mneedle {
namespace {

constexpr double kRadius = 150e-6;
constexpr double kLength = 1e-3;

// A cone (15 deg half-angle) to its full radius, a shaft to 1 mm, then a holder 2.5 mm in radius
// and 1 mm thick: one closed body of revolution, as CAD exports a needle on its base.
TriangleMesh needle_on_holder(double holder_radius = 2.5e-3) {
  const double cone = kRadius / std::tan(std::numbers::pi / 12.0);
  std::vector<std::array<double, 2>> rings{{0.0, 0.0}};
  for (int k = 1; k <= 8; ++k) rings.push_back({kRadius * k / 8.0, cone * k / 8.0});
  rings.push_back({kRadius, kLength});
  rings.push_back({holder_radius, kLength});
  rings.push_back({holder_radius, kLength + 1e-3});
  return test::revolved_needle(rings, 48);
}

double top(const TriangleMesh& mesh) {
  double z = -1.0;
  for (const Vec3& p : mesh.vertices) z = std::max(z, p[2]);
  return z;
}

// The jump is bisected to 1e-9 of the mesh's height: 2 nm here.
TEST(Holder, JumpIsFoundWhereTheHolderBegins) {
  const auto jump = find_holder_jump(needle_on_holder());
  ASSERT_TRUE(jump.has_value());
  EXPECT_NEAR(jump->height_m, kLength, 1e-9 * 2e-3 * 2);
  EXPECT_GT(jump->holder_outline_m2 / jump->needle_outline_m2, 100.0);
}

TEST(Holder, TaperedAndBevelledNeedlesAloneHaveNoJump) {
  EXPECT_FALSE(find_holder_jump(test::cone_needle(std::numbers::pi / 12.0, kRadius, kLength)));
  EXPECT_FALSE(find_holder_jump(test::sharp_bevel({}, std::numbers::pi / 6.0)));
  EXPECT_FALSE(find_holder_jump(test::cylinder_needle(kRadius, kLength)));
}

TEST(Holder, CutKeepsTheNeedleClosedAndItsSections) {
  const TriangleMesh mesh = needle_on_holder();
  const TriangleMesh needle = cut_above(mesh, kLength - 1e-9);
  EXPECT_NEAR(top(needle), kLength - 1e-9, 1e-12);
  // The shaft's section survives the cut unchanged.
  const double section = cross_section(needle, 0.9 * kLength).area_m2;
  EXPECT_NEAR(section, cross_section(mesh, 0.9 * kLength).area_m2, 1e-12 * section);
  EXPECT_FALSE(find_holder_jump(needle));
}

}  // namespace
}  // namespace mneedle
