#pragma once
// Goodness of fit between a measured and a predicted force curve, as paper B reports it.

#include <cstddef>
#include <span>

namespace mneedle {

struct CurveMetrics {
  double rmse_N = 0.0;       ///< root mean square of measured - predicted
  double r2 = 0.0;           ///< 1 - SS_res / SS_tot (may be negative for a bad prediction)
  double max_error_N = 0.0;  ///< largest |measured - predicted|
  std::size_t samples = 0;
};

/// RMSE, R^2 and maximum error over paired samples. A constant measured curve has no variance:
/// R^2 is then 1 for an exact prediction and 0 otherwise (never NaN). Throws InputError when the
/// lengths differ or there are no samples.
CurveMetrics compare_curves(std::span<const double> measured, std::span<const double> predicted);

}  // namespace mneedle
