// mneedle screen: rank a folder of needle designs on one scene (docs/cli.md).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/screening_report.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/units.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/screening.h"
#include "mneedle/screening_mpi.h"
#include "mneedle/uncertainty.h"
#include "mpi_start.h"
#include "option_values.h"
#include "report_needles.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct ScreenArgs {
  std::vector<std::string> designs;
  std::string scene;
  std::string unit = "mm";
  std::string material;
  std::string fidelity = "fast";
  std::string model = "auto";
  std::string axis = "auto";
  bool repair = false;
  int jobs = 1;
  std::string out;
  std::string report;
  bool json = false;
  bool resume = false;
  bool mpi = false;
  int uncertainty = 0;
  std::vector<std::string> vary;
  std::uint64_t seed = 1;
  std::string method = "mc";
  std::vector<std::string> plugin_dirs;
};

std::string cell(double value, Dimension d) {
  return format_quantity(value, d);
}

void print_table(const std::vector<ScreeningRow>& ranked, const Scene& scene,
                 const std::string& material) {
  std::printf("Scene %s: depth %s, material %s, safety factor %.2f\n", scene.source_name.c_str(),
              format_quantity(scene.requirements.target_depth.value_or(scene.insertion.depth),
                              Dimension::Length)
                  .c_str(),
              material.c_str(), scene.requirements.safety_factor);
  std::printf(
      "Ranked by puncture depth, then puncture force (two-stage model: FE until the %s "
      "criterion fires, then paper A's distributed loads); designs that do not puncture "
      "before the target depth come last. pass = punctures before the target depth and "
      "margin (capacity / peak force) >= safety factor. A depth marked * is where the "
      "criterion already fires at the first depth step: not resolved, ranked after the "
      "resolved ones (docs/model.md, \"Criteria\"). A depth marked + is a lower bound (a flat "
      "end under the penetration criterion), ranked after the resolved ones too.\n\n",
      std::string(to_string(scene.model.criterion)).c_str());
  bool sampled = false;
  for (const auto& row : ranked) sampled = sampled || row.pass_probability.has_value();
  if (sampled)
    std::printf(
        "With --uncertainty: ranked by the probability of passing over the sampled scenes "
        "(the same draws for every design), then by the median puncture depth; the columns are "
        "the nominal run's.\n\n");
  std::printf("%-4s %-24s %-6s %-11s %-11s %-11s %-11s %-9s %-8s %s\n", "rank", "design", "status",
              "puncture at", "force", "peak force", "capacity", "governing", "margin", "model");
  int rank = 0;
  for (const auto& row : ranked) {
    if (!row.ok) {
      std::printf("%-4s %-24s %-6s %s\n", "-", row.design.c_str(), "error", row.error.c_str());
      continue;
    }
    const auto j = nlohmann::json::parse(row.json);
    // Four significant digits in the 8-column cell: 7.32e10 must not print as "732099".
    char margin_text[32];
    std::snprintf(margin_text, sizeof margin_text, "%.4g", row.margin);
    const std::string margin = j["margin"].is_null() ? "no load" : margin_text;
    std::string models;
    for (const auto& m : j["models_run"])
      models += (models.empty() ? "" : "+") + m.get<std::string>();
    const std::string depth =
        row.puncture_depth_m
            ? cell(*row.puncture_depth_m, Dimension::Length) + (row.puncture_at_first_contact ? "*"
                                                                : row.puncture_lower_bound    ? "+"
                                                                                              : "")
            : "none";
    const std::string force =
        row.puncture_depth_m ? cell(row.puncture_force_n, Dimension::Force) : "-";
    std::printf("%-4d %-24s %-6s %-11s %-11s %-11s %-11s %-9s %-8s %s\n", ++rank,
                row.design.c_str(), row.passes ? "pass" : "FAIL", depth.c_str(), force.c_str(),
                cell(row.peak_force_n, Dimension::Force).c_str(),
                cell(j["capacity_N"].get<double>(), Dimension::Force).c_str(),
                j["governing"].get<std::string>().c_str(), margin.c_str(), models.c_str());
    if (row.pass_probability) {
      const auto& u = j["uncertainty"];
      const auto& d = u["puncture_depth_m"];
      const double p = *row.pass_probability;
      std::printf(
          "     P(pass) %.1f %% (standard error %.1f %%) of %d samples; puncture depth 5/50/95 "
          "%%: %s\n",
          100.0 * p, 100.0 * u["pass_probability_standard_error"].get<double>(),
          u["samples"].get<int>(),
          d["p50"].is_null() ? "no resolved puncture"
                             : (cell(d["p5"].get<double>(), Dimension::Length) + " / " +
                                cell(d["p50"].get<double>(), Dimension::Length) + " / " +
                                cell(d["p95"].get<double>(), Dimension::Length))
                                   .c_str());
    }
  }
}

