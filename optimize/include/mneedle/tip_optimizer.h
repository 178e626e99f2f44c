#pragma once
// NLopt searches over named design parameters (docs/model.md, "Optimisation"): scaled bounds, an
// evaluation cache, failed evaluations as penalised points, infeasible problems reported as such,
// multi-start and MLSL for problems with more than one minimum, evaluation and wall-time budgets.

#include <functional>
#include <map>
#include <stdexcept>
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

/// Thrown by a DesignFunction for parameters that make no valid design (a bevel longer than the
/// needle): the point is infeasible, not a failure of the evaluation, and is never the best.
class InfeasibleDesign : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using DesignFunction = std::function<DesignScore(const std::map<std::string, double>& values)>;

/// A snapshot for a progress line: how far the search is and what it has found.
struct OptimizerProgress {
  int evaluations = 0;
  double best_objective = 0.0;  // best feasible, else the least-violated design's objective
  bool feasible = false;        // whether any feasible design has been found
  double elapsed_s = 0.0;
  int start = 1;  // which of the multi-start runs is going (1-based)
  int starts = 1;
};

struct EvaluationRecord {
  std::map<std::string, double> values;
  double objective = 0.0;
  std::vector<double> constraints;
  bool feasible = false;
  bool failed = false;      // the evaluation threw: `error` says why
  bool impossible = false;  // InfeasibleDesign: no valid design there; `error` says why
  std::string error;
  double seconds = 0.0;
  int start = 1;  // the multi-start run that asked for it (1-based)
};

struct OptimizerOptions {
  /// cobyla | bobyqa (inside AUGLAG) | isres | mlsl (NLopt's MLSL with low-discrepancy points and
  /// the local algorithm below, inside AUGLAG when there are constraints)
  std::string algorithm = "cobyla";
  std::string local_algorithm = "bobyqa";  // mlsl's local search: cobyla | bobyqa
  int starts = 1;  // local algorithms: runs from the start point and scattered points, best kept
  int max_evaluations = 100;         // distinct designs over all starts
  double max_time_s = 0.0;           // wall time over all starts; 0 = no limit
  double relative_tolerance = 1e-4;  // on the scaled variables
  unsigned seed = 1;                 // scattered starts, ISRES and MLSL
  std::vector<double> start;         // SI; empty = the middle of the bounds
  double progress_interval_s = 2.0;  // at most one progress call per interval
  std::function<void(const OptimizerProgress&)> progress;  // optional
  /// Called once per distinct design, as soon as it is evaluated (optional): lets a caller write
  /// its history as it goes, so a killed run keeps what it evaluated. Its exceptions stop the
  /// search and reach the caller.
  std::function<void(const EvaluationRecord&)> on_evaluation;
};

/// One local run of a multi-start search.
struct StartRecord {
  std::map<std::string, double> start;  // SI
  int evaluations = 0;                  // distinct designs this run added
  std::string stop_reason;
};

/// Why the whole search stopped, as a short key for JSON and scripts.
enum class StopKind { Converged, MaxEvaluations, MaxTime, RoundoffLimited, Failed };
const char* to_string(StopKind kind);

struct OptimizerResult {
  std::map<std::string, double> best;  // best feasible, else least violated
  double best_objective = 0.0;
  bool feasible = false;
  int evaluations = 0;  // distinct designs evaluated (cache hits not counted)
  std::string algorithm;
  StopKind stop = StopKind::Converged;
  std::string stop_reason;  // human-readable, with the per-start reasons for a multi-start
  double seconds = 0.0;
  std::vector<StartRecord> starts;
  std::vector<EvaluationRecord> history;
};

/// Runs NLopt on `f` over `variables`. InputError for empty or inverted bounds, an unknown
/// algorithm, a start point outside the bounds, or --starts with a global algorithm.
OptimizerResult optimize_design(const std::vector<DesignVariable>& variables,
                                const DesignFunction& f, int constraint_count,
                                const OptimizerOptions& options);

}  // namespace mneedle
