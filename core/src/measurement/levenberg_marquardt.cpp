#include "measurement/levenberg_marquardt.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace mneedle::detail {
namespace {

double cost_of(const Eigen::VectorXd& r) {
  return r.allFinite() ? r.squaredNorm() : std::numeric_limits<double>::infinity();
}

}  // namespace

Eigen::MatrixXd numeric_jacobian(const ResidualFunction& f, const Eigen::VectorXd& x,
                                 double min_step) {
  Eigen::MatrixXd jac;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = std::max(min_step, 1e-6 * std::abs(x[j]));
    Eigen::VectorXd up = x, down = x;
    up[j] += h;
    down[j] -= h;
    const Eigen::VectorXd column = (f(up) - f(down)) / (2.0 * h);
    if (jac.size() == 0) jac.resize(column.size(), x.size());
    jac.col(j) = column;
  }
  return jac;
}

LmResult levenberg_marquardt(const ResidualFunction& f, const Eigen::VectorXd& x0,
                             const LmOptions& options) {
  LmResult out;
  out.x = x0;
  Eigen::VectorXd r = f(out.x);
  out.cost = cost_of(r);
  if (!std::isfinite(out.cost)) return out;
  double damping = -1.0;
  for (out.iterations = 0; out.iterations < options.max_iterations; ++out.iterations) {
    const Eigen::MatrixXd jac = numeric_jacobian(f, out.x, 1e-7);
    if (!jac.allFinite()) return out;
    const Eigen::MatrixXd normal = jac.transpose() * jac;
    const Eigen::VectorXd gradient = jac.transpose() * r;
    if (gradient.lpNorm<Eigen::Infinity>() < options.gradient_tolerance) {
      out.converged = true;
      return out;
    }
    const Eigen::VectorXd scale =
        normal.diagonal().cwiseMax(1e-12 * normal.diagonal().maxCoeff() + 1e-300);
    if (damping < 0.0) damping = 1e-3;
    bool accepted = false;
    while (!accepted) {
      Eigen::MatrixXd system = normal;
      system.diagonal() += damping * scale;
      const Eigen::VectorXd step = system.ldlt().solve(-gradient);
      const Eigen::VectorXd trial = out.x + step;
      const Eigen::VectorXd r_trial = f(trial);
      const double trial_cost = cost_of(r_trial);
      if (step.allFinite() && trial_cost < out.cost) {
        const double gain = out.cost - trial_cost;
        const bool small_step =
            step.norm() < options.step_tolerance * (out.x.norm() + options.step_tolerance);
        out.x = trial;
        r = r_trial;
        out.cost = trial_cost;
        damping = std::max(damping / 3.0, 1e-12);
        accepted = true;
        if (gain < options.relative_cost_tolerance * trial_cost || small_step) {
          out.converged = true;
          return out;
        }
      } else {
        damping *= 4.0;
        if (damping > 1e16) {
          out.converged = true;  // no descent direction left: a (local) minimum
          return out;
        }
      }
    }
  }
  return out;
}

}  // namespace mneedle::detail
