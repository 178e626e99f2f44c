// mneedle fit / predict / stats: paper B's tri-force model fitted to a user's recordings,
// predictions at other speeds and angles, and ANOVA/Tukey between groups (docs/model.md, "Tri-force
// model").
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/fit_report.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/units.h"
#include "mneedle/measurement/anova.h"
#include "mneedle/measurement/curve_metrics.h"
#include "mneedle/measurement/force_curve.h"
#include "mneedle/measurement/layer_boundaries.h"
#include "mneedle/measurement/triforce_fit.h"
#include "mneedle/measurement/triforce_model.h"
#include "mneedle/plot/figure.h"
#include "option_values.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

void add_curve_options(CLI::App* cmd, CurveSettings& a) {
  cmd->add_option("--depth-col", a.depth_col,
                  "Depth/travel column (default: depth*, travel*, ...)");
  cmd->add_option("--force-col", a.force_col, "Force column (default: force*, fz*, ...)");
  cmd->add_option("--depth-unit", a.depth_unit, "Unit of the depth column (default: its suffix)");
  cmd->add_option("--force-unit", a.force_unit, "Unit of the force column (default: its suffix)");
  cmd->add_option("--speed", a.speed,
                  "Insertion speed, e.g. 1mm/s (default: from the time column)");
  cmd->add_option("--angle", a.angle,
                  "Needle-to-surface angle, paper B's convention (90deg = perpendicular)")
      ->capture_default_str();
}

// ---------------------------------------------------------------- fit
struct FitArgs {
  std::vector<std::string> files;
  std::string model = "triforce";
  FitSettings settings;
  bool json = false;
  std::string out_dir;
  std::string plot;  // SVG: each curve measured (dots) and fitted (line)
};

void print_fit(const TriforceFit& fit, const std::vector<LoadedCurve>& curves) {
  for (const auto& c : curves) std::cout << c.branch.summary << "\n";
  std::cout << "\ntri-force fit (" << fit.samples << " samples, " << fit.starts << " starts, "
            << (fit.converged ? "converged" : "NOT converged") << ", residual sd "
            << fit.residual_sd_N << " N)\n";
  for (const auto& p : fit.parameters) {
    std::cout << "  " << std::left << std::setw(14) << p.name << std::right << std::setw(14)
              << p.value;
    if (!p.fitted) {
      std::cout << "  (fixed)\n";
    } else if (std::isfinite(p.standard_error)) {
      std::cout << "  +/- " << p.standard_error << "\n";
    } else {
      std::cout << "  +/- not identifiable\n";
    }
  }
  for (const auto& c : fit.curves) {
    std::cout << "  " << c.name << ": RMSE " << c.metrics.rmse_N << " N, R2 " << c.metrics.r2
              << ", max error " << c.metrics.max_error_N << " N, contact offset "
              << c.offset_m * 1e3 << " mm\n";
  }
}

// Each curve writes <stem>_fit.csv: two curves of one stem (from two folders) would share it.
void require_distinct_stems(const std::vector<std::string>& files) {
  std::map<std::string, std::string> stems;
  for (const std::string& file : files) {
    const std::string stem = std::filesystem::path(file).stem().string();
    const auto [it, fresh] = stems.emplace(stem, file);
    if (!fresh)
      throw InputError("--out: the curves '" + it->second + "' and '" + file +
                       "' would both write " + stem + "_fit.csv; rename one");
  }
}

