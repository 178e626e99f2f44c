#pragma once
// Where an optimisation ended and what went wrong on the way (docs/model.md, "Optimisation"): an
// optimum on a bound says the box, not the physics, stopped the search; one on a constraint says
// which limit binds; failed evaluations are counted by cause so a user can fix the commonest.

#include <string>
#include <vector>

#include "mneedle/tip_optimizer.h"

namespace mneedle {

/// One failure cause and how many evaluations it sank.
struct FailureCount {
  std::string error;
  int count = 0;
};

struct OptimumReport {
  std::vector<std::string> on_lower_bound;  // variable names
  std::vector<std::string> on_upper_bound;
  std::vector<int> active_constraints;    // indices into the design's constraints
  std::vector<int> violated_constraints;  // an infeasible optimum's broken constraints
  int failed = 0;                         // failed evaluations in the history
  std::vector<FailureCount> failures;     // by cause, commonest first, ties by first occurrence
  int impossible = 0;                     // points that made no valid design (InfeasibleDesign)
  std::vector<FailureCount> impossible_causes;  // as `failures`

  /// Neither on a bound nor on (or beyond) a constraint.
  bool interior() const {
    return on_lower_bound.empty() && on_upper_bound.empty() && active_constraints.empty() &&
           violated_constraints.empty();
  }
};

struct OptimumTolerances {
  /// A variable within this fraction of its range from a bound is on it: ten times the
  /// optimiser's default relative tolerance on the scaled variables (OptimizerOptions), so a
  /// search that converged onto the bound is recognised.
  double bound = 1e-3;
  /// A constraint within this much of zero is active. Constraints are scaled so that 1 is the
  /// limit itself (a safety factor, a wall, a depth), so this is 1 % of the limit.
  double constraint = 1e-2;
};

/// Describes `result.best` against `variables` and the history's record of it. With no best
/// design (every evaluation failed) only the failure counts are filled.
OptimumReport describe_optimum(const std::vector<DesignVariable>& variables,
                               const OptimizerResult& result, const OptimumTolerances& tol = {});

}  // namespace mneedle
