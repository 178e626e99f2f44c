#include "mneedle/report/html_report.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "viewer_script.h"

namespace mneedle::report {
namespace {

using nlohmann::json;

// Text from a result (design names, notes, file names) goes into HTML escaped.
std::string esc(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string text_of(const json& j) {
  if (j.is_string()) return j.get<std::string>();
  if (j.is_null()) return "";
  return j.dump();
}

std::optional<double> number_at(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j.at(key).is_number()) return std::nullopt;
  return j.at(key).get<double>();
}

// A dimensional value with its unit, "—" when the result has none (not punctured, no margin).
std::string quantity(const json& j, const char* key, Dimension d) {
  const auto v = number_at(j, key);
  return v ? esc(format_quantity(*v, d)) : "—";
}

std::string plain_number(const json& j, const char* key) {
  const auto v = number_at(j, key);
  if (!v) return "—";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", *v);
  return buf;
}

std::string yes_no(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j.at(key).is_boolean()) return "—";
  return j.at(key).get<bool>() ? "yes" : "no";
}

// A curve of the result as a plot series: [{depth_m, force_N, ...}], checked point by point.
plot::Series curve_series(const json& curve, const std::string& label, const std::string& where) {
  if (!curve.is_array()) throw InputError(where + ": not a list of points");
  plot::Series s;
  s.label = label;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const json& p = curve[i];
    const auto depth = number_at(p, "depth_m"), force = number_at(p, "force_N");
    if (!depth || !force)
      throw InputError(where + "[" + std::to_string(i) + "]: needs numbers depth_m and force_N");
    s.x.push_back(*depth);
    s.y.push_back(*force);
  }
  return s;
}

std::optional<plot::Point> puncture_point(const json& puncture, const std::string& label) {
  const auto depth = number_at(puncture, "depth_m"), force = number_at(puncture, "force_N");
  if (!depth || !force) return std::nullopt;
  return plot::Point{label, *depth, *force};
}

const json& member(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key))
    throw InputError(where + ": the result has no '" + key + "'");
  return j.at(key);
}

// Force against depth: one series per needle (or design), the punctures marked; labels on the
// points only while they stay readable.
plot::Figure force_figure(const std::string& title) {
  plot::Figure f;
  f.title = title;
  f.x = {"depth below the surface", Dimension::Length, "", false};
  f.y = {"force on the needle", Dimension::Force, "", false};
  return f;
}

std::vector<plot::Figure> simulate_figures(const json& r, const std::string& where) {
  plot::Figure f = force_figure("force against depth");
  const json& needles = member(r, "needles", where);
  for (std::size_t k = 0; k < needles.size(); ++k) {
    const json& n = needles[k];
    const std::string name = text_of(n.value("name", json("needle " + std::to_string(k + 1))));
    const std::string at = where + ": needles[" + std::to_string(k) + "].curve";
    plot::Series s = curve_series(member(n, "curve", at), name, at);
    if (!s.x.empty()) f.series.push_back(std::move(s));
    if (n.contains("puncture"))
      if (auto p = puncture_point(n.at("puncture"), needles.size() <= 3 ? "puncture" : ""))
        f.points.push_back(*p);
  }
  if (needles.size() > 1 && r.contains("total_curve")) {
    plot::Series total = curve_series(r.at("total_curve"), "all needles", where + ": total_curve");
    if (!total.x.empty()) f.series.push_back(std::move(total));
  }
  if (f.series.empty()) return {};
  // A stopped run's curves end at its last step (docs/cli.md, "A run whose solver stops"): marked
  // there on the total (the one needle's curve, or the sum), as simulate --plot marks it.
  if (r.contains("stopped") && r.at("stopped").is_object()) {
    const plot::Series& last = f.series.back();
    f.points.push_back({"FE stopped", last.x.back(), last.y.back()});
  }
  return {f};
}