void write_fit_files(const std::string& dir, const nlohmann::json& report, const TriforceFit& fit,
                     const std::vector<LoadedCurve>& curves) {
  create_output_folder(dir, "--out");
  write_output_file(std::filesystem::path(dir) / "fit.json", with_provenance(report).dump(2) + "\n",
                    "--out");
  const TriforceModel model(fit.params);
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const auto& c = curves[i].curve;
    const auto predicted = predict_loading(model, c, fit.curves[i].offset_m);
    for (std::size_t j = 0; j < c.depth_m.size(); ++j) {
      require_finite_row({c.depth_m[j], c.force_N[j], predicted[j]},
                         {"depth_m", "measured_N", "model_N"},
                         c.name + " row " + std::to_string(j + 1), "fit");
    }
    std::ostringstream csv;
    csv << "depth_m,measured_N,model_N\n" << std::setprecision(8);
    for (std::size_t j = 0; j < c.depth_m.size(); ++j) {
      csv << c.depth_m[j] << "," << c.force_N[j] << "," << predicted[j] << "\n";
    }
    write_output_file(
        std::filesystem::path(dir) / (std::filesystem::path(c.name).stem().string() + "_fit.csv"),
        csv.str(), "--out");
  }
}

void run_fit(const FitArgs& args) {
  if (args.model != "triforce")
    throw InputError("fit: unknown --model '" + args.model + "' (known: triforce)");
  for (const auto& f : args.files) record_input("curve", f);
  if (!args.out_dir.empty()) {
    require_distinct_stems(args.files);
    create_output_folder(args.out_dir, "--out");
  }
  const FitOutcome outcome = fit_recordings(args.files, args.settings);
  const TriforceFit& fit = outcome.fit;
  const std::vector<LoadedCurve>& curves = outcome.curves;
  const nlohmann::json& report = outcome.report;
  if (args.settings.detect_layers > 1 && !args.json) {
    std::cout << "layers start at (mm):";
    for (double start : outcome.initial_layer_starts_m) std::cout << " " << start * 1e3;
    std::cout << "\n";
  }
  if (!args.out_dir.empty()) write_fit_files(args.out_dir, report, fit, curves);
  if (!args.plot.empty()) {
    plot::Figure f;
    f.title = "fit: tri-force model (paper B)";
    f.x.name = "depth from contact";
    const TriforceModel model(fit.params);
    for (std::size_t i = 0; i < curves.size(); ++i) {
      const auto& c = curves[i].curve;
      f.series.push_back({c.name + " measured", c.depth_m, c.force_N, plot::Mark::Dots});
      f.series.push_back({c.name + " fitted", c.depth_m,
                          predict_loading(model, c, fit.curves[i].offset_m), plot::Mark::Line});
    }
    plot::write_svg(args.plot, f);
  }
  if (args.json) {
    std::cout << with_provenance(report).dump(2) << "\n";
  } else {
    print_fit(fit, curves);
  }
}

// ---------------------------------------------------------------- predict
struct PredictArgs {
  std::string model = "triforce";
  std::string params_file;
  std::string speed = "1mm/s";
  std::string angle = "90deg";
  std::string depth;
  std::string hold = "0s";
  std::string retract_speed;
  std::string step = "0.05s";
  std::string amplitude = "0m";
  double frequency_Hz = 1000.0;
  std::size_t max_samples = 1'000'000;
  std::string compare;
  CurveSettings curve;
  bool csv = false;
  bool json = false;
  std::string plot;  // SVG: the predicted force against depth (and --compare's curve)
};

TriforceParams read_params(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot open the file");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file + ": not JSON: " + e.what());
  }
  if (!j.contains("params") || !j["params"].is_object()) {
    throw InputError(file + ": no \"params\" object (write it with mneedle fit --json)");
  }
  TriforceParams p;
  std::set<std::string> given;
  for (const auto& [name, value] : j["params"].items()) {
    if (!value.is_number()) throw InputError(file + ": params." + name + ": not a number");
    set_parameter(p, name, value.get<double>());
    given.insert(name);
  }
  // Every parameter of the layers the file names: a missing one would be the model's built-in
  // default (a beta left out tripled the predicted peak).
  std::string missing;
  for (const auto& [name, value] : named_parameters(p))
    if (!given.count(name)) missing += (missing.empty() ? "" : ", ") + name;
  if (!missing.empty())
    throw InputError(file + ": params: missing " + missing + " (write it with mneedle fit --json)");
  TriforceModel{p};  // validates
  return p;
}

