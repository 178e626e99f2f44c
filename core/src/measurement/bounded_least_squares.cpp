#include "mneedle/measurement/bounded_least_squares.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "measurement/bounded_transform.h"
#include "measurement/levenberg_marquardt.h"
#include "mneedle/base/error.h"

namespace mneedle {
namespace detail {
namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

double to_internal(double value, const Bound& b) {
  const double q = b.log ? std::log(value) : value;
  const double lo = b.log ? std::log(b.lo) : b.lo;
  const double hi = b.log ? std::log(b.hi) : b.hi;
  const double t = std::clamp((q - lo) / (hi - lo), 1e-9, 1.0 - 1e-9);
  return std::log(t / (1.0 - t));
}

double to_external(double u, const Bound& b) {
  const double t = 1.0 / (1.0 + std::exp(-u));
  if (b.log) return std::exp(std::log(b.lo) + t * (std::log(b.hi) - std::log(b.lo)));
  return b.lo + t * (b.hi - b.lo);
}

Eigen::VectorXd standard_errors(const Eigen::MatrixXd& jac, double variance) {
  const Eigen::Index p = jac.cols();
  Eigen::VectorXd scale = jac.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j) scale[j] = scale[j] > 0.0 ? 1.0 / scale[j] : 0.0;
  const Eigen::MatrixXd scaled = jac * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled.transpose() * scaled);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const Eigen::MatrixXd& v = eig.eigenvectors();
  const double floor = 1e-13 * std::max(lambda.maxCoeff(), 1e-300);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    if (scale[j] == 0.0) {
      out[j] = kInfinity;
      continue;
    }
    double var = 0.0;
    for (Eigen::Index k = 0; k < p; ++k) {
      const double weight = v(j, k) * v(j, k);
      if (lambda[k] <= floor) {
        if (weight > 1e-12) var = kInfinity;
      } else {
        var += weight / lambda[k];
      }
    }
    out[j] = std::isfinite(var) ? std::sqrt(variance * var) * scale[j] : kInfinity;
  }
  return out;
}

Eigen::MatrixXd physical_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                  const Eigen::VectorXd& x, const std::vector<Bound>& bounds) {
  const Eigen::VectorXd r0 = f(x);
  Eigen::MatrixXd jac(r0.size(), x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const auto& b = bounds[static_cast<std::size_t>(j)];
    const double h = 1e-6 * std::max(std::abs(x[j]), 1e-3 * (b.hi - b.lo));
    Eigen::VectorXd up = x, down = x;
    up[j] += h;
    down[j] -= h;
    if (down[j] < b.lo) {
      jac.col(j) = (f(up) - r0) / h;
    } else if (up[j] > b.hi) {
      jac.col(j) = (r0 - f(down)) / h;
    } else {
      jac.col(j) = (f(up) - f(down)) / (2.0 * h);
    }
  }
  return jac;
}

}  // namespace detail

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

Eigen::VectorXd call(const ResidualVector& f, const Eigen::VectorXd& x) {
  const std::vector<double> r = f(std::vector<double>(x.data(), x.data() + x.size()));
  return Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
}

void check(const std::vector<double>& x0, const std::vector<ParameterBound>& bounds) {
  if (x0.size() != bounds.size() || x0.empty()) {
    throw InputError("bounded fit: " + std::to_string(x0.size()) + " start values for " +
                     std::to_string(bounds.size()) + " bounds");
  }
  for (std::size_t j = 0; j < bounds.size(); ++j) {
    const ParameterBound& b = bounds[j];
    if (!(std::isfinite(b.lo) && std::isfinite(b.hi) && b.lo < b.hi) || (b.log && !(b.lo > 0.0))) {
      throw InputError("bounded fit: parameter " + std::to_string(j + 1) +
                       " has no admissible interval");
    }
  }
}

}  // namespace