// What every rank of an MPI run prepares alike from the command line; only the writer (rank 0,
// or the one process) creates --out and records the run in it.
struct ScreenSetup {
  Scene scene;
  PluginRegistry registry;
  std::vector<DesignInput> designs;
  ScreeningOptions options;
};

ScreenSetup prepare_screen(const ScreenArgs& args, bool writer) {
  ScreenSetup s{
      load_scene(args.scene),
      PluginRegistry::discover({args.plugin_dirs.begin(), args.plugin_dirs.end()}),
      collect_designs({args.designs.begin(), args.designs.end()}, option_length_unit(args.unit)),
      {}};
  if (writer) {
    record_scene(s.scene, args.scene);
    // Each design's file, as the scene's own STL needles are (a design list once, however many
    // designs it holds): the provenance names every byte the ranking came from.
    std::set<std::filesystem::path> lists;
    for (const DesignInput& d : s.designs) {
      if (d.plugin) {
        if (lists.insert(d.file).second) record_input("design list", d.file);
      } else {
        record_input("design " + d.name, d.file);
      }
    }
  }
  ScreeningOptions& options = s.options;
  options.jobs = args.jobs;
  if (!args.material.empty()) options.material = args.material;
  options.resume = args.resume;
  options.fidelity = args.fidelity;
  options.model = args.model;
  options.axis = args.axis;
  options.repair = args.repair;
  parse_axis_choice(args.axis);  // a bad --axis is a usage error before any design runs
  check_screening_scene(s.scene, s.registry, options);
  if (args.uncertainty > 0 && args.vary.empty())
    throw InputError("screen: --uncertainty N needs the values to vary (--vary PATH=DIST)");
  if (args.uncertainty == 0 && !args.vary.empty())
    throw InputError("screen: --vary needs --uncertainty N (the number of samples)");
  if (args.uncertainty > 0) {
    for (const auto& spec : args.vary) options.vary.push_back(parse_varied_value(spec));
    options.uncertainty.samples = args.uncertainty;
    options.uncertainty.seed = args.seed;
    run_provenance().seed = args.seed;
    options.uncertainty.latin_hypercube = args.method == "lhs";
    // Every path checked against the scene once, before any design runs.
    std::vector<std::pair<VariedValue, double>> medians;
    for (const auto& v : options.vary)
      medians.emplace_back(v, distribution_quantile(v.distribution, 0.5));
    parse_scene(scene_with_values(read_input_file(args.scene), args.scene, medians),
                args.scene + " (with drawn values)");
  }
  if (options.resume && args.out.empty()) throw InputError("screen: --resume needs --out DIR");
  if (!args.out.empty()) {
    options.out = args.out;
    if (writer) {
      create_output_folder(args.out, "--out");
      append_provenance_line(args.out);
    }
  }
  // Checked before any design runs (it was refused only after the whole batch).
  if (writer && !args.report.empty()) create_output_folder(args.report, "--report");
  return s;
}

