#include "mneedle/measurement/curve_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mneedle/base/error.h"

namespace {

TEST(CurveMetrics, MatchHandComputedValues) {
  // measured mean 2.5, SS_tot = 5; errors 0.1, -0.2, 0, 0.3: SS_res = 0.14.
  const std::vector<double> measured{1.0, 2.0, 3.0, 4.0};
  const std::vector<double> predicted{0.9, 2.2, 3.0, 3.7};
  const auto m = mneedle::compare_curves(measured, predicted);
  EXPECT_NEAR(m.rmse_N, std::sqrt(0.14 / 4.0), 1e-12);
  EXPECT_NEAR(m.r2, 1.0 - 0.14 / 5.0, 1e-12);
  EXPECT_NEAR(m.max_error_N, 0.3, 1e-12);
  EXPECT_EQ(m.samples, 4u);
}

TEST(CurveMetrics, PredictingTheMeanGivesZeroR2) {
  const std::vector<double> measured{1.0, 2.0, 3.0};
  const std::vector<double> mean(3, 2.0);
  EXPECT_NEAR(mneedle::compare_curves(measured, mean).r2, 0.0, 1e-12);
}

TEST(CurveMetrics, ConstantCurveGivesFiniteR2) {
  const std::vector<double> flat(3, 1.0), off(3, 1.5);
  EXPECT_EQ(mneedle::compare_curves(flat, flat).r2, 1.0);
  EXPECT_EQ(mneedle::compare_curves(flat, off).r2, 0.0);
}

TEST(CurveMetrics, DifferentLengthsAreRejected) {
  const std::vector<double> a{1.0, 2.0}, b{1.0};
  EXPECT_THROW(mneedle::compare_curves(a, b), mneedle::InputError);
}

}  // namespace
