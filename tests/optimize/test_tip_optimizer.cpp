#include "mneedle/tip_optimizer.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>

#include "mneedle/base/error.h"

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

// Two minima along x: (x² − 1)² + 0.3 x + y². The global one is at x ≈ −1.04 (f ≈ −0.31), a
// local one at x ≈ +0.96 (f ≈ +0.29). Every search starts at x = 1.2, in the local basin.
mneedle::DesignScore two_wells(const std::map<std::string, double>& v) {
  const double x = v.at("x"), y = v.at("y");
  return {(x * x - 1) * (x * x - 1) + 0.3 * x + y * y, {}};
}
const std::vector<mneedle::DesignVariable> kWells = {{"x", -1.5, 2.5}, {"y", -1.0, 1.0}};
const std::vector<double> kWellsStart = {1.2, 0.3};
constexpr double kGlobalX = -1.0356;  // root of 4x(x² − 1) + 0.3 = 0 near −1
constexpr double kLocalX = 0.9603;

TEST(TipOptimizer, SingleLocalStartStaysInTheLocalMinimumOfTwoWells) {
  mneedle::OptimizerOptions o;
  o.start = kWellsStart;
  o.max_evaluations = 200;
  o.relative_tolerance = 1e-6;
  for (const char* algorithm : {"cobyla", "bobyqa"}) {
    o.algorithm = algorithm;
    const auto r = mneedle::optimize_design(kWells, two_wells, 0, o);
    EXPECT_NEAR(r.best.at("x"), kLocalX, 1e-2) << algorithm;
    EXPECT_EQ(r.starts.size(), 1u);
  }
}

TEST(TipOptimizer, MultiStartFindsTheGlobalMinimumOfTwoWells) {
  for (const char* algorithm : {"cobyla", "bobyqa"}) {
    mneedle::OptimizerOptions o;
    o.algorithm = algorithm;
    o.start = kWellsStart;
    o.starts = 4;
    o.max_evaluations = 800;
    o.seed = 7;
    const auto r = mneedle::optimize_design(kWells, two_wells, 0, o);
    EXPECT_NEAR(r.best.at("x"), kGlobalX, 1e-2) << algorithm;
    EXPECT_NEAR(r.best.at("y"), 0.0, 1e-2) << algorithm;
    EXPECT_EQ(r.starts.size(), 4u) << algorithm;
    EXPECT_LE(r.evaluations, 800) << algorithm;
    EXPECT_DOUBLE_EQ(r.starts[0].start.at("x"), 1.2) << algorithm;
    if (std::string(algorithm) == "bobyqa") {  // COBYLA may use a start's whole share here
      EXPECT_EQ(r.stop, mneedle::StopKind::Converged) << r.stop_reason;
    }
    // The scattered starts lie in different thirds of x's range (a Latin hypercube).
    std::set<int> thirds;
    for (std::size_t s = 1; s < r.starts.size(); ++s)
      thirds.insert(static_cast<int>((r.starts[s].start.at("x") + 1.5) / 4.0 * 3.0));
    EXPECT_EQ(thirds.size(), 3u) << algorithm;
  }
}

TEST(TipOptimizer, MlslFindsTheGlobalMinimumOfTwoWells) {
  for (const char* local : {"bobyqa", "cobyla"}) {
    mneedle::OptimizerOptions o;
    o.algorithm = "mlsl";
    o.local_algorithm = local;
    o.max_evaluations = 300;
    o.relative_tolerance = 1e-6;
    const auto r = mneedle::optimize_design(kWells, two_wells, 0, o);
    EXPECT_NEAR(r.best.at("x"), kGlobalX, 1e-2) << local;
    EXPECT_EQ(r.stop, mneedle::StopKind::MaxEvaluations) << local;  // MLSL runs to its budget
  }
}