void run_screen(const ScreenArgs& args) {
  std::optional<MpiSession> session;
  start_mpi(session, args.mpi, args.jobs, "screen", "screen every design into the same files");
  const bool writer = !session || session->rank() == 0;
  std::optional<ScreenSetup> setup;
  setup_on_every_rank(
      session, [&] { setup.emplace(prepare_screen(args, writer)); }, "screen");
  const Scene& scene = setup->scene;
  const ScreeningOptions& options = setup->options;
  const auto on_row = [&](const ScreeningRow& row) {
    if (!args.json) {
      std::cerr << (row.resumed ? "resumed " : "done    ") << row.design
                << (row.frame_note.empty() ? "" : " (" + row.frame_note + ")") << "\n";
    }
  };
  std::vector<ScreeningRow> screened;
  if (session) {
    try {
      screened = screen_designs_mpi(*session, setup->designs, scene, args.scene, setup->registry,
                                    options, on_row);
    } catch (const RankStopped&) {
      throw QuietExit{0};
    }
  } else {
    screened = screen_designs(setup->designs, scene, args.scene, setup->registry, options, on_row);
  }
  const auto rows = rank_rows(std::move(screened));
  if (!writer) return;  // rank 0 reports the run
  const std::vector<std::string> warnings = screening_warnings(rows, scene);
  for (const std::string& w : warnings) std::cerr << "mneedle: warning: " << w << "\n";
  std::size_t failed = 0;
  for (const auto& r : rows) failed += r.ok ? 0 : 1;
  const nlohmann::json out = screening_json(rows, args.scene, options, warnings);
  if (args.json) {
    std::cout << with_provenance(out).dump(2) << "\n";
  } else {
    std::string material = args.material;
    for (const auto& r : rows)
      if (r.ok && material.empty()) material = nlohmann::json::parse(r.json)["material"];
    print_table(rows, scene, material);
  }
  // After the table (a report that cannot be written loses none of it), before the failures'
  // error: a design that failed still leaves every finished row in the report.
  std::cout.flush();
  if (!args.report.empty()) write_report_folder(args.report, out, args.plugin_dirs);
  if (failed > 0)
    throw InputError("screen: " + std::to_string(failed) + " of " + std::to_string(rows.size()) +
                     " designs failed (their rows say why)");
}

}  // namespace

void add_screen_command(CLI::App& app) {
  auto args = std::make_shared<ScreenArgs>();
  auto* cmd = app.add_subcommand(
      "screen", "Rank needle designs (mesh files, folders, design lists) on a scene");
  cmd->footer(
      "Examples:\n"
      "  mneedle screen designs --scene designs/scenes/human_skin.toml\n"
      "  mneedle screen designs/*.stl my_designs.toml --scene skin.toml --jobs 2 --out results "
      "--resume");
  cmd->add_option("designs", args->designs, "Mesh files, folders of them, or TOML design lists")
      ->required();
  cmd->add_option("--scene", args->scene, "Scene file (TOML)")->required();
  cmd->add_option("--unit", args->unit, "Length unit of the mesh files: um, mm, m")
      ->capture_default_str();
  cmd->add_option("--material", args->material,
                  "Needle material (default: the scene's, else silicon)");
  cmd->add_option("--fidelity", args->fidelity,
                  "FE mesh level of the pre-puncture stage: fast, standard or fine")
      ->capture_default_str()
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_option("--axis", args->axis,
                  "Needle axis in the mesh files: auto (principal axis, tip at the narrower end), "
                  "x, y, z, or a tip direction a,b,c; a holder the needle stands on is cut off")
      ->capture_default_str();
  cmd->add_flag("--repair", args->repair,
                "Repair mesh files before checking them (outward orientation, degenerate faces, "
                "borders), as inspect --repair; the row says what changed");
  cmd->add_option("--model", args->model,
                  "Pre-puncture model: auto (axisymmetric for cylinders and cones on the axis, "
                  "else 3-D), analytic, axisymmetric or 3d")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "analytic", "axisymmetric", "3d"}));
  cmd->add_option("--jobs", args->jobs,
                  "Designs evaluated at once (each with one OpenBLAS thread when > 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--out", args->out,
                  "Folder for results.csv and results.jsonl, written as designs finish");
  cmd->add_flag("--resume", args->resume, "Skip designs already in --out for the same inputs");
  cmd->add_option("--uncertainty", args->uncertainty,
                  "Also run every design in N scenes with the --vary values drawn (the same "
                  "draws for every design) and rank by the probability of passing")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--vary", args->vary,
                  "With --uncertainty: PATH=normal(MEAN,SD)|lognormal(MEDIAN,CV%)|"
                  "uniform(LOW,HIGH), as mneedle uncertainty (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--seed", args->seed, "With --uncertainty: seed of the draws")
      ->capture_default_str();
  cmd->add_option("--method", args->method, "With --uncertainty: mc or lhs")
      ->capture_default_str()
      ->check(CLI::IsMember({"mc", "lhs"}));
  cmd->add_flag("--mpi", args->mpi,
                "Share the designs among the processes of mpirun -n N (rank 0 writes; each "
                "rank runs --jobs threads)");
  cmd->add_option("--plugin-dir", args->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->add_option(
      "--report", args->report,
      "Write result.json and report.html (ranking, curves, 3-D needles) to this folder");
  cmd->callback([args] { run_screen(*args); });
}

}  // namespace mneedle::cli
