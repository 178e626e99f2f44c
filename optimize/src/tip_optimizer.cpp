#include "mneedle/tip_optimizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <nlopt.hpp>
#include <numeric>
#include <random>

#include "mneedle/base/error.h"
#include "mneedle/nlopt_status.h"

namespace mneedle {
namespace {

using Clock = std::chrono::steady_clock;

double violation(const EvaluationRecord& r) {
  double v = 0.0;
  for (double c : r.constraints) v += std::max(c, 0.0);
  return v;
}

// Best feasible design, else the least violated; failed and impossible points never count.
const EvaluationRecord* best_record(const std::vector<EvaluationRecord>& history) {
  const EvaluationRecord* best = nullptr;
  for (const auto& r : history) {
    if (r.failed || r.impossible) continue;
    if (!best || (r.feasible && !best->feasible) ||
        (r.feasible == best->feasible &&
         (r.feasible ? r.objective < best->objective : violation(r) < violation(*best))))
      best = &r;
  }
  return best;
}

// NLopt sees every variable scaled to [0, 1], so tolerances mean the same for metres and radians.
class ScaledProblem {
 public:
  ScaledProblem(const std::vector<DesignVariable>& variables, const DesignFunction& f, int m,
                const OptimizerOptions& options, OptimizerResult& result)
      : variables_(variables),
        f_(f),
        m_(m),
        options_(options),
        result_(result),
        started_(Clock::now()),
        last_progress_(started_) {}

  const EvaluationRecord& evaluate(const std::vector<double>& unit) {
    if (const auto it = cache_.find(unit); it != cache_.end()) return result_.history[it->second];
    // The budgets are checked before a new design, so the search never overruns by more than the
    // evaluation that was running when the time ran out.
    if (options_.max_time_s > 0 && elapsed() >= options_.max_time_s) {
      time_up_ = true;
      throw nlopt::forced_stop();
    }
    if (result_.evaluations >= std::min(options_.max_evaluations, start_limit_))
      throw nlopt::forced_stop();
    EvaluationRecord record;
    record.values = to_si(unit);
    record.start = start_;
    const auto begin = Clock::now();
    try {
      const DesignScore score = f_(record.values);
      if (!std::isfinite(score.objective) || static_cast<int>(score.constraints.size()) != m_)
        throw SolverError("non-finite objective or wrong number of constraints");
      for (double c : score.constraints)
        if (!std::isfinite(c)) throw SolverError("non-finite constraint value");
      record.objective = score.objective;
      record.constraints = score.constraints;
      record.feasible = std::all_of(score.constraints.begin(), score.constraints.end(),
                                    [](double c) { return c <= 0.0; });
    } catch (const InfeasibleDesign& e) {
      // No design there: penalised like a failure, but reported as a property of the point.
      record.impossible = true;
      record.error = e.what();
      record.objective = penalty();
      record.constraints.assign(m_, 1.0);
    } catch (const std::exception& e) {
      // A failed design is a penalised point: worse than anything seen, and infeasible.
      record.failed = true;
      record.error = e.what();
      record.objective = penalty();
      record.constraints.assign(m_, 1.0);
    }
    record.seconds = std::chrono::duration<double>(Clock::now() - begin).count();
    cache_[unit] = result_.history.size();
    result_.history.push_back(record);
    ++result_.evaluations;
    if (options_.on_evaluation) {
      // NLopt would turn the caller's exception into its own failure text: keep it and stop.
      try {
        options_.on_evaluation(result_.history.back());
      } catch (...) {
        caller_error_ = std::current_exception();
        throw nlopt::forced_stop();
      }
    }
    report_progress();
    return result_.history.back();
  }

  std::map<std::string, double> to_si(const std::vector<double>& unit) const {
    std::map<std::string, double> values;
    for (std::size_t i = 0; i < variables_.size(); ++i)
      values[variables_[i].name] =
          variables_[i].lower + unit[i] * (variables_[i].upper - variables_[i].lower);
    return values;
  }

