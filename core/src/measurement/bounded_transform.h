#pragma once
// The pieces of bounded least squares shared by the tri-force fit and fit_bounded: the logistic
// map of an interval to the real line and the standard errors from a Jacobian.

#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "mneedle/measurement/bounded_least_squares.h"

namespace mneedle::detail {

using Bound = ParameterBound;

double to_internal(double value, const Bound& b);
double to_external(double u, const Bound& b);

/// Derivative of the residuals with respect to the physical parameters; one-sided at a bound.
Eigen::MatrixXd physical_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                  const Eigen::VectorXd& x, const std::vector<Bound>& bounds);

/// sqrt(diag(s^2 (J^T J)^-1)); directions the data cannot see give infinite errors.
Eigen::VectorXd standard_errors(const Eigen::MatrixXd& jac, double variance);

}  // namespace mneedle::detail
