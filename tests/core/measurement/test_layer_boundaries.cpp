#include "mneedle/measurement/layer_boundaries.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "mneedle/base/error.h"

namespace {

// Continuous force with slopes 100, 400 and 50 N/m, boundaries at 5 mm and 12 mm, plus noise:
// a cortex / medulla / calyx–like curve as in paper B's kidney.
void three_layers(std::vector<double>& depth, std::vector<double>& force) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i <= 2000; ++i) {
    const double z = 20e-3 * i / 2000.0;
    double f = 100.0 * std::min(z, 5e-3);
    if (z > 5e-3) f += 400.0 * (std::min(z, 12e-3) - 5e-3);
    if (z > 12e-3) f += 50.0 * (z - 12e-3);
    depth.push_back(z);
    force.push_back(f + noise(random));
  }
}

TEST(LayerBoundaries, ThreeSegmentsFindBothSlopeChanges) {
  std::vector<double> z, f;
  three_layers(z, f);
  const auto s = mneedle::segment_by_slope(z, f, 3);
  ASSERT_EQ(s.boundaries_m.size(), 2u);
  EXPECT_NEAR(s.boundaries_m[0], 5e-3, 0.2e-3);
  EXPECT_NEAR(s.boundaries_m[1], 12e-3, 0.2e-3);
  EXPECT_NEAR(s.slopes_N_per_m[0], 100.0, 5.0);
  EXPECT_NEAR(s.slopes_N_per_m[1], 400.0, 10.0);
  EXPECT_NEAR(s.slopes_N_per_m[2], 50.0, 5.0);
}

TEST(LayerBoundaries, InformationCriterionChoosesThreeLayers) {
  std::vector<double> z, f;
  three_layers(z, f);
  const auto b = mneedle::detect_layer_boundaries(z, f, 5);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_NEAR(b[0], 5e-3, 0.2e-3);
  EXPECT_NEAR(b[1], 12e-3, 0.2e-3);
}

TEST(LayerBoundaries, StraightLineHasNoBoundary) {
  std::vector<double> z, f;
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i <= 1000; ++i) {
    z.push_back(1e-5 * i);
    f.push_back(200.0 * z.back() + noise(random));
  }
  EXPECT_TRUE(mneedle::detect_layer_boundaries(z, f, 4).empty());
}

TEST(LayerBoundaries, TooShortCurveIsAnInputError) {
  const std::vector<double> z{0.0, 1e-3, 2e-3, 3e-3}, f{0.0, 1.0, 2.0, 3.0};
  EXPECT_THROW(mneedle::segment_by_slope(z, f, 2), mneedle::InputError);
}

}  // namespace