  double elapsed() const { return std::chrono::duration<double>(Clock::now() - started_).count(); }
  bool time_up() const { return time_up_; }
  void rethrow_caller_error() const {
    if (caller_error_) std::rethrow_exception(caller_error_);
  }
  void set_start(int start) { start_ = start; }
  /// Distinct designs evaluated by the end of this start, at most (its share of the budget;
  /// NLopt's own count also counts the repeats the cache answers).
  void set_start_limit(int limit) { start_limit_ = limit; }

 private:
  double penalty() const {
    double worst = 1.0;
    for (const auto& r : result_.history)
      if (!r.failed && !r.impossible) worst = std::max(worst, std::abs(r.objective) * 10.0);
    return worst;
  }

  void report_progress() {
    if (!options_.progress) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_progress_).count() < options_.progress_interval_s)
      return;
    last_progress_ = now;
    OptimizerProgress p;
    p.evaluations = result_.evaluations;
    p.elapsed_s = elapsed();
    p.start = start_;
    p.starts = options_.starts;
    if (const auto* best = best_record(result_.history)) {
      p.best_objective = best->objective;
      p.feasible = best->feasible;
    } else {
      p.best_objective = std::numeric_limits<double>::quiet_NaN();
    }
    options_.progress(p);
  }

  const std::vector<DesignVariable>& variables_;
  const DesignFunction& f_;
  int m_;
  const OptimizerOptions& options_;
  OptimizerResult& result_;
  Clock::time_point started_, last_progress_;
  int start_limit_ = std::numeric_limits<int>::max();
  std::map<std::vector<double>, std::size_t> cache_;
  bool time_up_ = false;
  int start_ = 1;
  std::exception_ptr caller_error_;
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

bool is_local(const std::string& algorithm) {
  return algorithm == "cobyla" || algorithm == "bobyqa";
}

nlopt::opt local_search(const std::string& name, unsigned n, double tolerance) {
  if (name != "cobyla" && name != "bobyqa")
    throw InputError("optimizer: unknown local algorithm '" + name +
                     "' for mlsl (expected cobyla or bobyqa)");
  nlopt::opt local(name == "cobyla" ? nlopt::LN_COBYLA : nlopt::LN_BOBYQA, n);
  local.set_xtol_rel(tolerance);
  return local;
}

// MLSL handles bounds only; with constraints it runs as the subsidiary search of an augmented
// Lagrangian, one MLSL per multiplier update, each given a share of the budget.
nlopt::opt make_mlsl(unsigned n, int constraint_count, const OptimizerOptions& o) {
  nlopt::opt mlsl(nlopt::G_MLSL_LDS, n);
  mlsl.set_lower_bounds(std::vector<double>(n, 0.0));
  mlsl.set_upper_bounds(std::vector<double>(n, 1.0));
  mlsl.set_local_optimizer(local_search(o.local_algorithm, n, o.relative_tolerance));
  if (constraint_count == 0) return mlsl;
  mlsl.set_maxeval(std::max(10 * static_cast<int>(n + 1), o.max_evaluations / 3));
  nlopt::opt outer(nlopt::AUGLAG, n);
  outer.set_local_optimizer(mlsl);
  return outer;
}

nlopt::opt make_optimizer(unsigned n, int constraint_count, const OptimizerOptions& o) {
  if (o.algorithm == "cobyla") return nlopt::opt(nlopt::LN_COBYLA, n);
  if (o.algorithm == "isres") {
    nlopt::opt isres(nlopt::GN_ISRES, n);
    isres.set_population(std::max(20u, 10 * (n + 1)));
    return isres;
  }
  if (o.algorithm == "bobyqa") {
    nlopt::opt outer(nlopt::AUGLAG, n);
    outer.set_local_optimizer(local_search("bobyqa", n, 1e-6));
    return outer;
  }
  if (o.algorithm == "mlsl") return make_mlsl(n, constraint_count, o);
  throw InputError("optimizer: unknown algorithm '" + o.algorithm +
                   "' (expected cobyla, bobyqa, isres or mlsl)");
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
  if (o.starts < 1) throw InputError("optimizer: starts must be at least 1");
  if (o.starts > 1 && !is_local(o.algorithm))
    throw InputError("optimizer: --starts applies to the local algorithms (cobyla, bobyqa); " +
                     o.algorithm + " scatters its own points");
  if (!(o.max_time_s >= 0.0) || !std::isfinite(o.max_time_s))
    throw InputError("optimizer: max time must be a finite number of seconds >= 0");
}

// Start points in [0, 1]^n: the user's (or the middle), then a Latin hypercube of the rest so
// every start lies in a different slice of each variable's range. Seeded, so reproducible.
std::vector<std::vector<double>> start_points(const std::vector<DesignVariable>& variables,
                                              const OptimizerOptions& o) {
  const std::size_t n = variables.size();
  std::vector<std::vector<double>> points(1, std::vector<double>(n, 0.5));
  for (std::size_t i = 0; i < o.start.size(); ++i)
    points[0][i] = (o.start[i] - variables[i].lower) / (variables[i].upper - variables[i].lower);
  const int scattered = o.starts - 1;
  if (scattered == 0) return points;
  std::mt19937 rng(o.seed);
  auto uniform = [&rng] { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; };
  std::vector<std::vector<double>> lhs(scattered, std::vector<double>(n));
  for (std::size_t d = 0; d < n; ++d) {
    std::vector<int> slice(scattered);
    std::iota(slice.begin(), slice.end(), 0);
    for (int i = scattered - 1; i > 0; --i)
      std::swap(slice[i], slice[rng() % static_cast<std::uint32_t>(i + 1)]);
    for (int i = 0; i < scattered; ++i) lhs[i][d] = (slice[i] + uniform()) / scattered;
  }
  points.insert(points.end(), lhs.begin(), lhs.end());
  return points;
}

// One NLopt run; returns its nlopt_result code (a time-budget stop reported as such).
int run_nlopt(nlopt::opt& opt, std::vector<double> x, const ScaledProblem& problem,
              std::string& failure) {
  double value = 0.0;
  try {
    return opt.optimize(x, value);
  } catch (const nlopt::roundoff_limited&) {
    return NLOPT_ROUNDOFF_LIMITED;
  } catch (const nlopt::forced_stop&) {
    return problem.time_up() ? NLOPT_MAXTIME_REACHED : NLOPT_MAXEVAL_REACHED;
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("optimizer: NLopt rejected the problem: ") + e.what());
  } catch (const std::runtime_error& e) {
    failure = std::string("NLopt failed: ") + e.what();
    return NLOPT_FAILURE;
  }
}

