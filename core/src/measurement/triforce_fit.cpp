#include "mneedle/measurement/triforce_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <set>

#include "measurement/bounded_transform.h"
#include "measurement/levenberg_marquardt.h"
#include "mneedle/base/error.h"

namespace mneedle {
namespace {

using detail::Bound;
using detail::standard_errors;
using detail::to_external;
using detail::to_internal;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Scales of the data that set the parameter bounds and the first start.
struct DataScale {
  double peak_N = 1.0;
  double depth_m = 1e-2;
  double strain = 1.0;
  double friction_c = 1.0;  // c giving a friction force of the order of the peak force
  double viscosity = 1.0;   // eta giving a viscous force of the order of the peak force
};

DataScale data_scale(const std::vector<FitCurve>& curves, const TriforceParams& p) {
  DataScale s;
  s.peak_N = 0.0;
  s.depth_m = 0.0;
  double rate = kInfinity;
  for (const auto& c : curves) {
    s.peak_N = std::max(s.peak_N, *std::max_element(c.force_N.begin(), c.force_N.end()));
    s.depth_m = std::max(s.depth_m, *std::max_element(c.depth_m.begin(), c.depth_m.end()));
    const double r = c.conditions.speed_m_per_s * std::sin(c.conditions.angle_rad);
    if (r > 0.0) rate = std::min(rate, r);
  }
  s.peak_N = std::max(s.peak_N, 1e-6);
  s.depth_m = std::max(s.depth_m, 1e-6);
  const double max_sin = 1.0;
  s.strain = std::max(s.depth_m * max_sin / p.reference_length_m, 1e-3);
  const double mu = std::max(p.friction_coefficient, 1e-2);
  s.friction_c = 1.0 / (std::numbers::pi * p.needle_radius_m * mu * s.depth_m);
  s.viscosity = std::isfinite(rate) ? s.peak_N * p.reference_length_m / rate : 1.0;
  return s;
}

std::string base_name(const std::string& name) {
  const auto pos = name.rfind("_L");
  if (pos == std::string::npos || pos + 2 >= name.size()) return name;
  for (std::size_t i = pos + 2; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return name;
  }
  return name.substr(0, pos);
}

Bound bound_for(const std::string& name, const DataScale& s) {
  const auto base = base_name(name);
  if (base == "Fc_max_N") return {0.0, 3.0 * s.peak_N};
  if (base == "kc_per_m") return {0.1 / s.depth_m, 1e4 / s.depth_m, true};
  if (base == "K0_N") return {0.0, 50.0 * s.peak_N / s.strain};
  if (base == "beta") return {-3.0 / s.strain, 8.0 / s.strain};
  if (base == "c_per_m2") return {0.0, 20.0 * s.friction_c};
  if (base == "start_m") return {0.0, s.depth_m};
  if (base == "mu") return {0.0, 2.0};
  if (base == "radius_m") return {1e-5, 5e-3, true};
  if (base == "ref_length_m") return {1e-4, 1.0, true};
  if (base == "eta_Ns") return {0.0, 20.0 * s.viscosity};
  if (base == "lambda_s") return {1e-2, 1e2, true};
  throw InputError("tri-force fit: unknown parameter '" + name + "'");
}

// A physically sensible first start for each parameter.
double first_guess(const std::string& name, const DataScale& s, const TriforceParams& p) {
  const auto base = base_name(name);
  if (base == "Fc_max_N") return 0.3 * s.peak_N;
  if (base == "kc_per_m") return 5.0 / s.depth_m;
  if (base == "K0_N") return 0.3 * s.peak_N / s.strain;
  if (base == "beta") return 1.0 / s.strain;
  if (base == "c_per_m2") return 0.5 * s.friction_c;
  if (base == "eta_Ns") return 0.1 * s.viscosity;
  if (base == "lambda_s") return 1.0;
  return get_parameter(p, name);
}

std::vector<std::size_t> thinned_indices(std::size_t n, std::size_t max_samples) {
  const std::size_t stride =
      max_samples == 0 ? 1 : std::max<std::size_t>(1, (n + max_samples - 1) / max_samples);
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; i += stride) out.push_back(i);
  if (out.back() != n - 1) out.push_back(n - 1);
  return out;
}

// The fit problem in external (physical) coordinates: fitted parameters then curve offsets.
class Problem {
 public:
  Problem(const std::vector<FitCurve>& curves, TriforceParams base, std::vector<std::string> free,
          const TriforceFitOptions& options)
      : curves_(curves),
        base_(std::move(base)),
        free_(std::move(free)),
        fit_offsets_(options.fit_offsets) {
    for (const auto& c : curves_)
      samples_.push_back(thinned_indices(c.depth_m.size(), options.max_samples_per_curve));
  }

