// Which needles a model reduced by its mirror planes keeps, and how their results stand in for
// the needles it drops.

#include "fe/mirror_planes.h"

#include <gtest/gtest.h>

#include <numbers>

#include "mneedle/base/error.h"
#include "needle_meshes.h"

namespace {

using namespace mneedle::fe;
using mneedle::test::bevel_needle;
using mneedle::test::cone_needle;

std::vector<Needle3d> two_by_two_cones() {
  const auto cone = cone_needle(std::numbers::pi / 6, 60e-6, 1e-3);
  return {{"a", cone, -200e-6, -150e-6},
          {"b", cone, 200e-6, -150e-6},
          {"c", cone, -200e-6, 150e-6},
          {"d", cone, 200e-6, 150e-6}};
}

TEST(MirrorPlanes, QuarterOfATwoByTwoArrayKeepsOneNeedleAndMapsEveryOtherOntoIt) {
  const MirrorSelection s = select_mirrored_part(two_by_two_cones(), true, true);
  ASSERT_EQ(s.kept.size(), 1U);
  EXPECT_EQ(s.kept[0].name, "d");
  EXPECT_EQ(s.source, (std::vector<std::size_t>{0, 0, 0, 0}));
  EXPECT_EQ(s.lateral_sign[0], Eigen::Vector2d(-1.0, -1.0));
  EXPECT_EQ(s.lateral_sign[1], Eigen::Vector2d(1.0, -1.0));
  EXPECT_EQ(s.lateral_sign[2], Eigen::Vector2d(-1.0, 1.0));
  EXPECT_EQ(s.lateral_sign[3], Eigen::Vector2d(1.0, 1.0));
}

TEST(MirrorPlanes, HalfOfTheArrayKeepsTheNeedlesOnTheKeptSideInSceneOrder) {
  const MirrorSelection s = select_mirrored_part(two_by_two_cones(), false, true);
  ASSERT_EQ(s.kept.size(), 2U);
  EXPECT_EQ(s.kept[0].name, "c");
  EXPECT_EQ(s.kept[1].name, "d");
  EXPECT_EQ(s.kept_from, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(s.source, (std::vector<std::size_t>{0, 1, 0, 1}));
}

TEST(MirrorPlanes, WholeSceneStepNamesEveryNeedleAndFlipsTheMirroredLateralForces) {
  const std::vector<Needle3d> needles = two_by_two_cones();
  const MirrorSelection s = select_mirrored_part(needles, true, true);
  Step3d reduced;
  reduced.depth_m = 10e-6;
  reduced.strain_energy_J = 3e-9;
  NeedleStep3d d;
  d.name = "d";
  d.force_N = 2e-3;
  d.lateral_force_N = {1e-4, 5e-5};
  reduced.needles = {d};
  const Step3d whole = whole_scene_step(reduced, s, needles);
  ASSERT_EQ(whole.needles.size(), 4U);
  EXPECT_EQ(whole.strain_energy_J, 3e-9);
  EXPECT_EQ(whole.needles[0].name, "a");
  EXPECT_EQ(whole.needles[0].force_N, 2e-3);
  EXPECT_EQ(whole.needles[0].lateral_force_N[0], -1e-4);
  EXPECT_EQ(whole.needles[0].lateral_force_N[1], -5e-5);
  EXPECT_EQ(whole.needles[1].lateral_force_N[0], 1e-4);
  EXPECT_EQ(whole.needles[1].lateral_force_N[1], -5e-5);
}

TEST(MirrorPlanes, NeedleWithoutATwinOrNotSymmetricIsAnInputError) {
  std::vector<Needle3d> lonely = two_by_two_cones();
  lonely.pop_back();  // "c" has no image across x = 0 any more, "b" none across y = 0
  EXPECT_THROW(select_mirrored_part(lonely, true, false), mneedle::InputError);
  EXPECT_THROW(select_mirrored_part(lonely, false, true), mneedle::InputError);
  std::vector<Needle3d> other = two_by_two_cones();
  other[0].mesh = cone_needle(std::numbers::pi / 5, 60e-6, 1e-3);  // a's twin differs
  EXPECT_THROW(select_mirrored_part(other, true, true), mneedle::InputError);
  // A bevel is symmetric about its y = 0 plane, not its x = 0 plane.
  const std::vector<Needle3d> bevel{{"bevel", bevel_needle(60e-6, std::numbers::pi / 6, 1e-3)}};
  EXPECT_NO_THROW(select_mirrored_part(bevel, false, true));
  EXPECT_THROW(select_mirrored_part(bevel, true, false), mneedle::InputError);
}

}  // namespace