StopKind stop_kind(int code) {
  if (nlopt_result_converged(code)) return StopKind::Converged;
  if (code == NLOPT_MAXEVAL_REACHED) return StopKind::MaxEvaluations;
  if (code == NLOPT_MAXTIME_REACHED) return StopKind::MaxTime;
  if (code == NLOPT_ROUNDOFF_LIMITED) return StopKind::RoundoffLimited;
  return StopKind::Failed;
}

// The whole search's reason: the time budget wins, then an exhausted evaluation budget, then
// convergence of any start.
StopKind overall_stop(const std::vector<int>& codes) {
  std::vector<StopKind> kinds;
  for (int c : codes) kinds.push_back(stop_kind(c));
  for (StopKind k : {StopKind::MaxTime, StopKind::MaxEvaluations, StopKind::Converged})
    if (std::find(kinds.begin(), kinds.end(), k) != kinds.end()) return k;
  return kinds.empty() ? StopKind::Failed : kinds.back();
}

int representative_code(StopKind kind) {
  switch (kind) {
    case StopKind::MaxTime:
      return NLOPT_MAXTIME_REACHED;
    case StopKind::MaxEvaluations:
      return NLOPT_MAXEVAL_REACHED;
    case StopKind::Converged:
      return NLOPT_SUCCESS;
    case StopKind::RoundoffLimited:
      return NLOPT_ROUNDOFF_LIMITED;
    case StopKind::Failed:
      break;
  }
  return NLOPT_FAILURE;
}

