// mneedle calibrate: fit a scene's tissue constants to one measured insertion curve
// (docs/cli.md "calibrate", docs/model.md "Calibration").

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/text.h"
#include "mneedle/base/units.h"
#include "mneedle/calibration/calibration.h"
#include "mneedle/design_source.h"
#include "mneedle/measurement/toughness.h"
#include "mneedle/plot/figure.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "mneedle/scene/scene_edit.h"
#include "progress_line.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct CalibrateArgs {
  std::filesystem::path scene;
  std::filesystem::path curve;
  std::string fit;
  std::filesystem::path out;
  std::filesystem::path plot;
  std::string contact_at;
  std::string puncture_at;
  std::string fit_range;
  std::string depth_col, force_col, depth_unit, force_unit;
  std::string fidelity;
  std::vector<std::string> plugin_dirs;
  bool json = false;
  bool quiet = false;  // no progress line
};

std::vector<CalibratedConstant> parse_fit_list(const std::string& text) {
  std::vector<CalibratedConstant> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) out.push_back(calibrated_constant(std::string(trim(item))));
  return out;
}

double length_option(const std::string& option, const std::string& text) {
  try {
    return parse_quantity(text, Dimension::Length);
  } catch (const InputError& e) {
    throw InputError(option + " " + text + ": " + e.what());
  }
}

const char* unit_of(CalibratedConstant c) {
  switch (c) {
    case CalibratedConstant::scale:
    case CalibratedConstant::friction_coefficient:
    case CalibratedConstant::modulus:
      return "";
    case CalibratedConstant::critical_pressure:
      return "Pa";
    case CalibratedConstant::toughness:
      return "J/m^2";
  }
  return "";
}

nlohmann::json metrics_json(const CurveMetrics& m) {
  return {
      {"rmse_N", m.rmse_N}, {"r2", m.r2}, {"max_error_N", m.max_error_N}, {"samples", m.samples}};
}

nlohmann::json to_json(const Calibration& c, const Scene& scene, const CalibrateArgs& a) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const CalibratedParameter& p : c.parameters) {
    parameters.push_back(
        {{"name", to_string(p.constant)},
         {"unit", unit_of(p.constant)},
         {"initial", p.initial},
         {"value", p.value},
         {"standard_error", std::isfinite(p.standard_error) ? nlohmann::json(p.standard_error)
                                                            : nlohmann::json(nullptr)},
         {"at_bound", p.at_bound}});
  }
  nlohmann::json layers = nlohmann::json::array();
  for (std::size_t i = 0; i < c.layer_pressure_scale_Pa.size(); ++i) {
    layers.push_back({{"name", scene.tissue.layers[i].name},
                      {"pressure_scale_Pa", c.layer_pressure_scale_Pa[i]},
                      {"youngs_modulus_Pa", c.layer_youngs_modulus_Pa[i]}});
  }
  nlohmann::json curve = nlohmann::json::array();
  for (std::size_t i = 0; i < c.depth_m.size(); ++i) {
    curve.push_back({{"depth_m", c.depth_m[i]},
                     {"measured_N", c.measured_N[i]},
                     {"model_N", c.model_N[i]},
                     {"fitted", static_cast<bool>(c.fitted[i])}});
  }
  nlohmann::json j = {
      {"scene", a.scene.string()},
      {"curve", a.curve.string()},
      {"parameters", parameters},
      {"correlation", c.correlation},
      {"fit", metrics_json(c.fit)},
      {"held_out", c.held_out ? metrics_json(*c.held_out) : nlohmann::json(nullptr)},
      {"straight_line_held_out", c.straight_line_held_out ? metrics_json(*c.straight_line_held_out)
                                                          : nlohmann::json(nullptr)},
      {"contact_travel_m", c.contact_travel_m},
      {"puncture_depth_m",
       c.puncture_depth_m ? nlohmann::json(*c.puncture_depth_m) : nlohmann::json(nullptr)},
      {"layers", layers},
      {"friction_coefficient", c.friction_coefficient},
      {"converged", c.converged},
      {"iterations", c.iterations},
      {"samples", curve}};
  return j;
}

