#include "mneedle/measurement/layer_boundaries.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Binned {
  std::vector<double> x, y;
};

Binned bin_curve(const std::vector<double>& depth, const std::vector<double>& force,
                 std::size_t bins) {
  if (depth.size() != force.size() || depth.empty()) {
    throw InputError("layer boundaries: depth and force must have the same, non-zero length");
  }
  const auto [lo, hi] = std::minmax_element(depth.begin(), depth.end());
  const double width = (*hi - *lo) / static_cast<double>(std::max<std::size_t>(bins, 1));
  std::vector<double> sx(bins, 0.0), sy(bins, 0.0), n(bins, 0.0);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const auto b =
        width > 0.0 ? std::min(bins - 1, static_cast<std::size_t>((depth[i] - *lo) / width)) : 0;
    sx[b] += depth[i];
    sy[b] += force[i];
    n[b] += 1.0;
  }
  Binned out;
  for (std::size_t b = 0; b < bins; ++b) {
    if (n[b] > 0.0) {
      out.x.push_back(sx[b] / n[b]);
      out.y.push_back(sy[b] / n[b]);
    }
  }
  return out;
}

// Prefix sums give the least-squares line of any run of points in O(1).
class LineCost {
 public:
  explicit LineCost(const Binned& b) : sums_(b.x.size() + 1, {0, 0, 0, 0, 0, 0}) {
    for (std::size_t i = 0; i < b.x.size(); ++i) {
      const double x = b.x[i], y = b.y[i];
      const std::array<double, 6> add{1.0, x, y, x * x, x * y, y * y};
      for (std::size_t k = 0; k < 6; ++k) sums_[i + 1][k] = sums_[i][k] + add[k];
    }
  }
  // Residual sum of squares and slope of points [i, j).
  std::pair<double, double> fit(std::size_t i, std::size_t j) const {
    std::array<double, 6> s{};
    for (std::size_t k = 0; k < 6; ++k) s[k] = sums_[j][k] - sums_[i][k];
    const double n = s[0], sxx = s[3] - s[1] * s[1] / n, sxy = s[4] - s[1] * s[2] / n;
    const double syy = s[5] - s[2] * s[2] / n;
    const double slope = sxx > 0.0 ? sxy / sxx : 0.0;
    return {std::max(0.0, syy - slope * sxy), slope};
  }

 private:
  std::vector<std::array<double, 6>> sums_;
};

SlopeSegmentation segment_binned(const Binned& b, std::size_t segments) {
  const std::size_t n = b.x.size();
  constexpr std::size_t kMinRun = 3;
  if (segments == 0 || n < segments * kMinRun) {
    throw InputError("layer boundaries: " + std::to_string(n) + " depth bins are too few for " +
                     std::to_string(segments) + " segments");
  }
  const LineCost cost(b);
  // best[m][j]: least RSS of m lines over the first j points; from[m][j]: start of the last line.
  std::vector<std::vector<double>> best(segments + 1, std::vector<double>(n + 1, kInfinity));
  std::vector<std::vector<std::size_t>> from(segments + 1, std::vector<std::size_t>(n + 1, 0));
  best[0][0] = 0.0;
  for (std::size_t m = 1; m <= segments; ++m) {
    for (std::size_t j = m * kMinRun; j <= n; ++j) {
      for (std::size_t i = (m - 1) * kMinRun; i + kMinRun <= j; ++i) {
        if (!std::isfinite(best[m - 1][i])) continue;
        const double c = best[m - 1][i] + cost.fit(i, j).first;
        if (c < best[m][j]) {
          best[m][j] = c;
          from[m][j] = i;
        }
      }
    }
  }
  SlopeSegmentation out;
  out.residual_sum_N2 = best[segments][n];
  std::size_t j = n;
  for (std::size_t m = segments; m >= 1; --m) {
    const std::size_t i = from[m][j];
    out.slopes_N_per_m.push_back(cost.fit(i, j).second);
    if (i > 0) out.boundaries_m.push_back(0.5 * (b.x[i - 1] + b.x[i]));
    j = i;
  }
  std::reverse(out.slopes_N_per_m.begin(), out.slopes_N_per_m.end());
  std::reverse(out.boundaries_m.begin(), out.boundaries_m.end());
  return out;
}

}  // namespace

SlopeSegmentation segment_by_slope(const std::vector<double>& depth_m,
                                   const std::vector<double>& force_N, std::size_t segments,
                                   std::size_t bins) {
  return segment_binned(bin_curve(depth_m, force_N, bins), segments);
}

std::vector<double> detect_layer_boundaries(const std::vector<double>& depth_m,
                                            const std::vector<double>& force_N,
                                            std::size_t max_segments, std::size_t bins) {
  const Binned b = bin_curve(depth_m, force_N, bins);
  const double n = static_cast<double>(b.x.size());
  double best_score = kInfinity;
  std::vector<double> best;
  for (std::size_t m = 1; m <= max_segments && b.x.size() >= 3 * m; ++m) {
    const auto s = segment_binned(b, m);
    const double rss = std::max(s.residual_sum_N2, 1e-300);
    const double score = n * std::log(rss / n) + 3.0 * static_cast<double>(m) * std::log(n);
    if (score < best_score) {
      best_score = score;
      best = s.boundaries_m;
    }
  }
  return best;
}

}  // namespace mneedle