// Mean contact offset of the fitted curves: detected contact + offset is where the model starts.
double mean_fitted_offset(const std::string& file) {
  std::ifstream in(file);
  const auto j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.contains("curves") || !j["curves"].is_array()) return 0.0;
  double sum = 0.0;
  int n = 0;
  for (const auto& c : j["curves"]) {
    if (c.contains("offset_m") && c["offset_m"].is_number()) {
      sum += c["offset_m"].get<double>();
      ++n;
    }
  }
  return n > 0 ? sum / n : 0.0;
}

const char* phase_name(InsertionPhase p) {
  switch (p) {
    case InsertionPhase::Insertion:
      return "insertion";
    case InsertionPhase::Hold:
      return "hold";
    case InsertionPhase::Retraction:
      return "retraction";
  }
  return "?";
}

void run_predict(const PredictArgs& args) {
  if (args.model != "triforce")
    throw InputError("predict: unknown --model '" + args.model + "' (known: triforce)");
  if (args.params_file.empty()) throw InputError("predict: --params FIT.json is required");
  if (!(args.frequency_Hz > 0.0)) throw InputError("predict: --perturb-frequency must be > 0 Hz");
  const TriforceModel model(read_params(args.params_file));
  InsertionProtocol protocol;
  protocol.conditions.speed_m_per_s = option_quantity("--speed", args.speed, Dimension::Speed);
  protocol.conditions.angle_rad =
      checked_insertion_angle(option_quantity("--angle", args.angle, Dimension::Angle), "--angle");
  protocol.conditions.perturbation_amplitude_m =
      option_quantity("--perturb-amplitude", args.amplitude, Dimension::Length);
  protocol.conditions.perturbation_frequency_Hz = args.frequency_Hz;
  protocol.hold_s = option_quantity("--hold", args.hold, Dimension::Time);
  protocol.time_step_s = option_quantity("--step", args.step, Dimension::Time);
  protocol.max_samples = args.max_samples;
  if (!args.retract_speed.empty()) {
    protocol.retraction_speed_m_per_s =
        option_quantity("--retract-speed", args.retract_speed, Dimension::Speed);
  }
  std::optional<LoadedCurve> measured;
  if (!args.compare.empty()) {
    CurveSettings c = args.curve;
    c.speed = args.speed;
    c.angle = args.angle;
    record_input("curve", args.compare);
    measured = load_fit_curve(args.compare, c);
  }
  if (!args.depth.empty()) {
    protocol.max_depth_m = option_quantity("--depth", args.depth, Dimension::Length);
  } else if (measured) {
    protocol.max_depth_m = measured->curve.depth_m.back();
  } else {
    throw InputError("predict: give --depth (or --compare CURVE.csv to use its depth)");
  }
  const auto samples = model.simulate(protocol);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto& s = samples[i];
    require_finite_row(
        {s.time_s, s.depth_m, s.force.total_N(), s.force.cutting_N, s.force.stiffness_N,
         s.force.friction_N, s.force.viscous_N},
        {"time_s", "depth_m", "force_N", "cutting_N", "stiffness_N", "friction_N", "viscous_N"},
        "sample " + std::to_string(i + 1), "predict");
  }
  nlohmann::json comparison;
  if (measured) {
    const double offset = mean_fitted_offset(args.params_file);
    // The measured samples as deep as the prediction goes (--depth cut nothing of them).
    FitCurve within = measured->curve;
    within.depth_m.clear();
    within.force_N.clear();
    for (std::size_t i = 0; i < measured->curve.depth_m.size(); ++i)
      if (measured->curve.depth_m[i] <= protocol.max_depth_m * (1.0 + 1e-12)) {
        within.depth_m.push_back(measured->curve.depth_m[i]);
        within.force_N.push_back(measured->curve.force_N[i]);
      }
    if (within.depth_m.empty())
      throw InputError("predict: --depth " + args.depth + " lies before every sample of " +
                       measured->curve.name);
    const auto predicted = predict_loading(model, within, offset);
    const auto m = compare_curves(within.force_N, predicted);
    comparison = {{"file", measured->curve.name},
                  {"rmse_N", m.rmse_N},
                  {"r2", m.r2},
                  {"max_error_N", m.max_error_N},
                  {"samples", m.samples},
                  {"loading_branch", measured->branch.summary}};
    require_finite_json(comparison, "predict: comparison");
    if (!args.json) {
      std::cerr << measured->branch.summary << "\nprediction vs " << measured->curve.name
                << ": RMSE " << m.rmse_N << " N, R2 " << m.r2 << ", max error " << m.max_error_N
                << " N\n";
    }
  }
  if (!args.plot.empty()) {
    plot::Figure fig;
    fig.title = "predict: tri-force model (paper B)";
    fig.x.name = "depth from contact";
    plot::Series predicted{"predicted", {}, {}, plot::Mark::Line};
    for (const auto& s : samples) {
      predicted.x.push_back(s.depth_m);
      predicted.y.push_back(s.force.total_N());
    }
    fig.series.push_back(std::move(predicted));
    if (measured)
      fig.series.push_back({measured->curve.name + " measured", measured->curve.depth_m,
                            measured->curve.force_N, plot::Mark::Dots});
    plot::write_svg(args.plot, fig);
  }
  if (args.json) {
    nlohmann::json t = nlohmann::json::array(), z = t, ph = t, f = t, fc = t, fs = t, ff = t,
                   fv = t;
    for (const auto& s : samples) {
      t.push_back(s.time_s);
      z.push_back(s.depth_m);
      ph.push_back(phase_name(s.phase));
      f.push_back(s.force.total_N());
      fc.push_back(s.force.cutting_N);
      fs.push_back(s.force.stiffness_N);
      ff.push_back(s.force.friction_N);
      fv.push_back(s.force.viscous_N);
    }
    nlohmann::json out = {
        {"model", "triforce"},
        {"conditions",
         {{"speed_m_per_s", protocol.conditions.speed_m_per_s},
          {"angle_rad", protocol.conditions.angle_rad},
          {"depth_m", protocol.max_depth_m},
          {"hold_s", protocol.hold_s},
          {"perturbation_amplitude_m", protocol.conditions.perturbation_amplitude_m},
          {"perturbation_frequency_Hz", protocol.conditions.perturbation_frequency_Hz}}},
        {"time_s", t},
        {"depth_m", z},
        {"phase", ph},
        {"force_N", f},
        {"cutting_N", fc},
        {"stiffness_N", fs},
        {"friction_N", ff},
        {"viscous_N", fv}};
    if (measured) out["comparison"] = comparison;
    print_checked_json(std::cout, out, "predict");
    return;
  }
  std::cout << "time_s,depth_m,phase,force_N,cutting_N,stiffness_N,friction_N,viscous_N\n"
            << std::setprecision(8);
  for (const auto& s : samples) {
    std::cout << s.time_s << "," << s.depth_m << "," << phase_name(s.phase) << ","
              << s.force.total_N() << "," << s.force.cutting_N << "," << s.force.stiffness_N << ","
              << s.force.friction_N << "," << s.force.viscous_N << "\n";
  }
}