  std::size_t parameter_count() const { return free_.size() + (fit_offsets_ ? curves_.size() : 0); }
  std::size_t sample_count() const {
    std::size_t n = 0;
    for (const auto& s : samples_) n += s.size();
    return n;
  }

  TriforceParams params_at(const Eigen::VectorXd& x) const {
    TriforceParams p = base_;
    for (std::size_t j = 0; j < free_.size(); ++j)
      set_parameter(p, free_[j], x[static_cast<Eigen::Index>(j)]);
    return p;
  }
  double offset_at(const Eigen::VectorXd& x, std::size_t curve) const {
    return fit_offsets_ ? x[static_cast<Eigen::Index>(free_.size() + curve)] : 0.0;
  }

  Eigen::VectorXd residuals(const Eigen::VectorXd& x) const {
    Eigen::VectorXd r(static_cast<Eigen::Index>(sample_count()));
    std::optional<TriforceModel> model;
    try {
      model.emplace(params_at(x));
    } catch (const InputError&) {
      return Eigen::VectorXd::Constant(r.size(), kInfinity);  // outside the admissible set
    }
    Eigen::Index k = 0;
    for (std::size_t i = 0; i < curves_.size(); ++i) {
      const auto& c = curves_[i];
      const double offset = offset_at(x, i);
      for (std::size_t j : samples_[i]) {
        r[k++] = model->loading(c.depth_m[j] - offset, c.conditions).total_N() - c.force_N[j];
      }
    }
    return r;
  }

 private:
  const std::vector<FitCurve>& curves_;
  TriforceParams base_;
  std::vector<std::string> free_;
  bool fit_offsets_;
  std::vector<std::vector<std::size_t>> samples_;
};

std::vector<std::string> default_free(const TriforceParams& p) {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < p.layers.size(); ++i) {
    const std::string suffix = i == 0 ? "" : "_L" + std::to_string(i + 1);
    for (const char* n : {"Fc_max_N", "kc_per_m", "K0_N", "beta", "c_per_m2"})
      out.push_back(n + suffix);
  }
  return out;
}

void check_curves(const std::vector<FitCurve>& curves) {
  if (curves.empty()) throw InputError("tri-force fit: no curve to fit");
  for (const auto& c : curves) {
    if (c.depth_m.empty() || c.depth_m.size() != c.force_N.size()) {
      throw InputError(c.name + ": no samples to fit (or depth and force of different lengths)");
    }
    if (!(c.conditions.speed_m_per_s > 0.0))
      throw InputError(c.name + ": insertion speed must be > 0");
  }
}

}  // namespace

std::vector<double> predict_loading(const TriforceModel& model, const FitCurve& curve,
                                    double offset_m) {
  std::vector<double> out;
  out.reserve(curve.depth_m.size());
  for (double z : curve.depth_m)
    out.push_back(model.loading(z - offset_m, curve.conditions).total_N());
  return out;
}