std::vector<plot::Figure> screen_figures(const json& r, const std::string& where) {
  plot::Figure f = force_figure("force against depth of every design");
  const json& designs = member(r, "designs", where);
  for (std::size_t k = 0; k < designs.size(); ++k) {
    const json& d = designs[k];
    if (!d.value("ok", false) || !d.contains("curve")) continue;
    const std::string at = where + ": designs[" + std::to_string(k) + "].curve";
    plot::Series s = curve_series(d.at("curve"), text_of(d.value("design", json(""))), at);
    if (!s.x.empty()) f.series.push_back(std::move(s));
    if (d.contains("puncture"))
      if (auto p = puncture_point(d.at("puncture"), "")) f.points.push_back(*p);
  }
  if (f.series.empty()) return {};
  return {f};
}

std::vector<plot::Figure> optimize_figures(const json& r, const std::string& where) {
  std::vector<plot::Figure> figures;
  const json& history = member(r, "history", where);
  const bool force_objective = r.value("objective", "") == "peak_force_N";
  plot::Figure h;
  h.title = "the search: objective of every evaluation";
  h.x = {"evaluation", Dimension::Dimensionless, "", false};
  // Without a puncture the objective is a stand-in beyond the target depth (docs/cli.md).
  h.y = {force_objective ? "objective: peak force" : "objective: puncture depth",
         force_objective ? Dimension::Force : Dimension::Length, "", false};
  plot::Series feasible{"feasible", {}, {}, plot::Mark::Dots};
  plot::Series infeasible{"infeasible", {}, {}, plot::Mark::Dots};
  for (std::size_t i = 0; i < history.size(); ++i) {
    const auto objective = number_at(history[i], "objective");
    if (!objective) continue;  // failed or impossible: no objective
    plot::Series& s = history[i].value("feasible", false) ? feasible : infeasible;
    s.x.push_back(static_cast<double>(i + 1));
    s.y.push_back(*objective);
  }
  for (plot::Series* s : {&feasible, &infeasible})
    if (!s->x.empty()) h.series.push_back(std::move(*s));
  if (!h.series.empty()) figures.push_back(std::move(h));

  const json& best = member(r, "best", where);
  if (best.contains("curve")) {
    plot::Figure f = force_figure("force against depth of the best design");
    plot::Series s = curve_series(best.at("curve"), "best design", where + ": best.curve");
    if (!s.x.empty()) f.series.push_back(std::move(s));
    const auto depth = number_at(best, "puncture_depth_m");
    const auto force = number_at(best, "puncture_force_N");
    if (depth && force) f.points.push_back({"puncture", *depth, *force});
    if (!f.series.empty()) figures.push_back(std::move(f));
  }
  return figures;
}

std::string section(const std::string& id, const std::string& heading, const std::string& body) {
  return "<section id=\"" + id + "\">\n<h2>" + esc(heading) + "</h2>\n" + body + "</section>\n";
}

std::string table(const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows,
                  const std::vector<std::string>& row_attributes = {}) {
  std::string t = "<table>\n<thead><tr>";
  for (const auto& h : header) t += "<th>" + esc(h) + "</th>";
  t += "</tr></thead>\n<tbody>\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    t += "<tr" + (i < row_attributes.size() ? row_attributes[i] : std::string()) + ">";
    for (const auto& cell : rows[i]) t += "<td>" + cell + "</td>";  // cells arrive escaped
    t += "</tr>\n";
  }
  return t + "</tbody>\n</table>\n";
}

// A table row is clickable when a needle of the 3-D view belongs to its entry of the result.
std::string needle_row_attribute(const std::vector<NeedleView>& views, std::size_t entry) {
  for (std::size_t i = 0; i < views.size(); ++i)
    if (views[i].entry >= 0 && static_cast<std::size_t>(views[i].entry) == entry)
      return " data-needle=\"" + std::to_string(i) + "\" class=\"viewable\"";
  return "";
}

