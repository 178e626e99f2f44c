// mneedle toughness: fracture toughness J from two insertions into the same spot (paper A eqs.
// 13-14).
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/measurement/force_curve.h"
#include "mneedle/measurement/toughness.h"
#include "mneedle/plot/figure.h"
#include "option_values.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct ToughnessArgs {
  std::string first;
  std::string second;
  std::string second_from;
  std::string area;
  std::string needle;
  std::string unit = "mm";
  std::string plugin;
  std::vector<std::string> settings;
  std::vector<std::string> plugin_dirs;
  std::string depth_col, force_col, depth_unit, force_unit;
  std::string align = "contact";
  std::string max_depth;
  std::string integrand;
  std::string plot;  // SVG of F, F' and F - F' against depth
  bool json = false;
};

struct CrackAreaChoice {
  double area_m2 = 0.0;
  std::string source;                  // "given" or the needle's name
  std::optional<CrackArea> from_mesh;  // when measured on a needle
};

// A number with `digits` significant digits, for the summary lines.
std::string sig(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string format_energy(double joules) {
  const double a = std::abs(joules);
  if (a >= 1.0 || a == 0.0) return sig(joules) + " J";
  if (a >= 1e-3) return sig(joules * 1e3) + " mJ";
  if (a >= 1e-6) return sig(joules * 1e6) + " uJ";
  return sig(joules * 1e9) + " nJ";
}

std::string format_toughness(double j) {
  if (std::abs(j) >= 1e3) return sig(j * 1e-3) + " kJ/m^2";
  return sig(j) + " J/m^2";
}

CrackAreaChoice crack_area(const ToughnessArgs& a, double end_depth_m) {
  const int given = !a.area.empty() + !a.needle.empty() + !a.plugin.empty();
  if (given != 1) throw InputError("toughness: give exactly one of --area, --needle or --plugin");
  // Options of another crack-area source would be ignored in silence.
  if (!a.settings.empty() && a.plugin.empty())
    throw InputError("toughness: --set needs --plugin (it sets the plugin's parameters)");
  CrackAreaChoice out;
  if (!a.area.empty()) {
    try {
      out.area_m2 = parse_area_m2(a.area);
    } catch (const InputError& e) {
      throw InputError(std::string("toughness: --area: ") + e.what());
    }
    out.source = "given";
    return out;
  }
  const auto registry = PluginRegistry::discover({a.plugin_dirs.begin(), a.plugin_dirs.end()});
  const NeedleSource needle =
      a.needle.empty()
          ? needle_from_plugin(registry, a.plugin,
                               parse_parameter_settings(registry.shape(a.plugin), a.settings))
          : needle_from_file(a.needle, option_length_unit(a.unit));
  if (a.needle.empty())
    record_mesh(needle.name, needle.mesh);
  else
    record_input("needle", a.needle);
  out.from_mesh = needle_crack_area(needle.mesh, end_depth_m);
  out.area_m2 = out.from_mesh->area_m2;
  out.source = needle.name;
  if (!(out.area_m2 > 0.0)) {
    throw InputError("toughness: needle '" + needle.name + "' has no cross-section at " +
                     format_quantity(end_depth_m, Dimension::Length) + " above its tip");
  }
  return out;
}

InsertionPass load_pass(const std::string& file, const ToughnessArgs& a) {
  const CurveColumns columns{a.depth_col, a.force_col, "", a.depth_unit, a.force_unit};
  InsertionPass pass = prepare_pass(read_force_curve_csv(file, columns));
  record_input("curve", file);
  return pass;
}

// --max-depth as a length; zero or negative is refused, not read as "no limit".
double parse_max_depth(const std::string& text) {
  double metres = 0.0;
  try {
    metres = parse_quantity(text, Dimension::Length);
  } catch (const InputError& e) {
    throw InputError("--max-depth: " + std::string(e.what()));
  }
  if (!(metres > 0.0)) {
    throw InputError("--max-depth '" + text + "': must be a positive length, e.g. 0.5mm");
  }
  return metres;
}

void write_integrand(const std::string& path, const ForceDifference& d) {
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot write the integrand file");
  out << "depth_m,first_force_N,second_force_N,difference_N\n" << std::setprecision(10);
  for (std::size_t i = 0; i < d.depth_m.size(); ++i) {
    out << d.depth_m[i] << "," << d.first_force_N[i] << "," << d.second_force_N[i] << ","
        << d.first_force_N[i] - d.second_force_N[i] << "\n";
  }
  if (!out) throw InputError(path + ": writing the integrand failed");
}

nlohmann::json cut_json(const PassCut& c) {
  return {{"file", c.source},
          {"rows", c.rows},
          {"points", c.points},
          {"contact_travel_m", c.contact_travel_m},
          {"baseline_N", c.baseline_N},
          {"noise_N", c.noise_N},
          {"cut",
           {{"before_contact", c.before_contact},
            {"hold", c.hold},
            {"retraction", c.retraction},
            {"repeated_depth", c.repeated_depth},
            {"receding_depth", c.receding_depth},
            {"beyond_end", c.beyond_end}}}};
}

std::string cut_line(const PassCut& c) {
  std::ostringstream s;
  s << c.source << ": " << c.points << " points used";
  if (c.rows > 0) s << " of " << c.rows << " rows";
  s << " (contact at travel " << format_quantity(c.contact_travel_m, Dimension::Length)
    << ", baseline " << format_quantity(c.baseline_N, Dimension::Force) << " removed); cut "
    << c.before_contact << " before contact, " << c.hold << " in the hold, " << c.retraction
    << " in the retraction, " << c.beyond_end << " beyond the end; merged " << c.repeated_depth
    << " repeated and " << c.receding_depth << " receding depths";
  return s.str();
}

void run_toughness(const ToughnessArgs& a) {
  if (a.second.empty() == a.second_from.empty())
    throw InputError("toughness: give either SECOND.csv or --second-from retraction|tail");
  const InsertionPass first = load_pass(a.first, a);
  std::optional<ForceDrop> drop;
  InsertionPass second;
  if (!a.second.empty()) {
    second = load_pass(a.second, a);
  } else if (a.second_from == "retraction") {
    const CurveColumns columns{a.depth_col, a.force_col, "", a.depth_unit, a.force_unit};
    second = second_pass_from_retraction(read_force_curve_csv(a.first, columns), first);
  } else if (a.second_from == "tail") {
    drop.emplace();
    second = second_pass_from_tail(first, &*drop);
  } else {
    throw InputError("--second-from '" + a.second_from + "': expected retraction or tail");
  }
  ToughnessOptions options;
  options.alignment = parse_depth_alignment(a.align);
  if (!a.max_depth.empty()) options.max_depth_m = parse_max_depth(a.max_depth);
  const ForceDifference d = force_difference(first, second, options);
  const CrackAreaChoice area = crack_area(a, d.end_depth_m);
  const double j = toughness_J_per_m2(d, area.area_m2);
  if (!a.integrand.empty()) write_integrand(a.integrand, d);
  if (!a.plot.empty()) {
    plot::Figure f;
    f.title = "toughness: J = " + format_toughness(j);
    f.x.name = "depth from contact";
    std::vector<double> difference;
    for (std::size_t i = 0; i < d.depth_m.size(); ++i)
      difference.push_back(d.first_force_N[i] - d.second_force_N[i]);
    f.series.push_back({"first pass F", d.depth_m, d.first_force_N, plot::Mark::Line});
    f.series.push_back({"second pass F'", d.depth_m, d.second_force_N, plot::Mark::Line});
    f.series.push_back({"F - F'", d.depth_m, difference, plot::Mark::Line});
    if (drop) f.points.push_back({"puncture", drop->peak_depth_m, drop->peak_force_N});
    plot::write_svg(a.plot, f);
  }

  nlohmann::json warnings = nlohmann::json::array();
  if (j < 0.0)
    warnings.push_back(
        "the second pass took more work than the first: J < 0 has no physical "
        "meaning (misaligned depths, or not the same hole?)");
  if (area.from_mesh && d.end_depth_m > area.from_mesh->needle_length_m)
    warnings.push_back(
        "the insertion is deeper than the needle mesh is long: its top section "
        "was used as the crack area");
  nlohmann::json out = {
      {"toughness_J_per_m2", j},
      {"crack_area_m2", area.area_m2},
      {"crack_area_source", area.source},
      {"work_difference_J", d.difference_work_J},
      {"first_work_J", d.first_work_J},
      {"second_work_J", d.second_work_J},
      {"end_depth_m", d.end_depth_m},
      {"alignment", a.align},
      {"second_pass", a.second.empty() ? a.second_from : "file"},
      {"first", cut_json(d.first)},
      {"second", cut_json(d.second)},
      {"integrand_csv", a.integrand.empty() ? nlohmann::json() : nlohmann::json(a.integrand)},
      {"warnings", warnings}};
  if (area.from_mesh) {
    out["crack_area_height_m"] = area.from_mesh->height_m;
    out["needle_length_m"] = area.from_mesh->needle_length_m;
    out["needle_tip_length_m"] = area.from_mesh->tip_length_m;
  }
  if (drop) {
    out["puncture"] = {{"peak_depth_m", drop->peak_depth_m},
                       {"peak_force_N", drop->peak_force_N},
                       {"post_depth_m", drop->bottom_depth_m},
                       {"post_force_N", drop->bottom_force_N}};
  }
  require_finite_json(out, a.first);
  if (a.json) {
    std::cout << with_provenance(out).dump(2) << "\n";
    return;
  }
  std::cout << "fracture toughness J = " << format_toughness(j) << "  (" << sig(j * 1e-3)
            << " N/mm)\n"
            << "  integral of (F - F') dz = " << format_energy(d.difference_work_J) << " over 0 to "
            << format_quantity(d.end_depth_m, Dimension::Length) << " (first pass "
            << format_energy(d.first_work_J) << ", second " << format_energy(d.second_work_J)
            << ")\n"
            << "  crack area A = " << sig(area.area_m2 * 1e6) << " mm^2";
  if (area.from_mesh) {
    std::cout << " (section of " << area.source << " at "
              << format_quantity(area.from_mesh->height_m, Dimension::Length)
              << " above its tip; tip length "
              << format_quantity(area.from_mesh->tip_length_m, Dimension::Length) << ")";
  }
  std::cout << "\n";
  if (drop) {
    std::cout << "  second pass from the post-puncture tail: puncture at "
              << format_quantity(drop->peak_depth_m, Dimension::Length) << " ("
              << format_quantity(drop->peak_force_N, Dimension::Force) << " -> "
              << format_quantity(drop->bottom_force_N, Dimension::Force) << ")\n";
  }
  std::cout << "  first:  " << cut_line(d.first) << "\n"
            << "  second: " << cut_line(d.second) << "\n";
  if (!a.integrand.empty()) std::cout << "  integrand written to " << a.integrand << "\n";
  for (const auto& w : warnings) std::cout << "  warning: " << w.get<std::string>() << "\n";
}

}  // namespace

