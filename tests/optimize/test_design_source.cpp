// Where a needle comes from and what its shape lets the pre-puncture model reduce. The symmetry
// is taken in one place for every command: a cylinder STL once ran `screen` on a half model while
// `simulate` solved its quarter (the same numbers to round-off, at twice the cost).
#include "mneedle/design_source.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"

namespace {

const std::string kRoot = MNEEDLE_SOURCE_ROOT;

class DesignSource : public ::testing::Test {
 protected:
  void SetUp() override {
    registry_ = mneedle::PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
  }
  mneedle::PluginRegistry registry_;
};

void expect_symmetry(const mneedle::NeedleSymmetry& s, bool profile, bool y0, bool x0) {
  EXPECT_EQ(s.axisymmetric.has_value(), profile);
  EXPECT_EQ(s.mirror_y0, y0);
  EXPECT_EQ(s.mirror_x0, x0);
}

TEST_F(DesignSource, ABodyOfRevolutionPluginHasItsProfileAndBothMirrorPlanes) {
  const auto cylinder = mneedle::needle_from_plugin(registry_, "cylinder", {});
  expect_symmetry(mneedle::needle_symmetry(registry_, cylinder, "cylinder"), true, true, true);
}

TEST_F(DesignSource, ABevelIsSymmetricAboutItsYZeroPlaneOnly) {
  const auto bevel = mneedle::needle_from_plugin(registry_, "sharp_bevel", {});
  expect_symmetry(mneedle::needle_symmetry(registry_, bevel, "sharp_bevel"), false, true, false);
}

TEST_F(DesignSource, ACylinderStlHasItsFacetsProfileAndBothMirrorPlanes) {
  // A round mesh takes the axisymmetric model as the plugin it was written from does, so the
  // STL and the plugin give one number (design_source.h, revolution_profile). Its facets are
  // symmetric about both planes too, for the 3-D model's quarter when it is forced.
  const auto stl = mneedle::needle_from_file(kRoot + "/designs/cylinder.stl", 1e-3);
  const auto symmetry = mneedle::needle_symmetry(registry_, stl, "cylinder.stl");
  expect_symmetry(symmetry, true, true, true);
  // A flat punch of the faceted circle's equal-area radius: the plugin's 115 um shaft as 64
  // facets, r = R sqrt((64 / 2 pi) sin(2 pi / 64)) = 0.99920 R (to the file's single precision).
  const auto plugin = mneedle::needle_symmetry(
      registry_, mneedle::needle_from_plugin(registry_, "cylinder", {}), "cylinder");
  ASSERT_TRUE(plugin.axisymmetric.has_value());
  const double R = plugin.axisymmetric->max_radius();
  const double expected =
      R * std::sqrt(64.0 / (2.0 * std::numbers::pi) * std::sin(2.0 * std::numbers::pi / 64.0));
  EXPECT_NEAR(symmetry.axisymmetric->max_radius(), expected, 1e-5 * R);
  EXPECT_EQ(symmetry.axisymmetric->heights_m, plugin.axisymmetric->heights_m);  // a flat punch
}

TEST_F(DesignSource, AConeStlHasAProfileThatNarrowsToItsTip) {
  const auto stl = mneedle::needle_from_file(kRoot + "/designs/cone.stl", 1e-3);
  const auto profile = mneedle::revolution_profile(stl.mesh);
  ASSERT_TRUE(profile.has_value());
  EXPECT_LT(profile->radii_m.front(), 0.1 * profile->max_radius());
  for (std::size_t i = 1; i < profile->radii_m.size(); ++i)
    EXPECT_GE(profile->radii_m[i], profile->radii_m[i - 1]);
}

TEST_F(DesignSource, ABevelOrAMeshThatIsNotRoundHasNoProfile) {
  const auto bevel = mneedle::needle_from_file(kRoot + "/designs/sharp_bevel.stl", 1e-3);
  EXPECT_FALSE(mneedle::revolution_profile(bevel.mesh).has_value());
  // The cylinder with one vertex of a ring pushed out by 1 % of the radius.
  auto stl = mneedle::needle_from_file(kRoot + "/designs/cylinder.stl", 1e-3);
  ASSERT_TRUE(mneedle::revolution_profile(stl.mesh).has_value());
  for (auto& v : stl.mesh.vertices) {
    if (std::hypot(v[0], v[1]) > 0.0) {
      v[0] *= 1.01;
      v[1] *= 1.01;
      break;
    }
  }
  EXPECT_FALSE(mneedle::revolution_profile(stl.mesh).has_value());
}

TEST_F(DesignSource, SimulatesPreparedNeedlesCarryTheirSymmetry) {
  // simulate's path (prepare_needles): a cylinder plugin has its profile and both planes, a bevel
  // plugin its y = 0 plane only; screen's path gives the same (tests above, and test_screening).
  const auto cylinder = mneedle::prepare_needles(
      registry_, mneedle::load_scene(kRoot + "/designs/scenes/paper_a_silicone_cylinder.toml"), 16);
  ASSERT_EQ(cylinder.size(), 1u);
  EXPECT_TRUE(cylinder[0].axisymmetric.has_value());
  EXPECT_TRUE(cylinder[0].mirror_symmetric_y0);
  EXPECT_TRUE(cylinder[0].mirror_symmetric_x0);
  const auto bevel = mneedle::prepare_needles(
      registry_, mneedle::load_scene(kRoot + "/designs/scenes/human_skin.toml"), 16);
  ASSERT_EQ(bevel.size(), 1u);
  EXPECT_FALSE(bevel[0].axisymmetric.has_value());
  EXPECT_TRUE(bevel[0].mirror_symmetric_y0);
  EXPECT_FALSE(bevel[0].mirror_symmetric_x0);
}

}  // namespace
