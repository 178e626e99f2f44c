// Bounded least squares: the answer, its standard errors and correlations against the closed
// form of a straight-line fit, the bounds, and the at-bound flag in log space.

#include "mneedle/measurement/bounded_least_squares.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

struct Line {
  std::vector<double> x, y;
};

Line noisy_line(double a, double b, int n) {
  Line l;
  std::mt19937 random(5u);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int i = 0; i < n; ++i) {
    l.x.push_back(i / static_cast<double>(n - 1));
    l.y.push_back(a + b * l.x.back() + noise(random));
  }
  return l;
}

ResidualVector residuals_of(const Line& l) {
  return [&l](const std::vector<double>& p) {
    std::vector<double> r;
    for (std::size_t i = 0; i < l.x.size(); ++i) r.push_back(l.y[i] - p[0] - p[1] * l.x[i]);
    return r;
  };
}

// Ordinary least squares in closed form: the fit and s^2 (X^T X)^-1 (the model is linear, so the
// Jacobian is exact and the optimiser's answer agrees to its tolerance, 1e-6 relative).
TEST(BoundedLeastSquares, StraightLineMatchesOrdinaryLeastSquaresAndItsErrors) {
  const Line l = noisy_line(0.3, 2.0, 50);
  const BoundedFit fit = fit_bounded(residuals_of(l), {1.0, 1.0}, {{-10, 10}, {-10, 10}});
  const double n = static_cast<double>(l.x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < l.x.size(); ++i) {
    sx += l.x[i];
    sy += l.y[i];
    sxx += l.x[i] * l.x[i];
    sxy += l.x[i] * l.y[i];
  }
  const double det = n * sxx - sx * sx;
  const double b = (n * sxy - sx * sy) / det, a = (sy - b * sx) / n;
  EXPECT_NEAR(fit.x[0], a, 1e-6);
  EXPECT_NEAR(fit.x[1], b, 1e-6);
  double ssr = 0;
  for (std::size_t i = 0; i < l.x.size(); ++i) ssr += std::pow(l.y[i] - a - b * l.x[i], 2);
  const double s2 = ssr / (n - 2);
  EXPECT_NEAR(fit.standard_error[0], std::sqrt(s2 * sxx / det), 1e-4 * std::sqrt(s2 * sxx / det));
  EXPECT_NEAR(fit.standard_error[1], std::sqrt(s2 * n / det), 1e-4 * std::sqrt(s2 * n / det));
  EXPECT_NEAR(fit.correlation[0][1], -sx / std::sqrt(n * sxx), 1e-4);
  EXPECT_FALSE(fit.at_bound[0] || fit.at_bound[1]);
}

TEST(BoundedLeastSquares, AnOptimumOutsideTheBoxStopsOnItsBoundAndSaysSo) {
  const Line l = noisy_line(0.3, 2.0, 50);
  const BoundedFit fit = fit_bounded(residuals_of(l), {0.0, 0.5}, {{-10, 10}, {0.0, 1.0}});
  EXPECT_LE(fit.x[1], 1.0);
  EXPECT_GT(fit.x[1], 0.999);
  EXPECT_TRUE(fit.at_bound[1]);
}

// A log bound 1e-4..1e4: 0.005 is four decades from the lower end, not at it.
TEST(BoundedLeastSquares, AtBoundIsJudgedInLogSpaceForALogBound) {
  const std::vector<double> y{0.005, 0.005, 0.005};
  const ResidualVector r = [&y](const std::vector<double>& p) {
    std::vector<double> out;
    for (double v : y) out.push_back(v - p[0]);
    return out;
  };
  const BoundedFit fit = fit_bounded(r, {1.0}, {{1e-4, 1e4, true}});
  EXPECT_NEAR(fit.x[0], 0.005, 1e-8);
  EXPECT_FALSE(fit.at_bound[0]);
}

TEST(BoundedLeastSquares, BadBoundsAndTooFewResidualsAreInputErrors) {
  const Line l = noisy_line(0.3, 2.0, 2);
  EXPECT_THROW(fit_bounded(residuals_of(l), {1.0, 1.0}, {{-10, 10}, {-10, 10}}), InputError);
  const Line ok = noisy_line(0.3, 2.0, 10);
  EXPECT_THROW(fit_bounded(residuals_of(ok), {1.0}, {{-10, 10}, {-10, 10}}), InputError);
  EXPECT_THROW(fit_bounded(residuals_of(ok), {1.0, 1.0}, {{1, -1}, {-10, 10}}), InputError);
  EXPECT_THROW(fit_bounded(residuals_of(ok), {1.0, 1.0}, {{0, 1, true}, {-10, 10}}), InputError);
}

}  // namespace
}  // namespace mneedle
