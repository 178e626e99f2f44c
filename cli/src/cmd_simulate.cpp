// `mneedle simulate SCENE [--fidelity ...] [--contact ...] [--criterion ...] [--model ...]
// [--json|--csv] [--vtu DIR]`: the two-stage insertion of paper A (run_insertion). The scene
// planner picks the pre-puncture model (axisymmetric for one needle of revolution on the axis,
// a half 3-D model for mirror-symmetric needles on y = 0, the full 3-D block otherwise), stops it
// where the puncture criterion fires, and continues with the post-puncture surface loads.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/simulation.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/insertion/energy_check.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/plot/figure.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "progress_line.h"
#include "report_needles.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct SimulateOptions {
  std::filesystem::path scene;
  SimulateSettings settings;
  std::string vtu;
  bool json = false;
  bool csv = false;
  bool quiet = false;  // no progress line
  std::string plot;    // SVG of force against depth
  std::string report;  // folder for result.json and report.html
  std::vector<std::string> plugin_dirs;
};

InsertionRunOptions run_options(const Scene& scene, const SimulateOptions& o) {
  InsertionRunOptions r = simulate_run_options(scene, o.settings);
  // The closed form has no field to write (it made an empty folder and said nothing).
  if (!o.vtu.empty() && o.settings.model == "analytic")
    throw InputError(
        "--vtu: the analytic model has no field to write; use --model "
        "axisymmetric or 3d");
  r.vtu_directory = o.vtu;
  if (r.vtu_directory.empty() && scene.model.wants(Output::Fields) &&
      o.settings.model == "analytic") {
    std::cerr << "mneedle: the scene asks for fields; the analytic model has none to write\n";
  } else if (r.vtu_directory.empty() && scene.model.wants(Output::Fields)) {
    // The scene asks for fields: write them beside the working directory, named after it.
    r.vtu_directory = o.scene.stem().string() + "_fields";
    std::cerr << "mneedle: the scene asks for fields: writing VTU files to " << r.vtu_directory
              << "/\n";
  }
  return r;
}

void print_csv(const InsertionRun& run) {
  std::cout << provenance_comment() << "\n";
  std::cout << "depth_m,force_N,stage,lateral_force_x_N,lateral_force_y_N,contact_area_m2,"
               "contact_pressure_Pa,section_area_m2,section_pressure_Pa,strain_energy_J,alpha_N,"
               "beta_N,friction_N,collar_N,needle\n";
  std::cout << std::setprecision(9);
  auto rows = [](const std::vector<RunPoint>& curve, const std::string& name) {
    for (const RunPoint& p : curve)
      std::cout << p.depth_m << "," << p.force_N << "," << to_string(p.stage) << ","
                << p.lateral_force_N[0] << "," << p.lateral_force_N[1] << "," << p.contact_area_m2
                << "," << p.contact_pressure_Pa << "," << p.section_area_m2 << ","
                << p.section_pressure_Pa << "," << p.strain_energy_J << "," << p.alpha_N << ","
                << p.beta_N << "," << p.friction_N << "," << p.collar_N << "," << name << "\n";
  };
  for (const NeedleRun& n : run.needles) rows(n.curve, n.name);
  if (run.needles.size() > 1) rows(run.total_curve, "total");
}