std::string simulate_body(const json& r, const ReportInput& in) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> attributes;
  for (const json& n : member(r, "needles", in.source)) {
    const std::string name = text_of(n.value("name", json("")));
    const json p = n.value("puncture", json(nullptr));
    rows.push_back({esc(name), quantity(p, "depth_m", Dimension::Length),
                    quantity(p, "force_N", Dimension::Force),
                    quantity(p, "post_force_N", Dimension::Force),
                    quantity(n, "max_force_N", Dimension::Force),
                    p.is_object() ? esc(text_of(p.value("criterion", json("")))) : "no puncture",
                    yes_no(p, "at_first_contact")});
    attributes.push_back(needle_row_attribute(in.needles, rows.size() - 1));
  }
  std::string body = table({"needle", "puncture depth", "force at puncture", "force just after",
                            "largest force", "criterion", "at first contact"},
                           rows, attributes);
  body += "<p>Fidelity " + esc(text_of(r.value("fidelity", json("")))) + "; models run: ";
  for (const json& m : r.value("models_run", json::array())) body += esc(text_of(m)) + " ";
  body +=
      ". The puncture at first contact is the first step's depth, not resolved (docs/model.md, "
      "&ldquo;Criteria&rdquo;).</p>\n";
  // A run whose solver stopped part-way: its curves end there (docs/cli.md, "simulate").
  if (r.contains("stopped") && r.at("stopped").is_object()) {
    const json& stop = r.at("stopped");
    body += "<p class=\"notes\">The finite element run stopped after its step at " +
            quantity(stop, "depth_m", Dimension::Length) +
            " and the curves end there: " + esc(text_of(stop.value("reason", json("")))) +
            ". &ldquo;No puncture&rdquo; means none before that depth.</p>\n";
  }
  if (r.contains("energy_check") && r.at("energy_check").is_object()) {
    const json& e = r.at("energy_check");
    body += "<p>Energy check at " + quantity(e, "depth_m", Dimension::Length) + ": strain energy " +
            plain_number(e, "strain_energy_J") + " J against work " + plain_number(e, "work_J") +
            " J, relative difference " + plain_number(e, "relative_difference") + " (" +
            (e.value("passes", false) ? "passes" : "FAILS") + ").</p>\n";
  }
  std::string out = section("summary", "Puncture", body);
  out += section("strength", "Strength",
                 "<p>simulate does not check the needle's strength; <code>mneedle screen</code> "
                 "and <code>mneedle strength</code> give its capacity and margin.</p>\n");
  return out;
}

std::string screen_body(const json& r, const ReportInput& in) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> attributes;
  int rank = 0;
  for (const json& d : member(r, "designs", in.source)) {
    const std::string name = text_of(d.value("design", json("")));
    ++rank;
    if (!d.value("ok", false)) {
      rows.push_back({std::to_string(rank), esc(name), "error", "—", "—", "—", "—", "—", "—",
                      esc(text_of(d.value("error", json(""))))});
    } else {
      std::string notes;
      for (const json& n : d.value("notes", json::array())) notes += esc(text_of(n)) + " ";
      rows.push_back({std::to_string(rank), esc(name),
                      d.value("passes", false) ? "passes" : "fails",
                      quantity(d, "puncture_depth_m", Dimension::Length) +
                          (d.value("puncture_at_first_contact", false) ? " (first step)" : ""),
                      quantity(d, "puncture_force_N", Dimension::Force),
                      quantity(d, "peak_force_N", Dimension::Force),
                      quantity(d, "capacity_N", Dimension::Force), plain_number(d, "margin"),
                      esc(text_of(d.value("governing", json("")))), notes});
    }
    attributes.push_back(needle_row_attribute(in.needles, rows.size() - 1));
  }
  std::string body =
      "<p>Ranked by puncture depth, then puncture force; designs that never puncture after them, "
      "errors last. A design passes when it punctures before the target depth and its strength "
      "margin (capacity over the peak force) reaches the safety factor. Click a row to see the "
      "needle.</p>\n" +
      table({"rank", "design", "verdict", "puncture depth", "puncture force", "peak force",
             "capacity", "margin", "governed by", "notes"},
            rows, attributes);
  return section("ranking", "Ranking", body);
}

