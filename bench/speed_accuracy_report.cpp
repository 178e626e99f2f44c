#include "speed_accuracy_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace mneedle::bench {
namespace {

std::string format(const char* pattern, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, pattern, value);
  return buffer;
}

std::string percent(const std::optional<double>& e) {
  if (!e) return "–";
  return format(*e < 0.001 ? "%.3f" : *e < 0.1 ? "%.2f" : "%.1f", *e * 100.0);
}

std::string scaled(const std::optional<double>& v, double factor, const char* pattern) {
  return v ? format(pattern, *v * factor) : std::string("–");
}

// Markdown cells must not contain a bar or a line break.
std::string cell(std::string text) {
  for (char& c : text)
    if (c == '|' || c == '\n') c = c == '|' ? '/' : ' ';
  return text;
}

std::string value_cells(const RunOutcome& r) {
  const std::string depth =
      r.puncture_depth_m ? scaled(r.puncture_depth_m, 1e6, "%.1f") : std::string("none");
  return depth + " | " + scaled(r.puncture_force_N, 1e3, "%.3g") + " | " +
         scaled(r.probe_force_N, 1e3, "%.4g");
}

struct PlotPoint {
  double seconds;
  double error;
  const RunOutcome* run;
};

std::vector<PlotPoint> plot_points(const std::vector<RunOutcome>& runs) {
  std::vector<PlotPoint> points;
  for (const RunOutcome& r : runs) {
    if (r.is_reference || !r.error.empty() || !(r.seconds > 0.0)) continue;
    const RunOutcome* ref = reference_for(runs, r);
    if (ref == nullptr) continue;
    const std::optional<double> worst = worst_error(errors_against(r, *ref));
    if (!worst || !std::isfinite(*worst)) continue;
    points.push_back({r.seconds, std::max(*worst, kPlotErrorFloor), &r});
  }
  return points;
}

}  // namespace

std::optional<double> force_at(const std::vector<CurvePoint>& curve, double depth_m) {
  if (curve.empty() || curve.back().depth_m < depth_m) return std::nullopt;
  CurvePoint before;  // the undeformed start: no force at zero depth
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const CurvePoint& p = curve[i];
    if (p.depth_m < depth_m) {
      before = p;
      continue;
    }
    if (p.depth_m == depth_m) {
      // At a puncture listed twice the probe reads the pre-puncture force (first point).
      return p.force_N;
    }
    const double span = p.depth_m - before.depth_m;
    const double t = span > 0.0 ? (depth_m - before.depth_m) / span : 1.0;
    return before.force_N + t * (p.force_N - before.force_N);
  }
  return std::nullopt;
}

std::optional<double> relative_error(std::optional<double> value, std::optional<double> reference) {
  if (!value || !reference || *reference == 0.0) return std::nullopt;
  if (!std::isfinite(*value) || !std::isfinite(*reference)) return std::nullopt;
  return std::abs(*value - *reference) / std::abs(*reference);
}

ErrorRow errors_against(const RunOutcome& run, const RunOutcome& reference) {
  ErrorRow row;
  row.puncture_mismatch =
      run.puncture_depth_m.has_value() != reference.puncture_depth_m.has_value();
  row.depth = relative_error(run.puncture_depth_m, reference.puncture_depth_m);
  row.force = relative_error(run.puncture_force_N, reference.puncture_force_N);
  row.probe = relative_error(run.probe_force_N, reference.probe_force_N);
  return row;
}

std::optional<double> worst_error(const ErrorRow& row) {
  std::optional<double> worst;
  for (const std::optional<double>& e : {row.depth, row.force, row.probe})
    if (e) worst = std::max(worst.value_or(0.0), *e);
  return worst;
}

const RunOutcome* reference_for(const std::vector<RunOutcome>& runs, const RunOutcome& run) {
  for (const RunOutcome& r : runs)
    if (r.is_reference && r.error.empty() && r.scene == run.scene && r.needle == run.needle)
      return &r;
  return nullptr;
}

std::string markdown_table(const std::vector<RunOutcome>& runs) {
  std::ostringstream s;
  s << "| Tissue | Needle | Level / reduction | What ran | Time [s] | CPU [s] | Puncture depth "
       "[µm] | "
       "Puncture force [mN] | F(200 µm) [mN] | Depth error % | Force error % | "
       "F(200 µm) error % |\n";
  s << "|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (const RunOutcome& r : runs) {
    s << "| " << r.scene << " | " << r.needle << " | "
      << (r.is_reference ? "**reference: " + cell(r.label) + "**" : cell(r.label)) << " | ";
    if (!r.error.empty()) {
      s << "**failed**: " << cell(r.error) << " | " << format("%.3g", r.seconds) << " | "
        << format("%.3g", r.cpu_seconds) << " | – | – | – | – | – | – |\n";
      continue;
    }
    s << cell(r.model) << " | " << format("%.3g", r.seconds) << " | "
      << format("%.3g", r.cpu_seconds) << " | " << value_cells(r) << " | ";
    const RunOutcome* ref = reference_for(runs, r);
    if (r.is_reference || ref == nullptr) {
      s << (r.is_reference ? "ref | ref | ref |\n" : "no reference | – | – |\n");
      continue;
    }
    const ErrorRow e = errors_against(r, *ref);
    const std::string mismatch =
        r.puncture_depth_m ? "reference does not puncture" : "no puncture (reference does)";
    s << (e.puncture_mismatch ? mismatch : percent(e.depth)) << " | "
      << (e.puncture_mismatch ? "–" : percent(e.force)) << " | " << percent(e.probe) << " |\n";
  }
  return s.str();
}

plot::Figure speed_accuracy_figure(const std::vector<RunOutcome>& runs) {
  plot::Figure f;
  f.title = "speed against accuracy (paper A needles, skin and silicone)";
  f.x = {"wall time of the run", Dimension::Time, "", true};
  f.y = {"worst error against the reference", Dimension::Dimensionless, "%", true};
  // One series per level or reduction, in the order a reader compares them.
  const std::pair<const char*, const char*> groups[] = {{"analytic", "analytic (no FE)"},
                                                        {"fast", "fast"},
                                                        {"standard", "standard"},
                                                        {"fine", "fine"},
                                                        {"unreduced", "reduction switched off"},
                                                        {"override", "override (TET4, domain)"}};
  const std::vector<PlotPoint> points = plot_points(runs);
  for (const auto& [group, label] : groups) {
    plot::Series s{label, {}, {}, plot::Mark::Dots};
    for (const PlotPoint& p : points)
      if (p.run->group == group) {
        s.x.push_back(p.seconds);
        s.y.push_back(100.0 * p.error);
      }
    if (!s.x.empty()) f.series.push_back(std::move(s));
  }
  return f;
}

}  // namespace mneedle::bench