void print_table(const InsertionRun& run) {
  std::cout << "models: ";
  for (std::size_t i = 0; i < run.models_run.size(); ++i)
    std::cout << (i ? " + " : "") << run.models_run[i];
  std::cout << " (" << fe::to_string(run.fidelity) << ", " << std::setprecision(3) << run.seconds
            << " s";
  if (run.nodes > 0)
    std::cout << "; mesh " << run.nodes << " nodes, " << run.elements << " elements"
              << (run.axisymmetric ? ", axisymmetric" : "");
  std::cout << ")\n";
  for (const Reduction& r : run.reductions)
    std::cout << "  reduction " << r.name << ": " << r.detail << "\n";
  if (run.stopped)
    std::cout << "the finite element run stopped after its step at "
              << format_quantity(run.stopped->depth_m, Dimension::Length) << " ("
              << run.stopped->reason << "): the curves end there\n";
  for (const NeedleRun& n : run.needles) {
    std::cout << "needle " << n.name << ": ";
    if (n.puncture)
      std::cout << std::fixed << std::setprecision(1) << "punctures at "
                << n.puncture->depth_m * 1e6 << " um (" << to_string(n.puncture->criterion)
                << " criterion), force " << std::setprecision(3) << n.puncture->force_N * 1e3
                << " mN, then " << n.puncture->post_force_N * 1e3 << " mN post-puncture"
                << (n.puncture->at_first_contact
                        ? " [at first contact: the criterion is above its threshold at the first "
                          "depth step, so this depth is the step's, not the tissue's]"
                        : "")
                << (n.puncture->flat_tip
                        ? " [flat tip: F_p is a sharp tip's, a flat end needs more, so this "
                          "depth is a lower bound]"
                        : "");
    else if (run.criterion && run.stopped)
      std::cout << "no puncture before " << format_quantity(run.stopped->depth_m, Dimension::Length)
                << ", where the finite element run stopped";
    else if (run.criterion)
      std::cout << "no puncture within the insertion depth";
    else
      std::cout << "no puncture data in the scene: pre-puncture stage only";
    std::cout << std::fixed << std::setprecision(3) << "; max force " << n.max_force_N * 1e3
              << " mN\n";
    const bool stress = run.criterion == PunctureCriterion::Stress;
    const bool energy = run.criterion == PunctureCriterion::Energy;
    const bool penetration = run.criterion == PunctureCriterion::Penetration;
    const bool cohesive = run.criterion == PunctureCriterion::Cohesive;
    std::cout << "  depth [um]  stage   force [mN]   F/A_sec [MPa]"
              << (stress        ? "   tip stress [MPa]"
                  : energy      ? "   G [J/m^2]"
                  : penetration ? "   F_p [mN]"
                  : cohesive    ? "   crack [um]   damaged [um]   zone cells"
                                : "")
              << "\n";
    for (const RunPoint& p : n.curve) {
      std::cout << std::setprecision(2) << std::setw(12) << p.depth_m * 1e6 << "  " << std::setw(5)
                << to_string(p.stage) << std::setprecision(4) << std::setw(13) << p.force_N * 1e3
                << std::setw(16) << p.section_pressure_Pa * 1e-6;
      if (stress && p.stage == Stage::Pre) std::cout << std::setw(19) << p.tip_stress_Pa * 1e-6;
      if (energy && p.stage == Stage::Pre)
        std::cout << std::setw(13) << p.energy_release_rate_J_per_m2;
      if (penetration && p.stage == Stage::Pre)
        std::cout << std::setw(12) << p.penetration_force_N * 1e3;
      if (cohesive && p.stage == Stage::Pre)
        std::cout << std::setprecision(2) << std::setw(13) << p.cohesive_crack_m * 1e6
                  << std::setw(15) << p.cohesive_zone_m * 1e6 << std::setw(13)
                  << p.process_zone_cells;
      std::cout << "\n";
    }
    std::cout.unsetf(std::ios::fixed);
  }
}

// Force against depth of every needle (and their sum), the puncture and the post-puncture force
// marked, a line where the first puncture happens.
plot::Figure simulate_figure(const InsertionRun& run, const std::string& title) {
  plot::Figure f;
  f.title = title;
  f.x.name = "depth below the surface";
  for (const NeedleRun& n : run.needles) {
    plot::Series s;
    s.label = n.name;
    for (const RunPoint& p : n.curve) {
      s.x.push_back(p.depth_m);
      s.y.push_back(p.force_N);
    }
    f.series.push_back(std::move(s));
    if (n.puncture) {
      f.points.push_back({"puncture " + n.name, n.puncture->depth_m, n.puncture->force_N});
      f.points.push_back({"after", n.puncture->depth_m, n.puncture->post_force_N});
    }
  }
  if (run.needles.size() > 1) {
    plot::Series s;
    s.label = "total";
    for (const RunPoint& p : run.total_curve) {
      s.x.push_back(p.depth_m);
      s.y.push_back(p.force_N);
    }
    f.series.push_back(std::move(s));
  }
  // Where a stopped run's curves end (docs/cli.md, "A run whose solver stops"): marked, so the
  // end of a curve is not read as the end of the insertion.
  if (run.stopped && !run.total_curve.empty())
    f.points.push_back(
        {"FE stopped", run.total_curve.back().depth_m, run.total_curve.back().force_N});
  return f;
}