void print_table(const Calibration& c, const Scene& scene) {
  std::cout << std::setprecision(4);
  std::cout << "contact at travel " << format_quantity(c.contact_travel_m, Dimension::Length);
  if (c.puncture_depth_m)
    std::cout << "; model punctures at " << format_quantity(*c.puncture_depth_m, Dimension::Length)
              << " below the surface";
  std::cout << (c.converged ? "" : "; the fit did NOT converge") << "\n";
  std::cout << "  constant               initial        fitted    std. error\n";
  for (const CalibratedParameter& p : c.parameters) {
    std::cout << "  " << std::left << std::setw(20) << to_string(p.constant) << std::right
              << std::setw(10) << p.initial << std::setw(14) << p.value << std::setw(14);
    if (std::isfinite(p.standard_error))
      std::cout << p.standard_error;
    else
      std::cout << "not fixed";
    std::cout << " " << unit_of(p.constant) << (p.at_bound ? "  (at the search bound)" : "")
              << "\n";
  }
  if (c.parameters.size() > 1) {
    std::cout << "  correlations:";
    for (std::size_t i = 0; i < c.parameters.size(); ++i)
      for (std::size_t j = i + 1; j < c.parameters.size(); ++j)
        std::cout << " " << to_string(c.parameters[i].constant) << "/"
                  << to_string(c.parameters[j].constant) << " " << c.correlation[i][j];
    std::cout << "\n";
  }
  for (std::size_t i = 0; i < c.layer_pressure_scale_Pa.size(); ++i) {
    std::cout << "  q " << scene.tissue.layers[i].name << " "
              << format_quantity(c.layer_pressure_scale_Pa[i], Dimension::Pressure);
    const bool modulus_fitted = std::any_of(
        c.parameters.begin(), c.parameters.end(),
        [](const CalibratedParameter& p) { return p.constant == CalibratedConstant::modulus; });
    if (modulus_fitted) {
      std::cout << ", E " << format_quantity(c.layer_youngs_modulus_Pa[i], Dimension::Pressure);
    }
    std::cout << "\n";
  }
  std::cout << "fit: " << c.fit.samples << " samples, RMSE " << c.fit.rmse_N * 1e3 << " mN, R^2 "
            << c.fit.r2 << "\n";
  if (c.held_out) {
    std::cout << "held out: " << c.held_out->samples << " samples, RMSE "
              << c.held_out->rmse_N * 1e3 << " mN (a straight line fitted to the same samples: "
              << c.straight_line_held_out->rmse_N * 1e3 << " mN)\n";
  }
}

// Measured samples (dots; the held-out ones a series of their own) against the fitted model.
plot::Figure calibrate_figure(const Calibration& c, const std::string& title) {
  plot::Figure f;
  f.title = title;
  f.x.name = "depth below the surface";
  plot::Series fitted{"measured (fitted)", {}, {}, plot::Mark::Dots};
  plot::Series held{"measured (held out)", {}, {}, plot::Mark::Dots};
  plot::Series model{"model", c.depth_m, c.model_N, plot::Mark::Line};
  for (std::size_t i = 0; i < c.depth_m.size(); ++i) {
    plot::Series& s = c.fitted[i] ? fitted : held;
    s.x.push_back(c.depth_m[i]);
    s.y.push_back(c.measured_N[i]);
  }
  for (plot::Series* s : {&fitted, &held, &model})
    if (!s->x.empty()) f.series.push_back(std::move(*s));
  return f;
}

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw InputError(path.string() + ": cannot write");
}

