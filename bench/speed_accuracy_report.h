#pragma once
// The pure half of bench/speed_accuracy.cpp (docs/speed-accuracy.md): relative errors of a run
// against its scene's reference, the Markdown table and the hand-written log-log SVG of error
// against time. No solver here, so tests/bench/test_speed_accuracy_report.cpp can check it with
// made-up runs.

#include <optional>
#include <string>
#include <vector>

#include "mneedle/plot/figure.h"

namespace mneedle::bench {

/// Depth at which the "force at depth" column is read (paper A's 200 um array target).
inline constexpr double kProbeDepth_m = 200e-6;

/// Errors smaller than this are drawn on the floor of the plot (a log axis has no zero).
inline constexpr double kPlotErrorFloor = 1e-4;

struct CurvePoint {
  double depth_m = 0.0;
  double force_N = 0.0;
};

/// What one run of the insertion gave. `error` non-empty: the run failed and only the label,
/// the time and the message mean anything.
struct RunOutcome {
  std::string scene;   ///< tissue: "skin", "silicone"
  std::string needle;  ///< "sharp_bevel", "blunt_bevel", "cylinder"
  std::string label;   ///< the level or reduction, e.g. "standard, full model"
  std::string group;   ///< plot marker: analytic, fast, standard, fine, unreduced, override
  std::string model;   ///< what ran, e.g. "fe_3d half, TET10, 13485 nodes"
  bool is_reference = false;
  double seconds = 0.0;      ///< wall time of run_insertion
  double cpu_seconds = 0.0;  ///< process CPU time of it (all threads): robust on a shared machine
  std::string error;
  std::optional<double> puncture_depth_m;
  std::optional<double> puncture_force_N;
  std::optional<double> probe_force_N;  ///< force at kProbeDepth_m on the run's curve
};

/// Force on a curve at `depth_m`, linear between points from zero force at zero depth. A depth
/// listed twice (the puncture: pre- then post-puncture force) reads the first point when probed
/// exactly there and the second beyond it; nullopt when the curve does not reach the depth.
std::optional<double> force_at(const std::vector<CurvePoint>& curve, double depth_m);

/// |value - reference| / |reference|; nullopt when either is missing or the reference is zero.
std::optional<double> relative_error(std::optional<double> value, std::optional<double> reference);

struct ErrorRow {
  std::optional<double> depth;
  std::optional<double> force;
  std::optional<double> probe;
  /// One of run and reference punctures, the other does not: depth and force have no error.
  bool puncture_mismatch = false;
};

ErrorRow errors_against(const RunOutcome& run, const RunOutcome& reference);

/// Largest of the row's errors; nullopt when it has none.
std::optional<double> worst_error(const ErrorRow& row);

/// The reference of `run`'s scene and needle in `runs`; nullptr when there is none (or it failed).
const RunOutcome* reference_for(const std::vector<RunOutcome>& runs, const RunOutcome& run);

/// Markdown table: one row per run (the reference first in its block, with its values).
std::string markdown_table(const std::vector<RunOutcome>& runs);

/// Log-log figure of the worst error (%) against wall time (s): one point per successful
/// non-reference run that has an error (below kPlotErrorFloor drawn on it), one series per group
/// (analytic, fast, standard, fine, reduction switched off, override), drawn by plot/.
plot::Figure speed_accuracy_figure(const std::vector<RunOutcome>& runs);

}  // namespace mneedle::bench