BoundedFit fit_bounded(const ResidualVector& residuals, const std::vector<double>& x0,
                       const std::vector<ParameterBound>& bounds,
                       const BoundedFitOptions& options) {
  check(x0, bounds);
  const std::size_t p = x0.size();
  const auto external = [&](const Eigen::VectorXd& u) {
    Eigen::VectorXd x(u.size());
    for (Eigen::Index j = 0; j < u.size(); ++j)
      x[j] = detail::to_external(u[j], bounds[static_cast<std::size_t>(j)]);
    return x;
  };
  const detail::ResidualFunction transformed = [&](const Eigen::VectorXd& u) {
    return call(residuals, external(u));
  };
  std::mt19937 random(20261202u);  // fixed seed: the same data give the same fit
  std::uniform_real_distribution<double> spread(-3.0, 3.0);
  detail::LmOptions lm;
  lm.max_iterations = options.max_iterations;
  detail::LmResult best;
  best.cost = kInfinity;
  for (int start = 0; start < std::max(1, options.starts); ++start) {
    Eigen::VectorXd u0(static_cast<Eigen::Index>(p));
    for (std::size_t j = 0; j < p; ++j) {
      u0[static_cast<Eigen::Index>(j)] =
          start == 0 ? detail::to_internal(x0[j], bounds[j]) : spread(random);
    }
    const detail::LmResult result = detail::levenberg_marquardt(transformed, u0, lm);
    if (result.cost < best.cost) best = result;
  }
  if (!std::isfinite(best.cost)) throw SolverError("bounded fit: no start gave a finite residual");

  BoundedFit fit;
  const Eigen::VectorXd x = external(best.x);
  const Eigen::VectorXd r = call(residuals, x);
  fit.samples = static_cast<std::size_t>(r.size());
  if (fit.samples <= p) {
    throw InputError("bounded fit: " + std::to_string(fit.samples) + " residuals for " +
                     std::to_string(p) + " parameters");
  }
  fit.x.assign(x.data(), x.data() + x.size());
  fit.cost = r.squaredNorm();
  fit.iterations = best.iterations;
  fit.converged = best.converged;
  const double variance = fit.cost / static_cast<double>(fit.samples - p);
  fit.residual_sd = std::sqrt(variance);
  const Eigen::MatrixXd jac = detail::physical_jacobian(
      [&](const Eigen::VectorXd& y) { return call(residuals, y); }, x, bounds);
  const Eigen::VectorXd errors = detail::standard_errors(jac, variance);
  fit.standard_error.assign(errors.data(), errors.data() + errors.size());
  // Correlations from the pseudo-inverse of J^T J (a direction the data cannot see gives 0).
  const Eigen::MatrixXd jtj = jac.transpose() * jac;
  const Eigen::MatrixXd cov = jtj.completeOrthogonalDecomposition().pseudoInverse();
  fit.correlation.assign(p, std::vector<double>(p, 0.0));
  for (std::size_t i = 0; i < p; ++i) {
    for (std::size_t j = 0; j < p; ++j) {
      const auto ii = static_cast<Eigen::Index>(i), jj = static_cast<Eigen::Index>(j);
      const double d = std::sqrt(cov(ii, ii) * cov(jj, jj));
      fit.correlation[i][j] = d > 0.0 && std::isfinite(d) ? cov(ii, jj) / d : (i == j ? 1.0 : 0.0);
    }
  }
  for (std::size_t j = 0; j < p; ++j) {
    // Measured where the search happens: in log space for a log bound.
    const bool log = bounds[j].log;
    const auto map = [log](double v) { return log ? std::log(v) : v; };
    const double value = map(x[static_cast<Eigen::Index>(j)]);
    const double lo = map(bounds[j].lo), hi = map(bounds[j].hi);
    const double width = hi - lo;
    fit.at_bound.push_back(value - lo < 1e-6 * width || hi - value < 1e-6 * width);
  }
  return fit;
}

}  // namespace mneedle