TEST(TipOptimizer, MlslWithConstraintsFindsTheActiveConstraintOptimum) {
  mneedle::OptimizerOptions o;
  o.algorithm = "mlsl";
  o.max_evaluations = 600;
  o.relative_tolerance = 1e-7;
  const auto r = mneedle::optimize_design(kBox, constrained_bowl, 1, o);
  EXPECT_TRUE(r.feasible);
  EXPECT_NEAR(r.best.at("x"), 1.5, 2e-2);
  EXPECT_NEAR(r.best.at("y"), 0.5, 2e-2);
}

TEST(TipOptimizer, MultiStartIsDeterministicUnderASeedAndTheSeedMoves) {
  mneedle::OptimizerOptions o;
  o.starts = 5;
  o.max_evaluations = 150;
  o.seed = 3;
  const auto a = mneedle::optimize_design(kWells, two_wells, 0, o);
  const auto b = mneedle::optimize_design(kWells, two_wells, 0, o);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t i = 0; i < a.history.size(); ++i)
    EXPECT_EQ(a.history[i].values, b.history[i].values) << i;
  EXPECT_EQ(a.best, b.best);
  o.seed = 4;
  const auto c = mneedle::optimize_design(kWells, two_wells, 0, o);
  EXPECT_NE(a.starts[1].start, c.starts[1].start);
}

TEST(TipOptimizer, WallTimeBudgetStopsTheSearch) {
  // Each design takes 10 ms; 10 000 evaluations would take 100 s, the budget is 0.3 s.
  auto slow = [](const std::map<std::string, double>& v) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return two_wells(v);
  };
  for (const char* algorithm : {"cobyla", "isres"}) {
    mneedle::OptimizerOptions o;
    o.algorithm = algorithm;
    o.max_evaluations = 10000;
    o.relative_tolerance = 1e-15;
    o.max_time_s = 0.3;
    const auto r = mneedle::optimize_design(kWells, slow, 0, o);
    EXPECT_EQ(r.stop, mneedle::StopKind::MaxTime) << algorithm << ": " << r.stop_reason;
    EXPECT_NE(r.stop_reason.find("time"), std::string::npos) << r.stop_reason;
    EXPECT_LT(r.evaluations, 1000) << algorithm;
    EXPECT_GE(r.evaluations, 1) << algorithm;
    EXPECT_FALSE(r.best.empty());
  }
}

TEST(TipOptimizer, EvaluationBudgetIsReportedAsTheStopReason) {
  mneedle::OptimizerOptions o;
  o.algorithm = "isres";
  o.max_evaluations = 50;
  const auto r = mneedle::optimize_design(kWells, two_wells, 0, o);
  EXPECT_EQ(r.stop, mneedle::StopKind::MaxEvaluations);
  EXPECT_EQ(r.evaluations, 50);
  EXPECT_STREQ(mneedle::to_string(r.stop), "max_evaluations");
}

TEST(TipOptimizer, ProgressIsReportedWithTheBestSoFar) {
  std::vector<mneedle::OptimizerProgress> seen;
  mneedle::OptimizerOptions o;
  o.max_evaluations = 40;
  o.progress_interval_s = 0.0;  // every evaluation
  o.progress = [&](const mneedle::OptimizerProgress& p) { seen.push_back(p); };
  const auto r = mneedle::optimize_design(kBox, constrained_bowl, 1, o);
  ASSERT_EQ(static_cast<int>(seen.size()), r.evaluations);
  for (std::size_t i = 1; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].evaluations, seen[i - 1].evaluations + 1);
    if (seen[i - 1].feasible) {
      EXPECT_TRUE(seen[i].feasible);
      EXPECT_LE(seen[i].best_objective, seen[i - 1].best_objective);
    }
  }
  EXPECT_TRUE(seen.back().feasible);
  EXPECT_DOUBLE_EQ(seen.back().best_objective, r.best_objective);
}

