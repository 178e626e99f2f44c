#pragma once
// `fit` as a library call: force–depth recordings read, paper B's tri-force model fitted to them
// jointly (Levenberg–Marquardt), and the fit as the JSON tree the CLI prints and Python returns
// (docs/model.md, "Tri-force model"; docs/cli.md, "fit").

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mneedle/measurement/force_curve.h"
#include "mneedle/measurement/triforce_fit.h"

namespace mneedle {

/// How a recording's columns are read; empty strings take the defaults (column names by prefix,
/// units from the column's bracket or suffix, speed from the time column).
struct CurveSettings {
  std::string depth_col;
  std::string force_col;
  std::string depth_unit;
  std::string force_unit;
  std::string speed;
  std::string angle = "90deg";  // needle to surface, paper B's convention
};

/// A recording's loading branch and the curve the fit sees.
struct LoadedCurve {
  LoadingBranch branch;
  FitCurve curve;
};

LoadedCurve load_fit_curve(const std::string& file, const CurveSettings& settings);

/// "NAME=VALUE" of --fix: the value in the unit the parameter's name implies (_N, _m, _s).
std::pair<std::string, double> parse_fixed_parameter(const std::string& text);

struct FitSettings {
  CurveSettings curve;
  std::vector<std::string> fix;           // NAME=VALUE
  std::vector<std::string> free;          // parameters to fit beyond the defaults
  std::vector<std::string> layer_starts;  // lengths with units: a layer starts there
  std::size_t detect_layers = 0;          // > 1: layer starts from the first curve's slopes
  int starts = 8;                         // Levenberg–Marquardt starts
};

struct FitOutcome {
  std::vector<LoadedCurve> curves;
  TriforceFit fit;
  std::vector<double> initial_layer_starts_m;  // where the fit started each layer (m)
  nlohmann::json report;                       // as `fit --json` prints it, checked finite
};

/// Reads every file and fits them jointly. InputError names the file or the setting.
FitOutcome fit_recordings(const std::vector<std::string>& files, const FitSettings& settings);

/// The report of a finished fit: {model, params, stderr (null: not identifiable), fixed, curves,
/// residual_sd_N, samples_fitted, converged, starts}.
nlohmann::json fit_json(const TriforceFit& fit, const std::vector<LoadedCurve>& curves);

}  // namespace mneedle