void add_toughness_command(CLI::App& app) {
  auto a = std::make_shared<ToughnessArgs>();
  auto* cmd = app.add_subcommand(
      "toughness", "Fracture toughness J = integral of (F - F') dz / A from two insertions");
  cmd->footer(
      "Columns are read by name with their unit: depth_m, depth_mm, travel_mm, position_um,\n"
      "'z [mm]', force_N, fz_N, force_mN, 'F (mN)'; --depth-col/--force-col pick others, and\n"
      "--depth-unit/--force-unit give the unit when the name has none.\n"
      "Examples:\n"
      "  mneedle toughness first.csv second.csv --area 0.0415mm^2\n"
      "  mneedle toughness first.csv second.csv --plugin sharp_bevel --set diameter=230um --json\n"
      "  mneedle toughness rec.csv --second-from retraction --needle needle.stl --unit mm");
  cmd->add_option("first", a->first, "First insertion (CSV)")->required();
  cmd->add_option("second", a->second, "Second insertion into the same hole (CSV)");
  cmd->add_option("--second-from", a->second_from,
                  "Without SECOND.csv: build the second pass from the first recording's "
                  "'retraction' or its post-puncture 'tail' (see docs/model.md)");
  cmd->add_option("--area", a->area, "Crack area with unit, e.g. 0.0415mm^2");
  cmd->add_option("--needle", a->needle, "Needle mesh: the crack area is its cross-section");
  cmd->add_option("--unit", a->unit, "Length unit of the --needle mesh: um, mm, m")
      ->capture_default_str();
  cmd->add_option("--plugin", a->plugin, "Tip-shape plugin: the crack area is its cross-section");
  cmd->add_option("--set", a->settings, "Plugin parameter, key=value with unit (repeatable)");
  cmd->add_option("--plugin-dir", a->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->add_option("--depth-col", a->depth_col, "Depth column (default: depth*, travel*, ...)");
  cmd->add_option("--force-col", a->force_col, "Force column (default: force*, fz*, ...)");
  cmd->add_option("--depth-unit", a->depth_unit, "Unit of the depth column (default: its name)");
  cmd->add_option("--force-unit", a->force_unit, "Unit of the force column (default: its name)");
  cmd->add_option("--align", a->align,
                  "Depth origin: 'contact' (each pass from its own contact) or 'travel' (both "
                  "from the first pass's contact travel)")
      ->capture_default_str();
  cmd->add_option("--max-depth", a->max_depth, "End of the integral, e.g. 2mm (default: common)");
  cmd->add_option("--integrand", a->integrand,
                  "Write depth_m,first_force_N,second_force_N,difference_N to this CSV");
  cmd->add_option("--plot", a->plot, "Write F, F' and F - F' against depth as SVG");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_toughness(*a); });
}

}  // namespace mneedle::cli