TriforceFit fit_triforce(const std::vector<FitCurve>& curves, const TriforceFitOptions& options) {
  check_curves(curves);
  TriforceParams base = options.initial;
  for (const auto& [name, value] : options.fixed) set_parameter(base, name, value);
  std::vector<std::string> free = options.free.empty() ? default_free(base) : options.free;
  std::erase_if(free, [&](const std::string& n) { return options.fixed.count(n) > 0; });
  std::set<std::string> seen;
  for (const auto& n : free) {
    get_parameter(base, n);  // throws for an unknown name
    if (!seen.insert(n).second)
      throw InputError("tri-force fit: parameter '" + n + "' given twice");
  }
  TriforceModel{base};  // the fixed values must be valid on their own
  if (free.empty())
    throw InputError("tri-force fit: every parameter is fixed; nothing is left to fit");

  const DataScale scale = data_scale(curves, base);
  const double max_offset =
      options.max_offset_m > 0.0 ? options.max_offset_m : 0.25 * scale.depth_m;
  std::vector<Bound> bounds;
  for (const auto& n : free) bounds.push_back(bound_for(n, scale));
  if (options.fit_offsets)
    bounds.insert(bounds.end(), curves.size(), Bound{-max_offset, max_offset});
  const Problem problem(curves, base, free, options);
  const std::size_t p = problem.parameter_count();
  const std::size_t n = problem.sample_count();
  if (n <= p) {
    throw InputError("tri-force fit: " + std::to_string(n) + " samples for " + std::to_string(p) +
                     " parameters");
  }
  const auto external = [&](const Eigen::VectorXd& u) {
    Eigen::VectorXd x(u.size());
    for (Eigen::Index j = 0; j < u.size(); ++j)
      x[j] = to_external(u[j], bounds[static_cast<std::size_t>(j)]);
    return x;
  };
  const detail::ResidualFunction transformed = [&](const Eigen::VectorXd& u) {
    return problem.residuals(external(u));
  };

  std::mt19937 random(20240611u);  // fixed seed: the same data give the same fit
  std::uniform_real_distribution<double> spread(-3.0, 3.0);
  detail::LmOptions lm;
  lm.max_iterations = options.max_iterations;
  detail::LmResult best;
  best.cost = kInfinity;
  TriforceFit fit;
  fit.starts = std::max(1, options.starts);
  for (int start = 0; start < fit.starts; ++start) {
    Eigen::VectorXd u0(static_cast<Eigen::Index>(p));
    for (std::size_t j = 0; j < p; ++j) {
      const bool is_offset = j >= free.size();
      u0[static_cast<Eigen::Index>(j)] =
          start == 0 ? to_internal(is_offset ? 0.0 : first_guess(free[j], scale, base), bounds[j])
                     : spread(random);
    }
    const auto result = detail::levenberg_marquardt(transformed, u0, lm);
    if (result.cost < best.cost) best = result;
  }
  if (!std::isfinite(best.cost))
    throw SolverError("tri-force fit: no start gave a finite residual");

  const Eigen::VectorXd x = external(best.x);
  fit.params = problem.params_at(x);
  fit.samples = n;
  fit.iterations = best.iterations;
  fit.converged = best.converged;
  const double variance = best.cost / static_cast<double>(n - p);
  fit.residual_sd_N = std::sqrt(variance);
  const Eigen::VectorXd errors = standard_errors(
      detail::physical_jacobian([&](const Eigen::VectorXd& y) { return problem.residuals(y); }, x,
                                bounds),
      variance);

  for (const auto& [name, value] : named_parameters(fit.params)) {
    FitParameter fp{name, value, 0.0, false};
    const auto it = std::find(free.begin(), free.end(), name);
    if (it != free.end()) {
      fp.fitted = true;
      fp.standard_error = errors[it - free.begin()];
    }
    fit.parameters.push_back(fp);
  }
  const TriforceModel model(fit.params);
  for (std::size_t i = 0; i < curves.size(); ++i) {
    CurveFit cf;
    cf.name = curves[i].name;
    cf.offset_m = problem.offset_at(x, i);
    cf.offset_standard_error_m =
        options.fit_offsets ? errors[static_cast<Eigen::Index>(free.size() + i)] : 0.0;
    cf.metrics = compare_curves(curves[i].force_N, predict_loading(model, curves[i], cf.offset_m));
    fit.curves.push_back(cf);
  }
  return fit;
}

}  // namespace mneedle