std::string optimize_body(const json& r, const ReportInput& in) {
  const json& best = member(r, "best", in.source);
  std::vector<std::vector<std::string>> params;
  const json units = r.value("parameter_units", json::object());
  const json all_params = best.value("params", json::object());
  for (const auto& [name, value] : all_params.items()) {
    const std::string unit = units.value(name, "");
    std::string shown = value.is_number() ? plain_number(all_params, name.c_str()) : "—";
    if (value.is_number() && unit == "m")
      shown = esc(format_quantity(value.get<double>(), Dimension::Length));
    else if (value.is_number() && unit == "rad")
      shown = esc(format_quantity(value.get<double>(), Dimension::Angle));
    bool varied = false;
    for (const json& v : r.value("variables", json::array()))
      varied = varied || v.value("name", "") == name;
    params.push_back({esc(name), shown, varied ? "varied" : "fixed"});
  }
  std::string body = "<p>" + esc(text_of(r.value("plugin", json("")))) + " searched by " +
                     esc(text_of(r.value("algorithm", json("")))) + " over " +
                     std::to_string(r.value("evaluations", 0)) + " evaluations; " +
                     esc(text_of(r.value("stop_reason", json("")))) + ". " +
                     (r.value("feasible", false)
                          ? "The best design meets every constraint."
                          : "No design met every constraint: this is the least-violated one.") +
                     "</p>\n" + table({"parameter", "value", ""}, params);
  body += table({"puncture depth", "puncture force", "peak force", "target depth"},
                {{quantity(best, "puncture_depth_m", Dimension::Length),
                  quantity(best, "puncture_force_N", Dimension::Force),
                  quantity(best, "peak_force_N", Dimension::Force),
                  quantity(best, "target_depth_m", Dimension::Length)}});
  std::string out = section("summary", "Best design", body);
  out += section("strength", "Strength",
                 table({"capacity", "margin", "safety factor"},
                       {{quantity(best, "capacity_N", Dimension::Force),
                         plain_number(best, "margin"), plain_number(best, "safety_factor")}}));

  std::vector<std::string> header{"#"};
  const json& variables = r.value("variables", json::array());
  for (const json& v : variables) header.push_back(text_of(v.value("name", json(""))) + " (SI)");
  header.insert(header.end(), {"objective (SI)", "feasible", "seconds", "error"});
  std::vector<std::vector<std::string>> rows;
  const json& history = member(r, "history", in.source);
  for (std::size_t i = 0; i < history.size(); ++i) {
    const json& e = history[i];
    std::vector<std::string> row{std::to_string(i + 1)};
    for (const json& v : variables)
      row.push_back(
          plain_number(e.value("values", json::object()), v.value("name", std::string()).c_str()));
    row.insert(row.end(), {plain_number(e, "objective"), yes_no(e, "feasible"),
                           plain_number(e, "seconds"), esc(text_of(e.value("error", json(""))))});
    rows.push_back(std::move(row));
  }
  out += section("history", "History",
                 "<details><summary>every evaluation (" + std::to_string(history.size()) +
                     ")</summary>\n" + table(header, rows) + "</details>\n");
  return out;
}

std::string provenance_body(const json& r, const json& made_by) {
  const json p = r.value("provenance", json::object());
  std::vector<std::vector<std::string>> rows;
  for (const char* key : {"tool", "version", "source_revision", "command", "time_utc", "seed"})
    if (p.contains(key) && !p.at(key).is_null())
      rows.push_back({key, "<code>" + esc(text_of(p.at(key))) + "</code>"});
  for (const char* key : {"fidelity", "model", "scene", "material"})
    if (r.contains(key) && r.at(key).is_string())
      rows.push_back({key, esc(r.at(key).get<std::string>())});
  std::string body = table({"", ""}, rows);
  std::vector<std::vector<std::string>> inputs;
  for (const json& i : p.value("inputs", json::array()))
    inputs.push_back({esc(text_of(i.value("role", json("")))),
                      esc(text_of(i.value("name", json("")))),
                      "<code>" + esc(text_of(i.value("sha256", json("")))) + "</code>"});
  if (!inputs.empty()) body += table({"input", "name", "SHA-256"}, inputs);
  if (made_by.is_object())
    body += "<p class=\"hint\">This page was written by <code>" +
            esc(text_of(made_by.value("command", json("")))) + "</code> (" +
            esc(text_of(made_by.value("tool", json("")))) + " " +
            esc(text_of(made_by.value("version", json("")))) + ", " +
            esc(text_of(made_by.value("source_revision", json("")))) + ", " +
            esc(text_of(made_by.value("time_utc", json("")))) + ").</p>\n";
  return section("inputs", "Inputs and provenance", body);
}