// ---------------------------------------------------------------- stats
struct StatsArgs {
  std::string file;
  std::string value = "value";
  std::string group = "group";
  double alpha = 0.05;
  // Tukey compares every pair: k groups make k (k - 1) / 2 rows of output (1000 groups: half a
  // million rows, a few seconds and about 1 GB for the report; docs/performance.md).
  std::size_t max_groups = 1000;
  bool json = false;
};

void run_stats(const StatsArgs& args) {
  // Checked before the file is read (1e-300 ended in the range quantile's own error).
  if (!(args.alpha >= 1e-6 && args.alpha <= 0.5))
    throw InputError("--alpha " +
                     (std::isfinite(args.alpha) ? (std::ostringstream() << args.alpha).str()
                                                : std::string("not a number")) +
                     ": must be in [1e-6, 0.5]");
  std::vector<std::string> labels;
  std::vector<double> values;
  read_grouped_csv(args.file, args.value, args.group, labels, values);
  const std::size_t groups = std::set<std::string>(labels.begin(), labels.end()).size();
  if (groups > args.max_groups) {
    throw InputError(args.file + ": " + std::to_string(groups) + " groups in column '" +
                     args.group + "', more than --max-groups " + std::to_string(args.max_groups) +
                     " (" + std::to_string(groups * (groups - 1) / 2) +
                     " Tukey pairs); raise --max-groups to compare them all");
  }
  // The analysis's own errors (too few groups, no spread, values too large) name the file.
  const auto r = [&] {
    try {
      return one_way_anova(labels, values, args.alpha);
    } catch (const InputError& e) {
      throw InputError(args.file + ": " + e.what());
    }
  }();
  {
    nlohmann::json groups = nlohmann::json::array(), pairs = nlohmann::json::array();
    for (const auto& g : r.groups)
      groups.push_back({{"name", g.name}, {"n", g.n}, {"mean", g.mean}, {"sd", g.sd}});
    for (const auto& c : r.tukey) {
      pairs.push_back({{"group1", c.group1},
                       {"group2", c.group2},
                       {"meandiff", c.mean_difference},
                       {"p_adj", c.p_adjusted},
                       {"lower", c.ci_low},
                       {"upper", c.ci_high},
                       {"reject", c.reject}});
    }
    const auto& a = r.anova;
    const nlohmann::json tree{{"value", args.value},
                              {"groups", groups},
                              {"anova",
                               {{"ss_between", a.ss_between},
                                {"ss_within", a.ss_within},
                                {"df_between", a.df_between},
                                {"df_within", a.df_within},
                                {"ms_between", a.ms_between},
                                {"ms_within", a.ms_within},
                                {"F", a.f},
                                {"p", a.p}}},
                              {"alpha", r.alpha},
                              {"q_critical", r.q_critical},
                              {"tukey_hsd", pairs}};
    // The text report prints the same numbers: one check covers both formats.
    require_finite_json(tree, "stats");
    if (args.json) {
      std::cout << with_provenance(tree).dump(2) << "\n";
      return;
    }
  }
  std::cout << "one-way ANOVA of '" << args.value << "' by '" << args.group << "'\n";
  for (const auto& g : r.groups) {
    std::cout << "  " << std::left << std::setw(16) << g.name << std::right << " n " << std::setw(3)
              << g.n << "  mean " << std::setw(10) << g.mean << "  sd " << g.sd << "\n";
  }
  std::cout << "  F(" << r.anova.df_between << ", " << r.anova.df_within << ") = " << r.anova.f
            << ", p = " << r.anova.p << "\n\nTukey HSD (alpha " << r.alpha << ", q_crit "
            << r.q_critical << "); meandiff = mean(group1) - mean(group2)\n"
            << "  group1 group2 meandiff p-adj lower upper reject\n";
  for (const auto& c : r.tukey) {
    std::cout << "  " << c.group1 << " " << c.group2 << " " << c.mean_difference << " "
              << c.p_adjusted << " " << c.ci_low << " " << c.ci_high << " "
              << (c.reject ? "True" : "False") << "\n";
  }
}

}  // namespace