TEST(TipOptimizer, RejectsBadProblems) {
  mneedle::OptimizerOptions o;
  EXPECT_THROW(mneedle::optimize_design({}, constrained_bowl, 1, o), mneedle::InputError);
  EXPECT_THROW(mneedle::optimize_design({{"x", 1.0, 1.0}}, constrained_bowl, 1, o),
               mneedle::InputError);
  o.algorithm = "simplex-of-doom";
  EXPECT_THROW(mneedle::optimize_design(kBox, constrained_bowl, 1, o), mneedle::InputError);
  o.algorithm = "isres";
  o.starts = 3;  // global algorithms scatter their own points
  EXPECT_THROW(mneedle::optimize_design(kBox, constrained_bowl, 1, o), mneedle::InputError);
  o.algorithm = "mlsl";
  o.starts = 1;
  o.local_algorithm = "newton";
  EXPECT_THROW(mneedle::optimize_design(kBox, constrained_bowl, 1, o), mneedle::InputError);
}

}  // namespace

namespace {

TEST(TipOptimizer, EveryDistinctDesignReachesTheCallerOnceAsSoonAsItIsEvaluated) {
  mneedle::OptimizerOptions o;
  o.max_evaluations = 30;
  int calls = 0;
  o.on_evaluation = [&](const mneedle::EvaluationRecord&) { ++calls; };
  int evaluated = 0;
  auto f = [&](const std::map<std::string, double>& v) {
    EXPECT_EQ(calls, evaluated) << "a design was not reported before the next one started";
    ++evaluated;
    return constrained_bowl(v);
  };
  const auto r = mneedle::optimize_design(kBox, f, 1, o);
  EXPECT_EQ(calls, r.evaluations);
  EXPECT_EQ(calls, evaluated);
}

TEST(TipOptimizer, ExceptionFromTheEvaluationCallbackStopsTheSearchAndReachesTheCaller) {
  mneedle::OptimizerOptions o;
  o.max_evaluations = 30;
  int calls = 0;
  o.on_evaluation = [&](const mneedle::EvaluationRecord&) {
    if (++calls == 3) throw std::runtime_error("disk full");
  };
  try {
    mneedle::optimize_design(kBox, constrained_bowl, 1, o);
    FAIL() << "the callback's exception was swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "disk full");
  }
  EXPECT_EQ(calls, 3);
}

}  // namespace

namespace {

TEST(TipOptimizer, ImpossibleDesignsAreInfeasiblePointsNeverFailuresAndNeverTheBest) {
  // x > 1 is no design at all; the bowl's optimum (1.5, 0.5) lies there, so the best valid
  // design is on x = 1.
  auto f = [](const std::map<std::string, double>& v) {
    if (v.at("x") > 1.0) throw mneedle::InfeasibleDesign("x beyond 1 makes no shape");
    return constrained_bowl(v);
  };
  mneedle::OptimizerOptions o;
  o.max_evaluations = 200;
  const auto r = mneedle::optimize_design(kBox, f, 1, o);
  int impossible = 0;
  for (const auto& e : r.history) {
    EXPECT_FALSE(e.failed);
    if (e.impossible) {
      ++impossible;
      EXPECT_EQ(e.error, "x beyond 1 makes no shape");
      EXPECT_FALSE(e.feasible);
    }
  }
  EXPECT_GT(impossible, 0);
  ASSERT_FALSE(r.best.empty());
  EXPECT_LE(r.best.at("x"), 1.0);
}

TEST(TipOptimizer, OnlyImpossibleDesignsSaySoInTheStopReason) {
  auto f = [](const std::map<std::string, double>&) -> mneedle::DesignScore {
    throw mneedle::InfeasibleDesign("never a shape");
  };
  mneedle::OptimizerOptions o;
  o.max_evaluations = 5;
  const auto r = mneedle::optimize_design(kBox, f, 1, o);
  EXPECT_TRUE(r.best.empty());
  EXPECT_NE(r.stop_reason.find("no evaluation gave a valid design"), std::string::npos)
      << r.stop_reason;
}

}  // namespace
