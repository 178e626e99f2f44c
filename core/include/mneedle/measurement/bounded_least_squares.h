#pragma once
// Bounded nonlinear least squares for fitting model constants to measured curves:
// Levenberg–Marquardt in a logistic (optionally log-scaled) parameterisation of each interval,
// several starts, and the uncertainty of the answer (standard errors and correlations from the
// Jacobian at the optimum, in the physical parameters). Plain vectors cross this header.

#include <cstddef>
#include <functional>
#include <vector>

namespace mneedle {

/// Residuals (measured - model, any unit) at the physical parameters x.
using ResidualVector = std::function<std::vector<double>(const std::vector<double>& x)>;

/// A parameter's admissible interval; `log` parameters span decades and are searched in log space.
struct ParameterBound {
  double lo = 0.0;
  double hi = 1.0;
  bool log = false;
};

struct BoundedFitOptions {
  int starts = 4;  ///< the first from x0, the others spread over the intervals (fixed seed)
  int max_iterations = 200;
};

struct BoundedFit {
  std::vector<double> x;
  /// sqrt(diag(s^2 (J^T J)^-1)), s^2 = cost / (n - p); infinity for a direction the data
  /// cannot see.
  std::vector<double> standard_error;
  std::vector<std::vector<double>> correlation;  ///< p x p; NaN-free (0 where undefined)
  double cost = 0.0;                             ///< sum of squared residuals at x
  double residual_sd = 0.0;                      ///< s
  std::size_t samples = 0;
  int iterations = 0;  ///< of the best start
  bool converged = false;
  /// Parameters within 1e-6 of an interval end (relative to the interval): their standard
  /// errors describe a constrained optimum.
  std::vector<bool> at_bound;
};

/// Minimises the sum of squared residuals over the box. Throws InputError when x0 and bounds
/// differ in size, a bound is empty or non-finite (or not positive for a log bound), or there
/// are no more residuals than parameters; SolverError when no start gives a finite residual.
BoundedFit fit_bounded(const ResidualVector& residuals, const std::vector<double>& x0,
                       const std::vector<ParameterBound>& bounds,
                       const BoundedFitOptions& options = {});

}  // namespace mneedle
