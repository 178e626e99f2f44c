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

std::string escape_xml(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string value_cells(const RunOutcome& r) {
  const std::string depth =
      r.puncture_depth_m ? scaled(r.puncture_depth_m, 1e6, "%.1f") : std::string("none");
  return depth + " | " + scaled(r.puncture_force_N, 1e3, "%.3g") + " | " +
         scaled(r.probe_force_N, 1e3, "%.4g");
}

// Plot layout (px).
constexpr double kWidth = 820.0, kHeight = 520.0;
constexpr double kLeft = 70.0, kRight = 250.0, kTop = 30.0, kBottom = 60.0;

struct LogAxis {
  double lo = 0.0, hi = 1.0;  // decades (log10)
  double to_px(double value, double px_lo, double px_hi) const {
    return px_lo + (std::log10(value) - lo) / (hi - lo) * (px_hi - px_lo);
  }
};

LogAxis axis_for(const std::vector<double>& values) {
  double lo = std::log10(*std::min_element(values.begin(), values.end()));
  double hi = std::log10(*std::max_element(values.begin(), values.end()));
  LogAxis a{std::floor(lo), std::ceil(hi)};
  if (a.hi <= a.lo) a.hi = a.lo + 1.0;
  return a;
}

const char* needle_colour(const std::string& needle) {
  if (needle == "sharp_bevel") return "#1f77b4";
  if (needle == "blunt_bevel") return "#d62728";
  if (needle == "cylinder") return "#2ca02c";
  return "#7f7f7f";
}

// One marker of `group`'s shape centred on (x, y); class "run" marks it for counting.
std::string marker(const std::string& group, double x, double y, const std::string& colour,
                   bool filled, const std::string& title) {
  const std::string style = "fill=\"" + (filled ? colour : std::string("white")) + "\" stroke=\"" +
                            colour + "\" stroke-width=\"1.6\"";
  const std::string t = title.empty() ? "" : "<title>" + escape_xml(title) + "</title>";
  std::ostringstream s;
  s.precision(5);
  const double r = 5.5;
  if (group == "fast") {
    s << "<polygon class=\"run\" points=\"" << x << "," << y - r << " " << x + r << ","
      << y + r * 0.8 << " " << x - r << "," << y + r * 0.8 << "\" " << style << ">" << t
      << "</polygon>";
  } else if (group == "fine") {
    s << "<rect class=\"run\" x=\"" << x - r * 0.85 << "\" y=\"" << y - r * 0.85 << "\" width=\""
      << 1.7 * r << "\" height=\"" << 1.7 * r << "\" " << style << ">" << t << "</rect>";
  } else if (group == "analytic") {
    s << "<polygon class=\"run\" points=\"" << x << "," << y - r << " " << x + r << "," << y << " "
      << x << "," << y + r << " " << x - r << "," << y << "\" " << style << ">" << t
      << "</polygon>";
  } else if (group == "unreduced") {
    s << "<polygon class=\"run\" points=\"" << x << "," << y + r << " " << x + r << ","
      << y - r * 0.8 << " " << x - r << "," << y - r * 0.8 << "\" " << style << ">" << t
      << "</polygon>";
  } else if (group == "override") {  // a line shape: plus when filled, cross when hollow
    const double d = filled ? 0.0 : r * 0.75;
    const double a = filled ? r : r * 0.75;
    s << "<path class=\"run\" d=\"M" << x - a << "," << y - d << "L" << x + a << "," << y + d << "M"
      << x + d << "," << y - a << "L" << x - d << "," << y + a << "\" fill=\"none\" stroke=\""
      << colour << "\" stroke-width=\"2.2\">" << t << "</path>";
  } else {  // standard
    s << "<circle class=\"run\" cx=\"" << x << "\" cy=\"" << y << "\" r=\"" << r << "\" " << style
      << ">" << t << "</circle>";
  }
  return s.str();
}

std::string text(double x, double y, const std::string& body, const char* anchor = "start") {
  std::ostringstream s;
  s.precision(5);
  s << "<text x=\"" << x << "\" y=\"" << y << "\" text-anchor=\"" << anchor << "\">"
    << escape_xml(body) << "</text>";
  return s.str();
}

std::string decade_label(double decade) {
  const double v = std::pow(10.0, decade);
  return format(v >= 1.0 ? "%.0f" : decade >= -3 ? "%g" : "%.0e", v);
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

// Legend markers are not runs: class "key" keeps them out of a count of runs.
std::string as_key(std::string m) {
  return m.replace(m.find("class=\"run\""), 11, "class=\"key\"");
}

std::string legend(double x0) {
  std::ostringstream s;
  double y = kTop + 10.0;
  s << text(x0, y, "colour: needle") << "\n";
  for (const char* n : {"sharp_bevel", "blunt_bevel", "cylinder"}) {
    y += 18.0;
    s << as_key(marker("standard", x0 + 8.0, y - 4.0, needle_colour(n), true, ""))
      << text(x0 + 20.0, y, n) << "\n";
  }
  y += 26.0;
  s << text(x0, y, "shape: level") << "\n";
  const std::pair<const char*, const char*> groups[] = {{"analytic", "analytic (no FE)"},
                                                        {"fast", "fast"},
                                                        {"standard", "standard"},
                                                        {"fine", "fine"},
                                                        {"unreduced", "reduction switched off"},
                                                        {"override", "override (TET4, domain)"}};
  for (const auto& [g, name] : groups) {
    y += 18.0;
    s << as_key(marker(g, x0 + 8.0, y - 4.0, "#333333", true, "")) << text(x0 + 20.0, y, name)
      << "\n";
  }
  y += 26.0;
  s << text(x0, y, "filled: human skin") << "\n";
  s << text(x0, y + 18.0, "hollow: silicone phantom") << "\n";
  s << text(x0, y + 36.0, "(override: + skin, x silicone)") << "\n";
  s << text(x0, y + 62.0, "error: worst of puncture") << "\n";
  s << text(x0, y + 80.0, "depth, puncture force and") << "\n";
  s << text(x0, y + 98.0, "F(200 um) vs the reference;") << "\n";
  s << text(x0, y + 116.0, "below 0.01 % drawn at 0.01 %") << "\n";
  return s.str();
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

std::string svg_plot(const std::vector<RunOutcome>& runs) {
  const std::vector<PlotPoint> points = plot_points(runs);
  std::vector<double> times{1e-3, 1.0}, errors{kPlotErrorFloor, 1.0};
  for (const PlotPoint& p : points) {
    times.push_back(p.seconds);
    errors.push_back(p.error);
  }
  const LogAxis tx = axis_for(times), ey = axis_for(errors);
  const double x0 = kLeft, x1 = kWidth - kRight, y0 = kHeight - kBottom, y1 = kTop;
  std::ostringstream s;
  s.precision(5);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidth << "\" height=\"" << kHeight
    << "\" viewBox=\"0 0 " << kWidth << " " << kHeight
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  // Decade grid and labels.
  for (double d = tx.lo; d <= tx.hi + 1e-9; d += 1.0) {
    const double x = tx.to_px(std::pow(10.0, d), x0, x1);
    s << "<line x1=\"" << x << "\" y1=\"" << y0 << "\" x2=\"" << x << "\" y2=\"" << y1
      << "\" stroke=\"#dddddd\"/>" << text(x, y0 + 16.0, decade_label(d), "middle") << "\n";
  }
  for (double d = ey.lo; d <= ey.hi + 1e-9; d += 1.0) {
    const double y = ey.to_px(std::pow(10.0, d), y0, y1);
    s << "<line x1=\"" << x0 << "\" y1=\"" << y << "\" x2=\"" << x1 << "\" y2=\"" << y
      << "\" stroke=\"#dddddd\"/>" << text(x0 - 6.0, y + 4.0, decade_label(d + 2.0), "end") << "\n";
  }
  s << "<rect x=\"" << x0 << "\" y=\"" << y1 << "\" width=\"" << x1 - x0 << "\" height=\""
    << y0 - y1 << "\" fill=\"none\" stroke=\"black\"/>\n";
  s << text((x0 + x1) / 2.0, kHeight - 18.0, "wall time of the run [s]", "middle") << "\n";
  s << "<text x=\"18\" y=\"" << (y0 + y1) / 2.0
    << "\" text-anchor=\"middle\" transform=\"rotate(-90 18 " << (y0 + y1) / 2.0
    << ")\">worst error against the reference [%]</text>\n";
  s << text((x0 + x1) / 2.0, 18.0, "mneedle: speed against accuracy (paper A needles)", "middle")
    << "\n";
  for (const PlotPoint& p : points) {
    const RunOutcome& r = *p.run;
    s << marker(r.group, tx.to_px(p.seconds, x0, x1), ey.to_px(p.error, y0, y1),
                needle_colour(r.needle), r.scene == "skin",
                r.scene + ", " + r.needle + ", " + r.label)
      << "\n";
  }
  s << legend(x1 + 20.0) << "</svg>\n";
  return s.str();
}

}  // namespace mneedle::bench