void add_fit_command(CLI::App& app) {
  auto args = std::make_shared<FitArgs>();
  auto* cmd = app.add_subcommand("fit", "Fit paper B's tri-force model to force-depth recordings");
  cmd->footer("Example:\n  mneedle fit curve1.csv curve2.csv --model triforce --out fit1");
  // A missing file is the reader's one-line error with status 1, as every command's (CLI11's
  // ExistingFile check said it with status 2).
  cmd->add_option("curves", args->files, "Force-depth CSV files (fitted jointly)")->required();
  cmd->add_option("--model", args->model, "Force model")->capture_default_str();
  add_curve_options(cmd, args->settings.curve);
  cmd->add_option("--fix", args->settings.fix,
                  "Hold a parameter, NAME=VALUE (e.g. beta=0, eta_Ns=0.5)");
  cmd->add_option("--free", args->settings.free,
                  "Fit exactly these parameters (default: the material ones)");
  cmd->add_option("--layer-start", args->settings.layer_starts,
                  "Add a layer starting at this travel (e.g. 8mm)");
  cmd->add_option("--detect-layers", args->settings.detect_layers,
                  "Up to N layers, boundaries from slope changes of the first curve");
  cmd->add_option("--starts", args->settings.starts, "Number of Levenberg-Marquardt starts")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "Print the fit as JSON");
  cmd->add_option("--plot", args->plot, "Write each curve measured and fitted as SVG");
  cmd->add_option("--out", args->out_dir, "Write fit.json and <curve>_fit.csv into this directory");
  cmd->callback([args] { run_fit(*args); });
}

