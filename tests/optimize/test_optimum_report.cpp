#include "mneedle/optimum_report.h"

#include <gtest/gtest.h>

namespace {

using mneedle::EvaluationRecord;
using mneedle::OptimizerResult;

const std::vector<mneedle::DesignVariable> kBox = {{"x", 0.0, 10.0}, {"y", -1.0, 1.0}};

EvaluationRecord record(double x, double y, std::vector<double> constraints) {
  EvaluationRecord e;
  e.values = {{"x", x}, {"y", y}};
  e.constraints = std::move(constraints);
  e.feasible = true;
  for (double c : e.constraints) e.feasible = e.feasible && c <= 0.0;
  return e;
}

EvaluationRecord failure(const std::string& error) {
  EvaluationRecord e;
  e.failed = true;
  e.error = error;
  return e;
}

OptimizerResult result_with_best(const EvaluationRecord& best) {
  OptimizerResult r;
  r.history = {record(4.0, 0.5, {-0.5}), best};
  r.best = best.values;
  r.evaluations = 2;
  return r;
}

TEST(OptimumReport, OptimumAwayFromBoundsAndConstraintsIsInterior) {
  const auto report = mneedle::describe_optimum(kBox, result_with_best(record(3.0, 0.2, {-0.3})));
  EXPECT_TRUE(report.interior());
  EXPECT_EQ(report.failed, 0);
}

TEST(OptimumReport, OptimumWithinATenthOfAPercentOfTheRangeIsOnThatBound) {
  // 1e-3 of the ranges 10 and 2 (OptimumTolerances::bound): 0.0099 from x's lower bound is on
  // it, 0.0021 below y's upper bound is not.
  const auto report =
      mneedle::describe_optimum(kBox, result_with_best(record(0.0099, 1.0 - 0.0021, {-0.3})));
  EXPECT_EQ(report.on_lower_bound, std::vector<std::string>{"x"});
  EXPECT_TRUE(report.on_upper_bound.empty());
  const auto upper =
      mneedle::describe_optimum(kBox, result_with_best(record(5.0, 1.0 - 0.0019, {-0.3})));
  EXPECT_EQ(upper.on_upper_bound, std::vector<std::string>{"y"});
  EXPECT_FALSE(upper.interior());
}

TEST(OptimumReport, ConstraintWithinOnePercentOfItsLimitIsActive) {
  const auto report =
      mneedle::describe_optimum(kBox, result_with_best(record(5.0, 0.0, {-0.2, -0.009, 0.0})));
  EXPECT_EQ(report.active_constraints, (std::vector<int>{1, 2}));
  EXPECT_FALSE(report.interior());
}

TEST(OptimumReport, FailuresAreCountedByCauseCommonestFirst) {
  OptimizerResult r = result_with_best(record(5.0, 0.0, {-0.4}));
  r.history.push_back(failure("mesh: open"));
  r.history.push_back(failure("solver: diverged"));
  r.history.push_back(failure("solver: diverged"));
  const auto report = mneedle::describe_optimum(kBox, r);
  EXPECT_EQ(report.failed, 3);
  ASSERT_EQ(report.failures.size(), 2u);
  EXPECT_EQ(report.failures[0].error, "solver: diverged");
  EXPECT_EQ(report.failures[0].count, 2);
  EXPECT_EQ(report.failures[1].error, "mesh: open");
  EXPECT_EQ(report.failures[1].count, 1);
}

TEST(OptimumReport, EveryEvaluationFailedGivesOnlyTheFailureCounts) {
  OptimizerResult r;
  r.history = {failure("a"), failure("a")};
  const auto report = mneedle::describe_optimum(kBox, r);
  EXPECT_EQ(report.failed, 2);
  EXPECT_TRUE(report.on_lower_bound.empty());
  EXPECT_TRUE(report.active_constraints.empty());
}

}  // namespace

namespace {

TEST(OptimumReport, InfeasibleOptimumListsTheConstraintsItBreaks) {
  const auto report =
      mneedle::describe_optimum(kBox, result_with_best(record(5.0, 0.0, {0.3, -0.005, -0.4})));
  EXPECT_EQ(report.violated_constraints, std::vector<int>{0});
  EXPECT_EQ(report.active_constraints, std::vector<int>{1});
  EXPECT_FALSE(report.interior());
}

TEST(OptimumReport, ImpossibleDesignsAreCountedApartFromFailures) {
  OptimizerResult r = result_with_best(record(5.0, 0.0, {-0.4}));
  EvaluationRecord impossible;
  impossible.impossible = true;
  impossible.error = "bevel longer than the needle";
  r.history.push_back(impossible);
  r.history.push_back(failure("solver: diverged"));
  const auto report = mneedle::describe_optimum(kBox, r);
  EXPECT_EQ(report.failed, 1);
  EXPECT_EQ(report.impossible, 1);
  ASSERT_EQ(report.impossible_causes.size(), 1u);
  EXPECT_EQ(report.impossible_causes[0].error, "bevel longer than the needle");
}

}  // namespace