void run(SimulateOptions o) {
  // A run whose FE stops part-way still prints what it reached, then fails (docs/cli.md, "A run
  // whose solver stops"): the curve up to there is what a user looking at the stop needs.
  o.settings.keep_reached = true;
  Scene scene = load_scene(o.scene);
  apply_simulate_settings(scene, o.settings);
  const PluginRegistry registry =
      PluginRegistry::discover({o.plugin_dirs.begin(), o.plugin_dirs.end()});
  // Checked before any needle is built: the finite element limit below would otherwise come
  // only after every mesh of a 10 000-needle scene was made.
  const std::vector<PreparedNeedle> needles =
      prepare_needles(registry, scene, o.settings.max_needles);
  if (!o.report.empty()) create_output_folder(o.report, "--report");  // before the run
  record_scene(scene, o.scene);
  record_plugin_meshes(scene, needles);
  for (const PreparedNeedle& n : needles) {
    if (!n.frame_note.empty())
      std::cerr << "mneedle: needle " << n.name << ": " << n.frame_note << "\n";
  }
  InsertionRunOptions options = run_options(scene, o);
  if (!options.vtu_directory.empty()) options.vtu_comment = provenance_comment().substr(2);
  ProgressLine progress(std::cerr, "simulate", stderr_is_terminal(), o.quiet);
  options.on_progress = [&](const std::string& model, int step, int steps, double depth,
                            double force) {
    progress.update({model, step, steps, depth, force});
  };
  const InsertionRun result = run_insertion(scene, needles, options);
  progress.finish();
  // Every format prints the numbers of this tree: check them once, before anything is printed.
  const nlohmann::json tree = simulation_json(result, scene, needles, o.settings);
  if (result.energy_check && !result.energy_check->passes)
    std::cerr << "mneedle: warning: " << o.scene.string() << ": the tissue stores "
              << std::setprecision(3) << 100.0 * (1.0 + result.energy_check->relative_difference)
              << " % of the work the needle did on it up to "
              << format_quantity(result.energy_check->depth_m, Dimension::Length) << " (more than "
              << 100.0 * kEnergyCheckTolerance
              << " % apart: the contact or the mesh is not resolved; docs/model.md, \"Energy "
                 "check\")\n";
  for (const std::string& w : criterion_warnings(result, scene))
    std::cerr << "mneedle: warning: " << w << "\n";
  if (!o.plot.empty())
    plot::write_svg(o.plot, simulate_figure(result, "simulate: " + o.scene.filename().string()));
  if (o.json)
    std::cout << with_provenance(tree).dump(2) << "\n";
  else if (o.csv)
    print_csv(result);
  else
    print_table(result);
  std::cout.flush();  // printed before the report: a report that cannot be written loses none
  if (!o.report.empty()) write_report_folder(o.report, tree, o.plugin_dirs);
  if (result.stopped) {
    std::cout.flush();
    throw SolverError(result.stopped->reason);  // exit status 3, the one-line error
  }
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Two-stage insertion: pre-puncture FE until the puncture criterion fires, then "
      "the post-puncture distributed loads");
  cmd->add_option("scene", options->scene, "scene file (TOML)")->required();
  cmd->add_option("--fidelity", options->settings.fidelity, "mesh fidelity (default: the scene's)")
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_option("--contact", options->settings.contact, "needle contact (default: the scene's)")
      ->check(CLI::IsMember({"sticking", "frictionless"}));
  cmd->add_option("--criterion", options->settings.criterion,
                  "puncture criterion (default: the scene's)")
      ->check(CLI::IsMember({"pressure", "energy", "stress", "penetration", "cohesive"}));
  cmd->add_option("--axis", options->settings.axis,
                  "Axis of the scene's STL needles (overrides their axis key): auto, x, y, z or "
                  "a tip direction a,b,c");
  cmd->add_option("--model", options->settings.model,
                  "pre-puncture model: auto (the planner decides), analytic, axisymmetric or 3d")
      ->check(CLI::IsMember({"auto", "analytic", "axisymmetric", "3d"}))
      ->capture_default_str();
  cmd->add_option("--vtu", options->vtu,
                  "write the fields of every pre-puncture step here for ParaView (steps.pvd)");
  cmd->footer(
      "Examples:\n  mneedle simulate designs/scenes/silicone_phantom.toml --fidelity fast\n"
      "  mneedle simulate designs/scenes/human_skin.toml --criterion stress --json\n"
      "  mneedle simulate tests/assets/scenes/axisymmetric_punch.toml --csv");
  cmd->add_option("--plugin-dir", options->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->add_option("--max-needles", options->settings.max_needles,
                  "Most needles the scene may hold (each finite element model holds them all)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}));
  cmd->add_flag("--no-reductions", options->settings.no_reductions,
                "solve the whole scene: no half model, layer merge or domain cut (to check them)");
  auto* json = cmd->add_flag("--json", options->json, "print the run as JSON");
  cmd->add_flag("--csv", options->csv, "print the curves as CSV")->excludes(json);
  cmd->add_option("--plot", options->plot, "write force against depth as SVG");
  cmd->add_option("--report", options->report,
                  "write result.json and report.html (tables, plots, 3-D needle) to this folder");
  cmd->add_flag("--quiet", options->quiet,
                "no progress line on stderr (shown for runs longer than a second)");
  cmd->callback([options]() { run(*options); });
}

}  // namespace mneedle::cli
