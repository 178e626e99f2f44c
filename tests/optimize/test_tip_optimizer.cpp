#include "mneedle/tip_optimizer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mneedle/error.h"

namespace {

// min (x − 2)² + (y − 1)² subject to x + y ≤ 2: the constraint is active, optimum (1.5, 0.5).
mneedle::DesignScore constrained_bowl(const std::map<std::string, double>& v) {
  const double x = v.at("x"), y = v.at("y");
  return {(x - 2) * (x - 2) + (y - 1) * (y - 1), {x + y - 2.0}};
}

const std::vector<mneedle::DesignVariable> kBox = {{"x", -3.0, 3.0}, {"y", -3.0, 3.0}};

TEST(TipOptimizer, FindsTheAnalyticOptimumOnItsActiveConstraint) {
  for (const char* algorithm : {"cobyla", "bobyqa"}) {
    mneedle::OptimizerOptions o;
    o.algorithm = algorithm;
    o.max_evaluations = 400;
    o.relative_tolerance = 1e-7;
    const auto r = mneedle::optimize_design(kBox, constrained_bowl, 1, o);
    EXPECT_TRUE(r.feasible) << algorithm;
    EXPECT_NEAR(r.best.at("x"), 1.5, 2e-3) << algorithm;
    EXPECT_NEAR(r.best.at("y"), 0.5, 2e-3) << algorithm;
    EXPECT_LE(r.evaluations, 400);
  }
}

TEST(TipOptimizer, InfeasibleProblemReportsTheLeastViolatedDesign) {
  // x ≥ 5 inside x ∈ [−3, 3]: never feasible; the least violation is at x = 3.
  auto f = [](const std::map<std::string, double>& v) {
    return mneedle::DesignScore{v.at("x") * v.at("x"), {5.0 - v.at("x")}};
  };
  mneedle::OptimizerOptions o;
  o.max_evaluations = 200;
  const auto r = mneedle::optimize_design({{"x", -3.0, 3.0}}, f, 1, o);
  EXPECT_FALSE(r.feasible);
  EXPECT_NEAR(r.best.at("x"), 3.0, 1e-2);
}

TEST(TipOptimizer, FailedEvaluationsArePenalisedNotFatal) {
  auto f = [](const std::map<std::string, double>& v) {
    if (v.at("x") > 1.0) throw mneedle::SolverError("no convergence");
    return mneedle::DesignScore{(v.at("x") - 0.5) * (v.at("x") - 0.5), {}};
  };
  mneedle::OptimizerOptions o;
  o.max_evaluations = 100;
  const auto r = mneedle::optimize_design({{"x", -3.0, 3.0}}, f, 0, o);
  EXPECT_TRUE(r.feasible);
  EXPECT_NEAR(r.best.at("x"), 0.5, 1e-2);
  bool saw_failure = false;
  for (const auto& e : r.history) saw_failure = saw_failure || e.failed;
  EXPECT_TRUE(saw_failure);
}

TEST(TipOptimizer, GlobalSearchIsDeterministicUnderASeed) {
  mneedle::OptimizerOptions o;
  o.algorithm = "isres";
  o.max_evaluations = 300;
  o.seed = 42;
  const auto a = mneedle::optimize_design(kBox, constrained_bowl, 1, o);
  const auto b = mneedle::optimize_design(kBox, constrained_bowl, 1, o);
  EXPECT_EQ(a.best, b.best);
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_NEAR(a.best.at("x") + a.best.at("y"), 2.0, 0.2);
}

TEST(TipOptimizer, RejectsBadProblems) {
  mneedle::OptimizerOptions o;
  EXPECT_THROW(mneedle::optimize_design({}, constrained_bowl, 1, o), mneedle::InputError);
  EXPECT_THROW(mneedle::optimize_design({{"x", 1.0, 1.0}}, constrained_bowl, 1, o),
               mneedle::InputError);
  o.algorithm = "simplex-of-doom";
  EXPECT_THROW(mneedle::optimize_design(kBox, constrained_bowl, 1, o), mneedle::InputError);
}

}  // namespace