// The needles for the viewer: millimetres, six significant digits (a micrometre of a 1 mm
// needle is the fourth), the JSON kept inside its <script> element.
std::string needles_json(const std::vector<NeedleView>& views) {
  std::string out = "[";
  char buf[40];
  for (std::size_t k = 0; k < views.size(); ++k) {
    const TriangleMesh& m = views[k].mesh;
    // No < or > at all inside the element: "</script" would end it, "<!--" changes how the
    // browser looks for its end. JSON's \u escapes read back as the same characters.
    std::string quoted;
    for (char c : json(views[k].name).dump())
      quoted += c == '<'   ? std::string("\\u003c")
                : c == '>' ? std::string("\\u003e")
                           : std::string(1, c);
    out += (k ? ",\n" : "\n") + std::string("{\"name\":") + quoted +
           ",\"triangles\":" + std::to_string(m.triangles.size()) + ",\"positions\":[";
    for (std::size_t i = 0; i < m.vertices.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const double mm = m.vertices[i][c] * 1e3;
        if (!std::isfinite(mm))
          throw InputError("report: needle '" + views[k].name + "' has a non-finite vertex");
        std::snprintf(buf, sizeof buf, "%s%.6g", (i || c) ? "," : "", mm);
        out += buf;
      }
    out += "],\"indices\":[";
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
      for (int c = 0; c < 3; ++c) out += (t || c ? "," : "") + std::to_string(m.triangles[t][c]);
    out += "]}";
  }
  return out + "\n]";
}

std::string needle_view_section(const std::vector<NeedleView>& views) {
  if (views.empty())
    return section("needles", "Needles in 3-D",
                   "<p>No needle could be shown (the notes above say why).</p>\n");
  std::string body = "<label>needle <select id=\"needle-select\">";
  for (std::size_t i = 0; i < views.size(); ++i)
    body += "<option value=\"" + std::to_string(i) + "\">" + esc(views[i].name) + "</option>";
  body +=
      "</select></label>\n<div id=\"needle-view\"></div>\n<p id=\"needle-caption\"></p>\n"
      "<p class=\"hint\">The needle frame: tip at the origin, axis z, millimetres; the grid lies "
      "in the tissue surface at first contact.</p>\n";
  return section("needles", "Needles in 3-D", body);
}