void run(const CalibrateArgs& a) {
  const Scene scene = load_scene(a.scene);
  record_scene(scene, a.scene);
  if (scene.needles.size() != 1) {
    throw InputError(a.scene.string() +
                     ": calibrate needs a scene with one needle (the one "
                     "the curve was measured with); it has " +
                     std::to_string(scene.needles.size()));
  }
  CalibrationOptions options;
  options.fit = parse_fit_list(a.fit);
  if (!a.contact_at.empty()) options.contact_travel_m = length_option("--contact-at", a.contact_at);
  const CurveColumns columns{a.depth_col, a.force_col, "", a.depth_unit, a.force_unit};
  const ForceCurve measured = read_force_curve_csv(a.curve, columns);
  record_input("curve", a.curve);
  if (a.puncture_at == "detect") {
    // On the loading branch only: a hold or a retraction has larger drops than any puncture.
    const LoadingBranch branch = extract_loading_branch(measured);
    const ForceDrop drop = largest_force_drop(branch.curve);
    options.puncture_travel_m = drop.bottom_depth_m + branch.contact_travel_m;
    options.drop_start_travel_m = drop.peak_depth_m + branch.contact_travel_m;
  } else if (!a.puncture_at.empty()) {
    options.puncture_travel_m = length_option("--puncture-at", a.puncture_at);
  }
  if (!a.fit_range.empty()) {
    const auto colon = a.fit_range.find(':');
    if (colon == std::string::npos)
      throw InputError("--fit-range " + a.fit_range + ": expected FROM:TO, e.g. 19mm:36mm");
    const std::string from(trim(a.fit_range.substr(0, colon)));
    const std::string to(trim(a.fit_range.substr(colon + 1)));
    if (!from.empty()) options.fit_from_travel_m = length_option("--fit-range", from);
    if (!to.empty()) options.fit_to_travel_m = length_option("--fit-range", to);
  }
  options.run = scene_run_options(scene);
  if (a.fidelity == "fast") options.run.fidelity = fe::Fidelity::Fast;
  if (a.fidelity == "fine") options.run.fidelity = fe::Fidelity::Fine;
  if (a.fidelity == "standard") options.run.fidelity = fe::Fidelity::Standard;
  const PluginRegistry registry =
      PluginRegistry::discover({a.plugin_dirs.begin(), a.plugin_dirs.end()});
  const std::vector<PreparedNeedle> needles = prepare_needles(registry, scene);
  record_plugin_meshes(scene, needles);
  ProgressLine progress(std::cerr, "calibrate", stderr_is_terminal(), a.quiet);
  options.run.on_progress = [&](const std::string& model, int step, int steps, double depth,
                                double force) {
    progress.update({model, step, steps, depth, force});
  };
  const Calibration c = calibrate(scene, needles.front(), measured, options);
  progress.finish();

  const nlohmann::json tree = to_json(c, scene, a);
  require_finite_json(tree, "calibrate");
  if (!a.out.empty()) {
    SceneConstantEdits edits;
    const std::string source = "fitted by mneedle calibrate to " + a.curve.filename().string();
    for (const CalibratedParameter& p : c.parameters) {
      if (p.constant == CalibratedConstant::scale) {
        for (double q : c.layer_pressure_scale_Pa) edits.layer_pressure_scale_Pa.push_back(q);
        edits.pressure_scale_source = source;
      }
      if (p.constant == CalibratedConstant::friction_coefficient)
        edits.friction_coefficient = c.friction_coefficient;
      // A q derived from the modulus is derived again from the written one.
      if (p.constant == CalibratedConstant::modulus) edits.modulus_factor = c.modulus_factor;
    }
    edits.critical_pressure_Pa = c.critical_pressure_Pa;
    edits.toughness_J_per_m2 = c.toughness_J_per_m2;
    std::ostringstream fitted;
    fitted << "fit RMSE " << std::setprecision(4) << c.fit.rmse_N * 1e3 << " mN, R^2 " << c.fit.r2
           << " on " << c.fit.samples << " samples";
    edits.header_comment = {"Written by mneedle calibrate from " + a.scene.string() + ",",
                            source + " (" + fitted.str() + ").",
                            "Comments of the original scene are not carried over."};
    write_file(a.out, edited_scene_text(a.scene, edits, a.out));
    load_scene(a.out);  // what is written must load
  }
  if (!a.plot.empty())
    plot::write_svg(a.plot, calibrate_figure(c, "calibrate: " + a.curve.filename().string()));
  if (a.json)
    std::cout << with_provenance(tree).dump(2) << "\n";
  else
    print_table(c, scene);
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Fit a scene's tissue constants (pressure scale, friction coefficient, P_c or toughness, "
      "modulus) to one measured insertion curve of its needle");
  cmd->footer(
      "Example:\n  mneedle calibrate my_scene.toml --curve measured.csv --fit "
      "scale,friction_coefficient "
      "--puncture-at detect --out fitted.toml --plot fit.svg");
  cmd->add_option("SCENE", a->scene, "Scene file with the one needle that was measured")
      ->required();
  cmd->add_option("--curve", a->curve, "Measured force-depth curve (CSV)")->required();
  cmd->add_option("--fit", a->fit,
                  "Constants to fit, comma-separated: scale, friction_coefficient, modulus (a "
                  "factor on every layer's stiffness, fitted before the puncture), and "
                  "critical_pressure or toughness")
      ->required();
  cmd->add_option("--out", a->out, "Write the scene with the fitted constants here (TOML)");
  cmd->add_option("--plot", a->plot, "Write measured against fitted as SVG");
  cmd->add_option("--contact-at", a->contact_at,
                  "Travel at contact, with unit (default: detected from the force)");
  cmd->add_option("--puncture-at", a->puncture_at,
                  "Travel at the measured puncture, with unit, or 'detect' (largest force drop): "
                  "fit the post-puncture stage only, no finite elements (unless modulus is "
                  "fitted, on the samples before it)");
  cmd->add_option("--fit-range", a->fit_range,
                  "Travel interval to fit, FROM:TO with units (either may be empty); the rest is "
                  "held out and its error reported");
  cmd->add_option("--fidelity", a->fidelity, "Pre-puncture model fidelity (default: the scene's)")
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_option("--depth-col", a->depth_col, "Depth column (default: depth*, travel*, ...)");
  cmd->add_option("--force-col", a->force_col, "Force column (default: force*, fz*, ...)");
  cmd->add_option("--depth-unit", a->depth_unit, "Unit of the depth column (default: its name)");
  cmd->add_option("--force-unit", a->force_unit, "Unit of the force column (default: its name)");
  cmd->add_option("--plugin-dir", a->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->add_flag("--json", a->json, "Print JSON");
  cmd->add_flag("--quiet", a->quiet,
                "no progress line on stderr (shown for runs longer than a second)");
  cmd->callback([a] { run(*a); });
}

}  // namespace mneedle::cli
