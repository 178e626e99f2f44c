#include "mneedle/api/fit_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "mneedle/api/finite_json.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/measurement/layer_boundaries.h"

namespace mneedle {
namespace {

nlohmann::json finite_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

}  // namespace

constexpr int kMaxStarts = 1000;
constexpr std::size_t kMaxDetectedLayers = 10;

LoadedCurve load_fit_curve(const std::string& file, const CurveSettings& a) {
  const CurveColumns columns{a.depth_col, a.force_col, "", a.depth_unit, a.force_unit};
  LoadedCurve out;
  out.branch = extract_loading_branch(read_force_curve_csv(file, columns));
  out.curve.name = std::filesystem::path(file).filename().string();
  // Samples at a depth already passed (a rig that steps back, a digitised curve's repeats) are
  // merged into the sample they repeat, as toughness and energy do: kept, one stepping back
  // 5 mm made the fit's residual 12 times larger without a word.
  const MonotoneCurve merged = merge_repeated_depths(out.branch.curve);
  out.curve.depth_m = merged.curve.depth_m;
  out.curve.force_N = merged.curve.force_N;
  if (merged.receding_samples + merged.repeated_samples > 0)
    out.branch.summary += "; " + std::to_string(merged.receding_samples) +
                          " samples stepping back and " + std::to_string(merged.repeated_samples) +
                          " at a repeated depth merged into the samples before them";
  out.curve.conditions.speed_m_per_s =
      a.speed.empty() ? loading_speed(out.branch) : parse_quantity(a.speed, Dimension::Speed);
  out.curve.conditions.angle_rad =
      checked_insertion_angle(parse_quantity(a.angle, Dimension::Angle), "--angle");
  return out;
}

Dimension parameter_dimension(const std::string& name) {
  const auto base =
      name.substr(0, name.rfind("_L") == std::string::npos ? name.size() : name.rfind("_L"));
  const auto ends = [&](std::string_view s) {
    return base.size() >= s.size() && base.compare(base.size() - s.size(), s.size(), s) == 0;
  };
  if (ends("_per_m") || ends("_per_m2") || ends("_Ns")) return Dimension::Dimensionless;
  if (ends("_N")) return Dimension::Force;
  if (ends("_m")) return Dimension::Length;
  if (ends("_s")) return Dimension::Time;
  return Dimension::Dimensionless;
}

std::pair<std::string, double> parse_fixed_parameter(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw InputError("--fix '" + text + "': expected NAME=VALUE, e.g. mu=0.2");
  }
  const std::string name = text.substr(0, eq);
  try {
    return {name, parse_quantity(text.substr(eq + 1), parameter_dimension(name))};
  } catch (const InputError& e) {
    throw InputError("--fix " + name + ": " + e.what());
  }
}

nlohmann::json fit_json(const TriforceFit& fit, const std::vector<LoadedCurve>& curves) {
  nlohmann::json params = nlohmann::json::object(), errors = nlohmann::json::object();
  nlohmann::json fixed = nlohmann::json::array();
  for (const auto& p : fit.parameters) {
    params[p.name] = p.value;
    if (p.fitted) {
      errors[p.name] = finite_or_null(p.standard_error);
    } else {
      fixed.push_back(p.name);
    }
  }
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const auto& c = fit.curves[i];
    const auto& loaded = curves[i];
    list.push_back({{"file", c.name},
                    {"rmse_N", c.metrics.rmse_N},
                    {"r2", c.metrics.r2},
                    {"max_error_N", c.metrics.max_error_N},
                    {"samples", c.metrics.samples},
                    {"offset_m", c.offset_m},
                    {"offset_stderr_m", finite_or_null(c.offset_standard_error_m)},
                    {"contact_travel_m", loaded.branch.contact_travel_m},
                    {"speed_m_per_s", loaded.curve.conditions.speed_m_per_s},
                    {"angle_rad", loaded.curve.conditions.angle_rad},
                    {"peak_force_N",
                     *std::max_element(loaded.curve.force_N.begin(), loaded.curve.force_N.end())},
                    {"loading_branch", loaded.branch.summary}});
  }
  return {{"model", "triforce"},
          {"params", params},
          {"stderr", errors},
          {"fixed", fixed},
          {"curves", list},
          {"residual_sd_N", fit.residual_sd_N},
          {"samples_fitted", fit.samples},
          {"converged", fit.converged},
          {"starts", fit.starts}};
}

FitOutcome fit_recordings(const std::vector<std::string>& files, const FitSettings& s) {
  if (files.empty()) throw InputError("fit: no recording given");
  std::vector<LoadedCurve> curves;
  std::vector<FitCurve> data;
  for (const auto& f : files) {
    curves.push_back(load_fit_curve(f, s.curve));
    data.push_back(curves.back().curve);
  }
  // Bounded work: each start is a Levenberg-Marquardt run, each layer five more parameters and
  // a boundary to place (20 layers took 12 s, 50 over 90 s; 10^5 starts over 90 s).
  if (s.starts < 1 || s.starts > kMaxStarts)
    throw InputError("--starts " + std::to_string(s.starts) + ": must be 1 to " +
                     std::to_string(kMaxStarts));
  if (s.detect_layers > kMaxDetectedLayers)
    throw InputError("--detect-layers " + std::to_string(s.detect_layers) + ": must be at most " +
                     std::to_string(kMaxDetectedLayers));
  // The total, given and detected (detect_layers N adds up to N - 1 boundaries).
  const std::size_t layers =
      1 + s.layer_starts.size() + (s.detect_layers > 1 ? s.detect_layers - 1 : 0);
  if (layers > kMaxDetectedLayers)
    throw InputError("--layer-start and --detect-layers: up to " + std::to_string(layers) +
                     " layers, at most " + std::to_string(kMaxDetectedLayers));
  TriforceFitOptions options;
  options.starts = s.starts;
  for (const auto& start : s.layer_starts) {
    TriforceLayer layer = options.initial.layers.back();
    layer.start_m = parse_quantity(start, Dimension::Length);
    options.initial.layers.push_back(layer);
  }
  if (s.detect_layers > 1) {
    // Boundaries from the slope changes of the first curve (paper B's layer reading).
    const auto& first = curves.front().curve;
    for (double start : detect_layer_boundaries(first.depth_m, first.force_N, s.detect_layers)) {
      TriforceLayer layer = options.initial.layers.back();
      layer.start_m = start;
      options.initial.layers.push_back(layer);
    }
    std::sort(options.initial.layers.begin(), options.initial.layers.end(),
              [](const auto& a, const auto& b) { return a.start_m < b.start_m; });
  }
  for (const auto& text : s.fix) {
    const auto [name, value] = parse_fixed_parameter(text);
    if (!options.fixed.emplace(name, value).second)
      throw InputError("--fix " + name + ": given twice");
    if (std::find(s.free.begin(), s.free.end(), name) != s.free.end())
      throw InputError("--fix " + name + ": also given to --free; a parameter is one or the other");
  }
  options.free = s.free;
  FitOutcome out{std::move(curves), fit_triforce(data, options), {}, {}};
  for (const auto& l : options.initial.layers) out.initial_layer_starts_m.push_back(l.start_m);
  out.report = fit_json(out.fit, out.curves);
  require_finite_json(out.report, "fit");
  return out;
}

}  // namespace mneedle
