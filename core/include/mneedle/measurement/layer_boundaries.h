#pragma once
// Layer boundaries read from changes of slope in a measured force–depth curve (paper B reads the
// renal cortex / medulla / calyx transitions this way): least-squares piecewise-linear
// segmentation by dynamic programming.

#include <cstddef>
#include <vector>

namespace mneedle {

struct SlopeSegmentation {
  std::vector<double> boundaries_m;    ///< depths where one segment ends and the next begins
  std::vector<double> slopes_N_per_m;  ///< one per segment, shallow to deep
  double residual_sum_N2 = 0.0;        ///< of the binned curve
};

/// The best fit of `segments` independent straight lines to the curve, after averaging it into at
/// most `bins` equal depth bins (removes sensor noise and makes the search O(segments bins^2)).
/// Throws InputError when the curve is too short for the number of segments (3 bins each).
SlopeSegmentation segment_by_slope(const std::vector<double>& depth_m,
                                   const std::vector<double>& force_N, std::size_t segments,
                                   std::size_t bins = 200);

/// Boundaries of the segmentation with 1..max_segments lines that minimises the Bayesian
/// information criterion n ln(RSS/n) + 3 m ln n (each line: slope, intercept, breakpoint).
std::vector<double> detect_layer_boundaries(const std::vector<double>& depth_m,
                                            const std::vector<double>& force_N,
                                            std::size_t max_segments = 4, std::size_t bins = 200);

}  // namespace mneedle
