#pragma once
// A small Levenberg–Marquardt least-squares solver on Eigen (Marquardt's diagonal scaling,
// forward-difference Jacobian). Bounds are the caller's business: it works in an unbounded
// transformed space.

#include <Eigen/Dense>
#include <functional>

namespace mneedle::detail {

using ResidualFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

struct LmOptions {
  int max_iterations = 200;
  double relative_cost_tolerance = 1e-10;
  double step_tolerance = 1e-10;
  double gradient_tolerance = 1e-12;
};

struct LmResult {
  Eigen::VectorXd x;
  double cost = 0.0;  ///< sum of squared residuals at x
  int iterations = 0;
  bool converged = false;
};

/// Jacobian of `f` at x by central differences (step relative to |x_j|, at least `min_step`).
Eigen::MatrixXd numeric_jacobian(const ResidualFunction& f, const Eigen::VectorXd& x,
                                 double min_step);

/// Minimises |f(x)|^2 from x0. Non-finite residuals count as an infinitely bad step.
LmResult levenberg_marquardt(const ResidualFunction& f, const Eigen::VectorXd& x0,
                             const LmOptions& options = {});

}  // namespace mneedle::detail