// One start: NLopt's own words. Several: the overall reason, then each start's.
std::string describe_stop(const OptimizerResult& r) {
  if (r.starts.size() == 1) return r.starts[0].stop_reason;
  std::string text = describe_nlopt_result(representative_code(r.stop));
  if (r.starts.empty()) return text;
  text += " (" + std::to_string(r.starts.size()) + " starts:";
  for (std::size_t s = 0; s < r.starts.size(); ++s)
    text += (s ? "; " : " ") + std::to_string(s + 1) + ": " + r.starts[s].stop_reason;
  return text + ")";
}

void pick_best(OptimizerResult& result) {
  const EvaluationRecord* best = best_record(result.history);
  if (!best) {
    const bool any_impossible = std::any_of(result.history.begin(), result.history.end(),
                                            [](const EvaluationRecord& r) { return r.impossible; });
    result.stop_reason +=
        any_impossible ? "; no evaluation gave a valid design" : "; every evaluation failed";
    return;
  }
  result.best = best->values;
  result.best_objective = best->objective;
  result.feasible = best->feasible;
}

}  // namespace

const char* to_string(StopKind kind) {
  switch (kind) {
    case StopKind::Converged:
      return "converged";
    case StopKind::MaxEvaluations:
      return "max_evaluations";
    case StopKind::MaxTime:
      return "max_time";
    case StopKind::RoundoffLimited:
      return "roundoff_limited";
    case StopKind::Failed:
      return "failed";
  }
  return "failed";
}

OptimizerResult optimize_design(const std::vector<DesignVariable>& variables,
                                const DesignFunction& f, int constraint_count,
                                const OptimizerOptions& options) {
  check_variables(variables, options);
  OptimizerResult result;
  result.algorithm = options.algorithm;
  const auto n = static_cast<unsigned>(variables.size());
  nlopt::srand(options.seed);
  ScaledProblem problem(variables, f, constraint_count, options, result);
  std::vector<ConstraintData> constraints;
  for (int i = 0; i < constraint_count; ++i) constraints.push_back({&problem, i});

  const auto points = start_points(variables, options);
  std::vector<int> codes;
  std::string failure;
  for (std::size_t s = 0; s < points.size(); ++s) {
    const int left = options.max_evaluations - result.evaluations;
    const double time_left = options.max_time_s - problem.elapsed();
    if (left <= 0 || (options.max_time_s > 0 && time_left <= 0)) break;
    nlopt::opt opt = make_optimizer(n, constraint_count, options);
    opt.set_lower_bounds(std::vector<double>(n, 0.0));
    opt.set_upper_bounds(std::vector<double>(n, 1.0));
    opt.set_min_objective(objective_callback, &problem);
    for (auto& c : constraints) opt.add_inequality_constraint(constraint_callback, &c, 1e-8);
    opt.set_xtol_rel(options.relative_tolerance);
    // The budget left is shared among the starts still to run; one that converges early leaves
    // its share to the next.
    // Counted in distinct designs (the problem stops the start at its share); NLopt's count,
    // which includes the repeats the cache answers, only guards against a search that repeats
    // itself without end.
    const int share = std::max(1, left / static_cast<int>(points.size() - s));
    problem.set_start_limit(result.evaluations + share);
    opt.set_maxeval(10 * share + 100);
    if (options.max_time_s > 0) opt.set_maxtime(time_left);
    problem.set_start(static_cast<int>(s) + 1);
    const int before = result.evaluations;
    int code = run_nlopt(opt, points[s], problem, failure);
    // NLopt's own cap with the share not spent: it asked for the points it had seen, over and
    // over (an infeasible corner), and makes no progress: not the budget.
    if (code == NLOPT_MAXEVAL_REACHED && result.evaluations - before < share && !problem.time_up())
      code = NLOPT_ROUNDOFF_LIMITED;
    problem.rethrow_caller_error();
    codes.push_back(code);
    result.starts.push_back(
        {problem.to_si(points[s]), result.evaluations - before,
         code == NLOPT_FAILURE && !failure.empty() ? failure : describe_nlopt_result(code)});
    if (problem.time_up()) break;
  }
  result.stop = overall_stop(codes);
  result.stop_reason = describe_stop(result);
  result.seconds = problem.elapsed();
  pick_best(result);
  return result;
}

}  // namespace mneedle
