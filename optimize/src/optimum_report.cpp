#include "mneedle/optimum_report.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace mneedle {

namespace {

// The history's records that `pick` selects, counted by their error text, commonest first.
template <class Pick>
std::vector<FailureCount> count_causes(const std::vector<EvaluationRecord>& history, Pick pick,
                                       int& total) {
  std::vector<FailureCount> causes;
  std::map<std::string, std::size_t> index;  // cause -> position in causes
  for (const EvaluationRecord& e : history) {
    if (!pick(e)) continue;
    ++total;
    const auto [it, inserted] = index.emplace(e.error, causes.size());
    if (inserted) causes.push_back({e.error, 0});
    ++causes[it->second].count;
  }
  std::stable_sort(causes.begin(), causes.end(),
                   [](const FailureCount& a, const FailureCount& b) { return a.count > b.count; });
  return causes;
}

}  // namespace

OptimumReport describe_optimum(const std::vector<DesignVariable>& variables,
                               const OptimizerResult& result, const OptimumTolerances& tol) {
  OptimumReport report;
  report.failures = count_causes(
      result.history, [](const EvaluationRecord& e) { return e.failed; }, report.failed);
  report.impossible_causes = count_causes(
      result.history, [](const EvaluationRecord& e) { return e.impossible; }, report.impossible);
  if (result.best.empty()) return report;

  for (const DesignVariable& v : variables) {
    const auto it = result.best.find(v.name);
    if (it == result.best.end()) continue;
    const double range = v.upper - v.lower;
    if (it->second - v.lower <= tol.bound * range) report.on_lower_bound.push_back(v.name);
    if (v.upper - it->second <= tol.bound * range) report.on_upper_bound.push_back(v.name);
  }
  const auto best =
      std::find_if(result.history.begin(), result.history.end(), [&](const EvaluationRecord& e) {
        return !e.failed && !e.impossible && e.values == result.best;
      });
  if (best == result.history.end()) return report;
  for (std::size_t i = 0; i < best->constraints.size(); ++i) {
    if (best->constraints[i] > tol.constraint)
      report.violated_constraints.push_back(static_cast<int>(i));
    else if (best->constraints[i] >= -tol.constraint)
      report.active_constraints.push_back(static_cast<int>(i));
  }
  return report;
}

}  // namespace mneedle
