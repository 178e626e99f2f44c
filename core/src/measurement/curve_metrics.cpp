#include "mneedle/measurement/curve_metrics.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {

CurveMetrics compare_curves(std::span<const double> measured, std::span<const double> predicted) {
  if (measured.size() != predicted.size() || measured.empty()) {
    throw InputError("curve comparison: " + std::to_string(measured.size()) + " measured and " +
                     std::to_string(predicted.size()) + " predicted samples (need equal, > 0)");
  }
  const double n = static_cast<double>(measured.size());
  double mean = 0.0;
  for (double m : measured) mean += m;
  mean /= n;
  CurveMetrics out;
  out.samples = measured.size();
  double ss_res = 0.0, ss_tot = 0.0;
  for (std::size_t i = 0; i < measured.size(); ++i) {
    const double e = measured[i] - predicted[i];
    ss_res += e * e;
    ss_tot += (measured[i] - mean) * (measured[i] - mean);
    out.max_error_N = std::max(out.max_error_N, std::abs(e));
  }
  out.rmse_N = std::sqrt(ss_res / n);
  if (ss_tot > 0.0) {
    out.r2 = 1.0 - ss_res / ss_tot;
  } else {
    out.r2 = ss_res == 0.0 ? 1.0 : 0.0;
  }
  return out;
}

}  // namespace mneedle