constexpr const char* kStyle = R"css(
body { font-family: system-ui, sans-serif; margin: 2rem auto; max-width: 1100px; padding: 0 1rem;
       color: #222; line-height: 1.45; }
h1 { font-size: 1.5rem; margin-bottom: 0.2rem; }
h2 { font-size: 1.2rem; border-bottom: 1px solid #ddd; padding-bottom: 0.2rem; margin-top: 2rem; }
.sub { color: #666; margin-top: 0; }
table { border-collapse: collapse; margin: 0.6rem 0; font-size: 0.9rem; }
th, td { border: 1px solid #ddd; padding: 0.25rem 0.5rem; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
tr.viewable { cursor: pointer; }
tr.viewable:hover { background: #eef4fb; }
figure.plot { margin: 1rem 0; }
figure.plot svg { width: 100%; height: auto; max-width: 900px; border: 1px solid #eee; }
#needle-view { width: 100%; max-width: 900px; border: 1px solid #eee; }
#needle-view canvas { display: block; }
.notes { background: #fff8e1; border: 1px solid #f0d98c; padding: 0.5rem 1rem; }
.hint { color: #666; font-size: 0.85rem; }
code { font-size: 0.85rem; word-break: break-all; }
)css";

}  // namespace

ResultKind result_kind(const json& r, const std::string& where) {
  if (r.is_object() && r.contains("designs") && r.contains("ranking")) return ResultKind::Screen;
  if (r.is_object() && r.contains("history") && r.contains("best")) return ResultKind::Optimize;
  if (r.is_object() && r.contains("needles") && r.contains("total_curve"))
    return ResultKind::Simulate;
  throw InputError(where +
                   ": not a result of simulate, screen or optimize (no 'needles', 'designs' or "
                   "'history'; write one with --json or --report)");
}

std::vector<plot::Figure> report_figures(const json& r, const std::string& where) {
  try {
    switch (result_kind(r, where)) {
      case ResultKind::Simulate:
        return simulate_figures(r, where);
      case ResultKind::Screen:
        return screen_figures(r, where);
      case ResultKind::Optimize:
        return optimize_figures(r, where);
    }
  } catch (const json::exception& e) {
    // A key of the wrong type (a file edited by hand, or not ours): the user's input, not a bug.
    throw InputError(where + ": malformed result (" + e.what() + ")");
  }
  return {};
}

namespace {

std::string page_of(const ReportInput& in) {
  const json& r = in.result;
  const ResultKind kind = result_kind(r, in.source);
  const char* kind_name = kind == ResultKind::Simulate ? "simulate"
                          : kind == ResultKind::Screen ? "screen"
                                                       : "optimize";
  std::string scene;
  for (const json& i : r.value("provenance", json::object()).value("inputs", json::array()))
    if (i.value("role", "") == "scene") scene = text_of(i.value("name", json("")));
  if (scene.empty() && r.contains("scene")) scene = text_of(r.at("scene"));
  const std::string title =
      std::string("mneedle ") + kind_name + (scene.empty() ? "" : ": " + scene);

  std::string page =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>" +
      esc(title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n";
  const json p = r.value("provenance", json::object());
  page += "<header>\n<h1>" + esc(title) + "</h1>\n<p class=\"sub\">" +
          esc(text_of(p.value("tool", json("mneedle")))) + " " +
          esc(text_of(p.value("version", json("")))) + ", " +
          esc(text_of(p.value("time_utc", json("")))) + "; from " + esc(in.source) +
          "</p>\n</header>\n";
  if (!in.notes.empty()) {
    page += "<div class=\"notes\"><ul>\n";
    for (const auto& n : in.notes) page += "<li>" + esc(n) + "</li>\n";
    page += "</ul></div>\n";
  }
  switch (kind) {
    case ResultKind::Simulate:
      page += simulate_body(r, in);
      break;
    case ResultKind::Screen:
      page += screen_body(r, in);
      break;
    case ResultKind::Optimize:
      page += optimize_body(r, in);
      break;
  }
  std::string figures;
  for (const plot::Figure& f : report_figures(r, in.source))
    figures += "<figure class=\"plot\">\n" + plot::svg_element(f) + "\n</figure>\n";
  if (figures.empty()) figures = "<p>The result holds no curve to draw.</p>\n";
  page += section("curves", "Force against depth", figures);
  page += needle_view_section(in.needles);
  page += provenance_body(r, in.made_by);
  page += "<script type=\"application/json\" id=\"mneedle-needles\">" + needles_json(in.needles) +
          "</script>\n<script>\n";
  page += detail::viewer_script();
  page += "\n</script>\n</body>\n</html>\n";
  return page;
}

}  // namespace

std::string html_report(const ReportInput& in) {
  try {
    return page_of(in);
  } catch (const json::exception& e) {
    throw InputError(in.source + ": malformed result (" + e.what() + ")");
  }
}

void write_report(const std::filesystem::path& file, const ReportInput& input) {
  std::error_code kind;
  if (std::filesystem::is_directory(file, kind))
    throw InputError(file.string() + ": is a folder, not a file (name the report's .html file)");
  const std::string page = html_report(input);
  const auto tmp = std::filesystem::path(file.string() + ".tmp");
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw InputError(file.string() + ": cannot write the report");
    out << page;
    if (!out.flush()) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw InputError(file.string() + ": writing the report failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() overwrites ec ("Success")
    std::filesystem::remove(tmp, ec);
    throw InputError(file.string() + ": cannot write the report (" + why + ")");
  }
}

}  // namespace mneedle::report
