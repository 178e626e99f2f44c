#pragma once
// NLopt searches over named design parameters (issue 6 §2): scaled bounds, an evaluation cache,
// failed evaluations as penalised points, infeasible problems reported as such.

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace mneedle {

struct DesignVariable {
  std::string name;
  double lower = 0.0;  // SI
  double upper = 0.0;  // SI
};

/// What one design scores: the objective to minimise and constraints that are satisfied when
/// <= 0 (each named, for the history). Throwing marks the design as failed.
struct DesignScore {
  double objective = 0.0;
  std::vector<double> constraints;
};

using DesignFunction = std::function<DesignScore(const std::map<std::string, double>& values)>;

struct OptimizerOptions {
  std::string algorithm = "cobyla";  // cobyla | bobyqa (inside AUGLAG) | isres
  int max_evaluations = 100;
  double max_time_s = 0.0;           // 0 = no limit
  double relative_tolerance = 1e-4;  // on the scaled variables
  unsigned seed = 1;
  std::vector<double> start;  // SI; empty = the middle of the bounds
  std::function<void(int evaluation, double best)> progress;  // optional, serialised
};

struct EvaluationRecord {
  std::map<std::string, double> values;
  double objective = 0.0;
  std::vector<double> constraints;
  bool feasible = false;
  bool failed = false;
  std::string error;
  double seconds = 0.0;
};

struct OptimizerResult {
  std::map<std::string, double> best;  // best feasible, else least violated
  double best_objective = 0.0;
  bool feasible = false;
  int evaluations = 0;  // distinct designs evaluated (cache hits not counted)
  std::string algorithm;
  std::string stop_reason;
  std::vector<EvaluationRecord> history;
};

/// Runs NLopt on `f` over `variables`. InputError for empty or inverted bounds, an unknown
/// algorithm, or a start point outside the bounds.
OptimizerResult optimize_design(const std::vector<DesignVariable>& variables,
                                const DesignFunction& f, int constraint_count,
                                const OptimizerOptions& options);

}  // namespace mneedle
