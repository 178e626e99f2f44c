// Where a needle comes from and what its shape lets the pre-puncture model reduce. The symmetry
// is taken in one place for every command: a cylinder STL once ran `screen` on a half model while
// `simulate` solved its quarter (the same numbers to round-off, at twice the cost).
#include "mneedle/design_source.h"

#include <gtest/gtest.h>

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

TEST_F(DesignSource, ACylinderStlHasBothMirrorPlanesButNoProfile) {
  // An STL carries no profile (the axisymmetric model needs the plugin's exact one), but its
  // facets are symmetric about both planes, so the 3-D model may solve a quarter.
  const auto stl = mneedle::needle_from_file(kRoot + "/designs/cylinder.stl", 1e-3);
  expect_symmetry(mneedle::needle_symmetry(registry_, stl, "cylinder.stl"), false, true, true);
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
