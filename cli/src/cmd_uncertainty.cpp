// mneedle uncertainty: the spread of puncture depth, forces and margin when scene values vary
// (docs/cli.md, "mneedle uncertainty").
#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/plot/figure.h"
#include "mneedle/screening_mpi.h"
#include "mneedle/uncertainty.h"
#include "mpi_start.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct UncertaintyArgs {
  std::string scene;
  std::vector<std::string> vary;
  int samples = 200;
  std::uint64_t seed = 1;
  std::string method = "mc";
  int jobs = 1;
  std::string fidelity = "fast";
  std::string model = "auto";
  std::string material;
  bool no_sensitivity = false;
  bool json = false;
  bool mpi = false;
  std::string plot;  // SVG: the distribution of puncture depth (or peak force)
  std::vector<std::string> plugin_dirs;
};

nlohmann::json optional_number(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

// `paths` name s.values in order (a sample: every input; a sensitivity run: its one input).
nlohmann::json sample_json(const UncertaintySample& s, const std::vector<std::string>& paths) {
  nlohmann::json values = nlohmann::json::object();
  for (std::size_t k = 0; k < s.values.size() && k < paths.size(); ++k)
    values[paths[k]] = s.values[k];
  nlohmann::json j = {{"values_si", values}, {"ok", s.ok}};
  if (!s.ok) {
    j["error"] = s.error;
    return j;
  }
  j["puncture_depth_m"] = optional_number(s.puncture_depth_m);
  j["puncture_force_N"] = s.puncture_depth_m ? nlohmann::json(s.puncture_force_n) : nullptr;
  j["puncture_at_first_contact"] = s.puncture_at_first_contact;
  j["puncture_objective_m"] = s.puncture_objective_m;
  j["peak_force_N"] = s.peak_force_n;
  j["margin"] = std::isfinite(s.margin) ? nlohmann::json(s.margin) : nullptr;
  j["passes"] = s.passes;
  return j;
}

nlohmann::json percentiles_json(const Percentiles& p) {
  if (p.count == 0) return {{"count", 0}, {"p5", nullptr}, {"p50", nullptr}, {"p95", nullptr}};
  return {{"count", p.count}, {"p5", p.p5}, {"p50", p.p50}, {"p95", p.p95}};
}

std::string kind_name(DistributionKind k) {
  switch (k) {
    case DistributionKind::Normal:
      return "normal";
    case DistributionKind::LogNormal:
      return "lognormal";
    case DistributionKind::Uniform:
      return "uniform";
  }
  return "";
}

void print_row(const char* what, const Percentiles& p, Dimension d) {
  if (p.count == 0) {
    std::printf("  %-22s (no sample has it)\n", what);
    return;
  }
  std::printf("  %-22s %-12s %-12s %-12s (%zu samples)\n", what, format_quantity(p.p5, d).c_str(),
              format_quantity(p.p50, d).c_str(), format_quantity(p.p95, d).c_str(), p.count);
}

// The empirical distribution function of the resolved puncture depths (or, when no sample has
// one, of the peak forces), with the 5 %, 50 % and 95 % percentiles marked.
plot::Figure distribution_figure(const UncertaintyResult& r, const std::string& scene) {
  const bool depths = r.puncture_depth_m.count > 0;
  std::vector<double> values;
  for (const auto& s : r.samples) {
    if (!s.ok) continue;
    if (!depths)
      values.push_back(s.peak_force_n);
    else if (s.puncture_depth_m && !s.puncture_at_first_contact)
      values.push_back(*s.puncture_depth_m);
  }
  std::sort(values.begin(), values.end());
  plot::Figure f;
  f.title = "uncertainty: " + std::filesystem::path(scene).filename().string() + ", " +
            std::to_string(values.size()) + " samples" +
            (depths ? " with a resolved puncture" : " (none punctures: peak force)");
  f.x = {depths ? "puncture depth" : "peak force", depths ? Dimension::Length : Dimension::Force,
         "", false};
  f.y = {"share of samples at or below", Dimension::Dimensionless, "%", false};
  plot::Series cdf;
  cdf.label = "samples";
  const double n = static_cast<double>(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {  // a step at every sample
    cdf.x.insert(cdf.x.end(), {values[i], values[i]});
    cdf.y.insert(cdf.y.end(),
                 {100.0 * static_cast<double>(i) / n, 100.0 * static_cast<double>(i + 1) / n});
  }
  f.series.push_back(std::move(cdf));
  const Percentiles& p = depths ? r.puncture_depth_m : r.peak_force_n;
  f.lines = {{"5 %", p.p5}, {"median", p.p50}, {"95 %", p.p95}};
  return f;
}

void run_uncertainty_command(const UncertaintyArgs& args) {
  std::optional<MpiSession> session;
  start_mpi(session, args.mpi, args.jobs, "uncertainty",
            "run every sample and print the same result");
  const bool writer = !session || session->rank() == 0;
  std::vector<VariedValue> inputs;
  std::optional<PluginRegistry> found;
  setup_on_every_rank(
      session,
      [&] {
        for (const auto& spec : args.vary) inputs.push_back(parse_varied_value(spec));
        if (args.method != "mc" && args.method != "lhs")
          throw InputError("uncertainty: --method '" + args.method + "' (mc or lhs)");
        found.emplace(PluginRegistry::discover({args.plugin_dirs.begin(), args.plugin_dirs.end()}));
        // Inside the setup: an unreadable scene must stop every rank, not rank 0 alone.
        if (writer) record_input("scene", args.scene);
      },
      "uncertainty");
  const PluginRegistry& registry = *found;
  UncertaintyOptions options;
  options.samples = args.samples;
  options.seed = args.seed;
  run_provenance().seed = args.seed;  // the draws are random (docs/cli.md, "Provenance")
  options.latin_hypercube = args.method == "lhs";
  options.jobs = args.jobs;
  options.fidelity = args.fidelity;
  options.model = args.model;
  if (!args.material.empty()) options.material = args.material;
  options.sensitivity = !args.no_sensitivity;
  const bool terminal = writer && ::isatty(STDERR_FILENO) == 1;
  // As every long run (docs/cli.md, "Progress"): redrawn on a terminal; to a file or a pipe one
  // line per ten runs once a second has passed (200 samples ran for minutes without a word).
  const auto started = std::chrono::steady_clock::now();
  const auto progress = [&](int done, int total) {
    if (!writer || !(done == total || done % 10 == 0)) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (terminal) {
      std::cerr << "\runcertainty: " << done << " of " << total << " runs" << std::flush;
    } else if (elapsed >= 1.0) {
      char seconds[32];
      std::snprintf(seconds, sizeof seconds, "%.1f", elapsed);
      std::cerr << "uncertainty: " << done << " of " << total << " runs, " << seconds << " s\n";
    }
  };
  std::optional<UncertaintyResult> result;
  if (session) {
    try {
      result = run_uncertainty_mpi(*session, args.scene, inputs, registry, options, progress);
    } catch (const RankStopped&) {
      throw QuietExit{0};
    }
    if (!result) return;  // a rank > 0: rank 0 reports the run
  } else {
    result = run_uncertainty(args.scene, inputs, registry, options, progress);
  }
  const UncertaintyResult& r = *result;
  if (terminal) std::cerr << "\n";

  nlohmann::json out = {{"scene", args.scene},       {"samples", args.samples},
                        {"seed", args.seed},         {"method", args.method},
                        {"fidelity", args.fidelity}, {"model", args.model}};
  out["inputs"] = nlohmann::json::array();
  for (const auto& v : r.inputs)
    out["inputs"].push_back({{"path", v.path},
                             {"text", v.text},
                             {"distribution", kind_name(v.distribution.kind)},
                             {"a_si", v.distribution.a},
                             {"b_si", v.distribution.b},
                             {"unit", std::string(si_unit(v.distribution.dimension))},
                             {"p5_si", distribution_quantile(v.distribution, 0.05)},
                             {"p95_si", distribution_quantile(v.distribution, 0.95)}});
  out["nominal"] = sample_json(r.nominal, {});
  out["summary"] = {{"puncture_depth_m", percentiles_json(r.puncture_depth_m)},
                    {"puncture_force_N", percentiles_json(r.puncture_force_n)},
                    {"peak_force_N", percentiles_json(r.peak_force_n)},
                    {"margin", percentiles_json(r.margin)},
                    {"punctured_fraction", r.punctured_fraction},
                    {"first_contact_fraction", r.first_contact_fraction},
                    {"pass_probability", r.pass_probability},
                    {"pass_probability_standard_error", r.pass_probability_standard_error},
                    {"failed_samples", r.failed}};
  out["sensitivity"] = nlohmann::json::array();
  for (const auto& s : r.sensitivity)
    out["sensitivity"].push_back({{"path", s.path},
                                  {"low", sample_json(s.low, {s.path})},
                                  {"high", sample_json(s.high, {s.path})},
                                  {"depth_effect_m", optional_number(s.depth_effect_m)},
                                  {"depths_resolved", s.both_resolved},
                                  {"peak_effect_N", optional_number(s.peak_effect_n)}});
  std::vector<std::string> paths;
  for (const auto& v : r.inputs) paths.push_back(v.path);
  out["rows"] = nlohmann::json::array();
  for (const auto& s : r.samples) out["rows"].push_back(sample_json(s, paths));
  if (args.json) {
    print_checked_json(std::cout, out, "uncertainty");
  } else {
    require_finite_json(out, "uncertainty");
    std::printf("Scene %s: %d samples (%s, seed %llu), %s fidelity, model %s\n", args.scene.c_str(),
                args.samples, args.method == "lhs" ? "Latin hypercube" : "Monte Carlo",
                static_cast<unsigned long long>(args.seed), args.fidelity.c_str(),
                args.model.c_str());
    for (const auto& v : r.inputs)
      std::printf(
          "  vary %-30s 5 %%: %-12s 95 %%: %s\n", v.text.c_str(),
          format_quantity(distribution_quantile(v.distribution, 0.05), v.distribution.dimension)
              .c_str(),
          format_quantity(distribution_quantile(v.distribution, 0.95), v.distribution.dimension)
              .c_str());
    std::printf("\n  %-22s %-12s %-12s %-12s\n", "", "5 %", "median", "95 %");
    print_row("puncture depth", r.puncture_depth_m, Dimension::Length);
    print_row("force at puncture", r.puncture_force_n, Dimension::Force);
    print_row("peak force", r.peak_force_n, Dimension::Force);
    print_row("margin", r.margin, Dimension::Dimensionless);
    std::printf(
        "\n  punctured before the target depth: %.1f %% of samples (first-contact "
        "crossings not counted)\n  passes: %.1f %% (standard error %.1f %%)\n",
        100.0 * r.punctured_fraction, 100.0 * r.pass_probability,
        100.0 * r.pass_probability_standard_error);
    if (r.first_contact_fraction > 0.0)
      std::printf(
          "  fired at the first depth step (depth unresolved, not in the spread): %.1f %%\n",
          100.0 * r.first_contact_fraction);
    if (r.margin.count < r.peak_force_n.count)
      std::printf("  (%zu samples without force have an infinite margin: not in its spread)\n",
                  r.peak_force_n.count - r.margin.count);
    if (r.failed > 0)
      std::printf("  %zu samples could not be evaluated (see --json rows)\n", r.failed);
    if (!r.sensitivity.empty()) {
      std::printf("\n  one at a time (5 %% -> 95 %% of each value, the others as written):\n");
      for (const auto& s : r.sensitivity) {
        if (!s.depth_effect_m) {
          const std::string& why = s.low.ok ? s.high.error : s.low.error;
          std::printf("  %-30s n/a: the %s run failed (%s)\n", s.path.c_str(),
                      s.low.ok ? "95 %" : "5 %", why.c_str());
          continue;
        }
        std::printf("  %-30s %s %-12s peak force %s\n", s.path.c_str(),
                    s.both_resolved ? "puncture depth moves" : "puncture objective moves*",
                    format_quantity(*s.depth_effect_m, Dimension::Length).c_str(),
                    format_quantity(*s.peak_effect_n, Dimension::Force).c_str());
      }
      bool starred = false;
      for (const auto& s : r.sensitivity)
        starred = starred || (s.depth_effect_m && !s.both_resolved);
      if (starred)
        std::printf(
            "  * an end that fires at the first step or does not puncture: the objective "
            "(docs/model.md, \"Optimisation\"), not a puncture depth\n");
    }
  }
  // After the result is out: a plot that cannot be written loses nothing.
  if (!args.plot.empty()) plot::write_svg(args.plot, distribution_figure(r, args.scene));
}

}  // namespace

void add_uncertainty_command(CLI::App& app) {
  auto args = std::make_shared<UncertaintyArgs>();
  auto* cmd = app.add_subcommand(
      "uncertainty", "Spread of puncture depth, forces and margin when scene values vary");
  cmd->footer(
      "Example:\n"
      "  mneedle uncertainty designs/scenes/paper_a_silicone_blunt_bevel.toml "
      "--vary 'silicone.E=lognormal(0.2MPa,20%)' "
      "--vary 'fracture.critical_pressure=uniform(0.5MPa,0.8MPa)' --samples 200 --seed 1");
  cmd->add_option("scene", args->scene, "Scene file (TOML); its first needle is evaluated")
      ->required();
  cmd->add_option("--vary", args->vary,
                  "PATH=normal(MEAN,SD|SD%) | lognormal(MEDIAN,CV%) | uniform(LOW,HIGH), "
                  "e.g. dermis.E=lognormal(80kPa,30%) (repeatable)")
      ->required()
      ->allow_extra_args(false);
  cmd->add_option("--samples", args->samples, "Number of samples")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--seed", args->seed, "Seed of the draws (same seed, same samples)")
      ->capture_default_str();
  cmd->add_option("--method", args->method, "mc (Monte Carlo) or lhs (Latin hypercube)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mc", "lhs"}));
  cmd->add_option("--jobs", args->jobs, "Samples evaluated at once (one OpenBLAS thread each)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--fidelity", args->fidelity, "fast, standard or fine")
      ->capture_default_str()
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_option("--model", args->model, "auto, analytic, axisymmetric or 3d (as screen)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "analytic", "axisymmetric", "3d"}));
  cmd->add_option("--material", args->material, "Needle material (default: the scene's)");
  cmd->add_flag("--no-sensitivity", args->no_sensitivity,
                "Skip the one-at-a-time runs (two per --vary)");
  cmd->add_option("--plugin-dir", args->plugin_dirs, "Extra plugin folder (repeatable)")
      ->allow_extra_args(false);
  cmd->add_flag("--json", args->json, "Print one JSON object (every sample in rows)");
  cmd->add_option("--plot", args->plot,
                  "Write the distribution of the puncture depth (or, if no sample punctures, of "
                  "the peak force) as SVG");
  cmd->add_flag("--mpi", args->mpi,
                "Share the runs among the processes of mpirun -n N (rank 0 prints; each rank "
                "runs --jobs threads)");
  cmd->callback([args] { run_uncertainty_command(*args); });
}

}  // namespace mneedle::cli