void add_predict_command(CLI::App& app) {
  auto args = std::make_shared<PredictArgs>();
  auto* cmd = app.add_subcommand(
      "predict", "Predict force against depth and time: insertion, hold, retraction");
  cmd->footer(
      "Example:\n  mneedle predict --model triforce --params fit1/fit.json --speed 2mm/s "
      "--angle 90deg --depth 20mm");
  cmd->add_option("--model", args->model, "Force model")->capture_default_str();
  cmd->add_option("--params", args->params_file, "Parameters written by `mneedle fit --json/--out`")
      ->required();
  cmd->add_option("--speed", args->speed, "Insertion speed")->capture_default_str();
  cmd->add_option("--angle", args->angle, "Needle-to-surface angle (90deg = perpendicular)")
      ->capture_default_str();
  cmd->add_option("--depth", args->depth, "Insertion depth (travel from contact)");
  cmd->add_option("--hold", args->hold, "Hold at depth before retraction")->capture_default_str();
  cmd->add_option("--max-samples", args->max_samples,
                  "Largest number of time samples a prediction may have")
      ->capture_default_str();
  cmd->add_option("--retract-speed", args->retract_speed, "Retraction speed (default: --speed)");
  cmd->add_option("--step", args->step, "Output time step")->capture_default_str();
  cmd->add_option("--perturb-amplitude", args->amplitude, "Lateral vibration amplitude A")
      ->capture_default_str();
  cmd->add_option("--perturb-frequency", args->frequency_Hz, "Lateral vibration frequency f, Hz")
      ->capture_default_str();
  cmd->add_option("--compare", args->compare,
                  "Measured CSV: report RMSE, R2, max error of the prediction");
  cmd->add_option("--depth-col", args->curve.depth_col, "Depth column of --compare");
  cmd->add_option("--force-col", args->curve.force_col, "Force column of --compare");
  auto* csv = cmd->add_flag("--csv", args->csv, "CSV output (the default)");
  cmd->add_flag("--json", args->json, "JSON output")->excludes(csv);
  cmd->add_option("--plot", args->plot, "Write the predicted force against depth as SVG");
  cmd->callback([args] { run_predict(*args); });
}

void add_stats_command(CLI::App& app) {
  auto args = std::make_shared<StatsArgs>();
  auto* cmd = app.add_subcommand("stats", "One-way ANOVA and Tukey HSD between groups");
  cmd->footer("Example:\n  mneedle stats peaks.csv --value force_N --group group");
  cmd->add_option("grouped", args->file, "CSV with a group column and a value column")->required();
  cmd->add_option("--value", args->value, "Value column")->capture_default_str();
  cmd->add_option("--group", args->group, "Group column")->capture_default_str();
  cmd->add_option("--alpha", args->alpha, "Family-wise significance level")->capture_default_str();
  cmd->add_option("--max-groups", args->max_groups,
                  "Most groups to compare (every pair is a row of the Tukey table)")
      ->check(CLI::Range(std::size_t{2}, std::size_t{1000000}))
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([args] { run_stats(*args); });
}

}  // namespace mneedle::cli
