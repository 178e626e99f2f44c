// The pure half of bench/speed_accuracy.cpp: relative errors against the scene's reference, the
// probe force on a two-stage curve, the Markdown table and the SVG (one marker per run, no NaN).
#include "speed_accuracy_report.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace mneedle::bench {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

RunOutcome outcome(const std::string& label, double seconds, std::optional<double> depth,
                   std::optional<double> force, std::optional<double> probe) {
  RunOutcome r;
  r.scene = "skin";
  r.needle = "sharp_bevel";
  r.label = label;
  r.group = label;
  r.model = "fe_3d half, TET10, 100 nodes";
  r.seconds = seconds;
  r.puncture_depth_m = depth;
  r.puncture_force_N = force;
  r.probe_force_N = probe;
  return r;
}

std::vector<RunOutcome> sample_runs() {
  RunOutcome ref = outcome("fine", 100.0, 100e-6, 10e-3, 50e-3);
  ref.is_reference = true;
  ref.group = "reference";
  RunOutcome failed = outcome("standard", 3.0, std::nullopt, std::nullopt, std::nullopt);
  failed.error = "3-D indentation: Newton diverged at depth 40 um";
  return {ref, outcome("fast", 2.0, 120e-6, 8e-3, 60e-3),
          outcome("analytic", 0.01, std::nullopt, std::nullopt, 25e-3), failed,
          outcome("fine", 60.0, 100e-6, 10e-3, 50e-3)};
}

TEST(SpeedAccuracyReport, RelativeErrorIsTheFractionOfTheReference) {
  EXPECT_NEAR(*relative_error(110e-6, 100e-6), 0.1, 1e-12);
  EXPECT_NEAR(*relative_error(9e-3, 10e-3), 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(*relative_error(-3.0, -2.0), 0.5);
  EXPECT_FALSE(relative_error(1.0, 0.0));
  EXPECT_FALSE(relative_error(std::nullopt, 1.0));
  EXPECT_FALSE(relative_error(1.0, std::nullopt));
}

TEST(SpeedAccuracyReport, ARunWithoutPunctureHasOnlyTheProbeError) {
  const std::vector<RunOutcome> runs = sample_runs();
  const ErrorRow e = errors_against(runs[2], runs[0]);
  EXPECT_TRUE(e.puncture_mismatch);
  EXPECT_FALSE(e.depth);
  EXPECT_FALSE(e.force);
  EXPECT_DOUBLE_EQ(*e.probe, 0.5);
  EXPECT_DOUBLE_EQ(*worst_error(e), 0.5);
  const ErrorRow fast = errors_against(runs[1], runs[0]);
  EXPECT_FALSE(fast.puncture_mismatch);
  EXPECT_NEAR(*worst_error(fast), 0.2, 1e-12);
}

TEST(SpeedAccuracyReport, ProbeReadsTheCurveAcrossThePuncture) {
  // Pre-puncture to 150 um, then the post-puncture curve (duplicate depth at the puncture).
  const std::vector<CurvePoint> curve{
      {100e-6, 10e-3}, {150e-6, 20e-3}, {150e-6, 5e-3}, {250e-6, 15e-3}};
  EXPECT_NEAR(*force_at(curve, 50e-6), 5e-3, 1e-15);    // from zero at zero depth
  EXPECT_NEAR(*force_at(curve, 150e-6), 20e-3, 1e-15);  // at the puncture: before it
  EXPECT_NEAR(*force_at(curve, 200e-6), 10e-3, 1e-15);  // past it: the post-puncture branch
  EXPECT_FALSE(force_at(curve, 300e-6));                // beyond the curve
  EXPECT_FALSE(force_at({}, 200e-6));
}

TEST(SpeedAccuracyReport, TableNamesTheReferenceTheFailureAndTheNonPuncture) {
  const std::string table = markdown_table(sample_runs());
  EXPECT_EQ(count(table, "\n"), 2u + 5u);  // header, rule, one line per run
  EXPECT_NE(table.find("**reference: fine**"), std::string::npos);
  EXPECT_NE(table.find("**failed**: 3-D indentation: Newton diverged at depth 40 um"),
            std::string::npos);
  EXPECT_NE(table.find("| none |"), std::string::npos);
  EXPECT_NE(table.find("no puncture (reference does)"), std::string::npos);
  EXPECT_NE(table.find("| 20.0 | 20.0 | 20.0 |"), std::string::npos);  // fast: 20 % each
  EXPECT_EQ(table.find("nan"), std::string::npos);
}

TEST(SpeedAccuracyReport, FigureHasOnePointPerComparedRunInPercentByLevel) {
  const std::vector<RunOutcome> runs = sample_runs();
  const plot::Figure f = speed_accuracy_figure(runs);
  // Plotted: fast, analytic, fine (exact: drawn on the floor); not the reference or the failure.
  std::size_t points = 0;
  for (const plot::Series& s : f.series) {
    points += s.x.size();
    EXPECT_EQ(s.mark, plot::Mark::Dots);
    for (double y : s.y) EXPECT_GE(y, 100.0 * kPlotErrorFloor);
  }
  EXPECT_EQ(points, 3u);
  ASSERT_EQ(f.series.size(), 3u);
  EXPECT_EQ(f.series[0].label, "analytic (no FE)");
  EXPECT_DOUBLE_EQ(f.series[0].y[0], 50.0);  // only the probe, 50 % off
  EXPECT_EQ(f.series[1].label, "fast");
  EXPECT_NEAR(f.series[1].y[0], 20.0, 1e-12);  // 20 % off in each
  EXPECT_EQ(f.series[2].label, "fine");
  EXPECT_DOUBLE_EQ(f.series[2].y[0], 100.0 * kPlotErrorFloor);  // exact: on the floor
  EXPECT_TRUE(f.x.logarithmic);
  EXPECT_TRUE(f.y.logarithmic);
  EXPECT_EQ(f.y.unit, "%");
}

}  // namespace
}  // namespace mneedle::bench
