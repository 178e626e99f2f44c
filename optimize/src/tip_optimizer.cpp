#include "mneedle/tip_optimizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <nlopt.hpp>

#include "mneedle/error.h"
#include "mneedle/nlopt_status.h"

namespace mneedle {
namespace {

// NLopt sees every variable scaled to [0, 1], so tolerances mean the same for metres and radians.
class ScaledProblem {
 public:
  ScaledProblem(const std::vector<DesignVariable>& variables, const DesignFunction& f, int m,
                const OptimizerOptions& options, OptimizerResult& result)
      : variables_(variables), f_(f), m_(m), options_(options), result_(result) {}

  const EvaluationRecord& evaluate(const std::vector<double>& unit) {
    const auto key = unit;
    if (const auto it = cache_.find(key); it != cache_.end()) return result_.history[it->second];
    EvaluationRecord record;
    for (std::size_t i = 0; i < variables_.size(); ++i)
      record.values[variables_[i].name] =
          variables_[i].lower + unit[i] * (variables_[i].upper - variables_[i].lower);
    const auto start = std::chrono::steady_clock::now();
    try {
      const DesignScore score = f_(record.values);
      if (!std::isfinite(score.objective) || static_cast<int>(score.constraints.size()) != m_)
        throw SolverError("non-finite objective or wrong number of constraints");
      record.objective = score.objective;
      record.constraints = score.constraints;
      record.feasible = std::all_of(score.constraints.begin(), score.constraints.end(),
                                    [](double c) { return c <= 0.0; });
    } catch (const std::exception& e) {
      // A failed design is a penalised point: worse than anything seen, and infeasible.
      record.failed = true;
      record.error = e.what();
      record.objective = penalty();
      record.constraints.assign(m_, 1.0);
    }
    record.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cache_[key] = result_.history.size();
    result_.history.push_back(record);
    ++result_.evaluations;
    if (options_.progress) options_.progress(result_.evaluations, best_so_far());
    return result_.history.back();
  }

 private:
  double penalty() const {
    double worst = 1.0;
    for (const auto& r : result_.history)
      if (!r.failed) worst = std::max(worst, std::abs(r.objective) * 10.0);
    return worst;
  }

  double best_so_far() const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& r : result_.history)
      if (r.feasible) best = std::min(best, r.objective);
    return best;
  }

  const std::vector<DesignVariable>& variables_;
  const DesignFunction& f_;
  int m_;
  const OptimizerOptions& options_;
  OptimizerResult& result_;
  std::map<std::vector<double>, std::size_t> cache_;
};

struct ConstraintData {
  ScaledProblem* problem;
  int index;
};

double objective_callback(const std::vector<double>& x, std::vector<double>&, void* data) {
  return static_cast<ScaledProblem*>(data)->evaluate(x).objective;
}

double constraint_callback(const std::vector<double>& x, std::vector<double>&, void* data) {
  const auto* c = static_cast<ConstraintData*>(data);
  return c->problem->evaluate(x).constraints[c->index];
}

nlopt::opt make_optimizer(const std::string& algorithm, unsigned n) {
  if (algorithm == "cobyla") return nlopt::opt(nlopt::LN_COBYLA, n);
  if (algorithm == "isres") return nlopt::opt(nlopt::GN_ISRES, n);
  if (algorithm == "bobyqa") {
    nlopt::opt outer(nlopt::AUGLAG, n);
    nlopt::opt local(nlopt::LN_BOBYQA, n);
    local.set_xtol_rel(1e-6);
    outer.set_local_optimizer(local);
    return outer;
  }
  throw InputError("optimizer: unknown algorithm '" + algorithm +
                   "' (expected cobyla, bobyqa or isres)");
}

void check_variables(const std::vector<DesignVariable>& variables, const OptimizerOptions& o) {
  if (variables.empty()) throw InputError("optimizer: no variables to vary");
  for (const auto& v : variables)
    if (!(v.lower < v.upper) || !std::isfinite(v.lower) || !std::isfinite(v.upper))
      throw InputError("optimizer: variable '" + v.name + "' needs finite bounds lower < upper");
  if (!o.start.empty() && o.start.size() != variables.size())
    throw InputError("optimizer: the start point needs one value per variable");
  for (std::size_t i = 0; i < o.start.size(); ++i)
    if (o.start[i] < variables[i].lower || o.start[i] > variables[i].upper)
      throw InputError("optimizer: start value of '" + variables[i].name +
                       "' is outside its bounds");
  if (o.max_evaluations < 1) throw InputError("optimizer: max evaluations must be at least 1");
}

void pick_best(OptimizerResult& result) {
  const EvaluationRecord* best = nullptr;
  auto violation = [](const EvaluationRecord& r) {
    double v = 0.0;
    for (double c : r.constraints) v += std::max(c, 0.0);
    return v;
  };
  for (const auto& r : result.history) {
    if (r.failed) continue;
    if (!best || (r.feasible && !best->feasible) ||
        (r.feasible == best->feasible &&
         (r.feasible ? r.objective < best->objective : violation(r) < violation(*best))))
      best = &r;
  }
  if (!best) {
    result.stop_reason += "; every evaluation failed";
    return;
  }
  result.best = best->values;
  result.best_objective = best->objective;
  result.feasible = best->feasible;
}

}  // namespace

OptimizerResult optimize_design(const std::vector<DesignVariable>& variables,
                                const DesignFunction& f, int constraint_count,
                                const OptimizerOptions& options) {
  check_variables(variables, options);
  OptimizerResult result;
  result.algorithm = options.algorithm;
  const auto n = static_cast<unsigned>(variables.size());
  nlopt::srand(options.seed);
  nlopt::opt opt = make_optimizer(options.algorithm, n);
  ScaledProblem problem(variables, f, constraint_count, options, result);
  opt.set_lower_bounds(std::vector<double>(n, 0.0));
  opt.set_upper_bounds(std::vector<double>(n, 1.0));
  opt.set_min_objective(objective_callback, &problem);
  std::vector<ConstraintData> constraints;
  for (int i = 0; i < constraint_count; ++i) constraints.push_back({&problem, i});
  for (auto& c : constraints) opt.add_inequality_constraint(constraint_callback, &c, 1e-8);
  opt.set_xtol_rel(options.relative_tolerance);
  opt.set_maxeval(options.max_evaluations);
  if (options.max_time_s > 0) opt.set_maxtime(options.max_time_s);
  if (options.algorithm == "isres") opt.set_population(std::max(20u, 10 * (n + 1)));

  std::vector<double> x(n, 0.5);
  for (std::size_t i = 0; i < options.start.size(); ++i)
    x[i] = (options.start[i] - variables[i].lower) / (variables[i].upper - variables[i].lower);
  double value = 0.0;
  try {
    result.stop_reason = describe_nlopt_result(opt.optimize(x, value));
  } catch (const nlopt::roundoff_limited&) {
    result.stop_reason = describe_nlopt_result(NLOPT_ROUNDOFF_LIMITED);
  } catch (const nlopt::forced_stop&) {
    result.stop_reason = describe_nlopt_result(NLOPT_FORCED_STOP);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("optimizer: NLopt rejected the problem: ") + e.what());
  } catch (const std::runtime_error& e) {
    result.stop_reason = std::string("NLopt failed: ") + e.what();
  }
  pick_best(result);
  return result;
}

}  // namespace mneedle
