// mneedle optimize: search a plugin's tip parameters (issue 6 §2). The objective is the peak
// post-puncture force up to the target depth; the puncture-depth objective comes with the
// puncture model.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "mneedle/design_evaluation.h"
#include "mneedle/design_source.h"
#include "mneedle/error.h"
#include "mneedle/mesh_io.h"
#include "mneedle/tip_optimizer.h"
#include "mneedle/units.h"

namespace mneedle::cli {
namespace {

struct OptimizeArgs {
  std::string plugin;
  std::string scene;
  std::string vary;
  std::vector<std::string> settings;
  std::vector<std::string> bounds;
  std::string material;
  std::string algorithm = "cobyla";
  int max_evals = 60;
  unsigned seed = 1;
  std::string min_feature = "5um";
  std::string out;
  bool json = false;
};

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, sep);)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

// The plugin's bounds, narrowed by --bound name=lo:hi (values with units).
std::vector<DesignVariable> variables(const PluginShapeInfo& shape, const OptimizeArgs& a) {
  std::map<std::string, std::pair<std::string, std::string>> user;
  for (const auto& b : a.bounds) {
    const auto eq = b.find('='), colon = b.find(':');
    if (eq == std::string::npos || colon == std::string::npos || colon < eq)
      throw InputError("--bound '" + b + "': expected name=low:high, e.g. bevel_angle=10deg:45deg");
    user[b.substr(0, eq)] = {b.substr(eq + 1, colon - eq - 1), b.substr(colon + 1)};
  }
  std::vector<DesignVariable> out;
  for (const auto& name : split(a.vary, ',')) {
    const auto it = std::find_if(shape.parameters.begin(), shape.parameters.end(),
                                 [&](const PluginParameter& p) { return p.name == name; });
    if (it == shape.parameters.end())
      throw InputError("--vary: shape '" + shape.name + "' has no parameter '" + name + "'");
    DesignVariable v{name, it->min, it->max};
    if (const auto u = user.find(name); u != user.end()) {
      const auto lo = parse_parameter_settings(shape, {name + "=" + u->second.first}).at(name);
      const auto hi = parse_parameter_settings(shape, {name + "=" + u->second.second}).at(name);
      v.lower = std::max(v.lower, lo);
      v.upper = std::min(v.upper, hi);
    }
    out.push_back(v);
  }
  if (out.empty()) throw InputError("--vary: name at least one parameter, e.g. --vary bevel_angle");
  return out;
}

void write_outputs(const std::filesystem::path& dir, const OptimizerResult& r,
                   const std::vector<DesignVariable>& vars, const TriangleMesh& best_mesh,
                   const nlohmann::json& summary) {
  std::filesystem::create_directories(dir);
  write_stl_binary(best_mesh, dir / "best.stl", 1e-3, "mneedle optimize best design (mm)");
  std::ofstream csv(dir / "history.csv");
  for (const auto& v : vars) csv << v.name << "_SI,";
  csv << "peak_force_N,strength_constraint,feature_constraint,feasible,failed,seconds,error\n";
  for (const auto& e : r.history) {
    for (const auto& v : vars) csv << e.values.at(v.name) << ",";
    csv << (e.failed ? "" : std::to_string(e.objective)) << ","
        << (e.failed ? "" : std::to_string(e.constraints[0])) << ","
        << (e.failed ? "" : std::to_string(e.constraints[1])) << "," << e.feasible << ","
        << e.failed << "," << e.seconds << ",\"" << e.error << "\"\n";
  }
  std::ofstream(dir / "summary.json") << summary.dump(2) << "\n";
}

void run_optimize(const OptimizeArgs& a) {
  const Scene scene = load_scene(a.scene);
  const auto registry = PluginRegistry::discover();
  const PluginShapeInfo& shape = registry.shape(a.plugin);
  const auto fixed = parse_parameter_settings(shape, a.settings);
  const auto vars = variables(shape, a);
  const double min_feature = parse_quantity(a.min_feature, Dimension::Length);
  if (!(min_feature > 0.0))
    throw InputError("--min-feature: must be a positive length, got '" + a.min_feature + "'");
  std::string material = a.material;
  if (material.empty())
    for (const auto& n : scene.needles)
      if (n.material && material.empty()) material = *n.material;
  if (material.empty()) material = "silicon";

  auto params_of = [&](const std::map<std::string, double>& values) {
    auto p = fixed;
    for (const auto& [k, v] : values) p[k] = v;
    return p;
  };
  // Objective: peak force (N); constraints: margin ≥ safety factor, wall ≥ minimum feature.
  const DesignFunction f = [&](const std::map<std::string, double>& values) {
    const NeedleSource needle = needle_from_plugin(registry, a.plugin, params_of(values));
    const DesignEvaluation e = evaluate_design(needle.mesh, scene, material);
    const double sf = e.safety_factor;
    const double margin = std::isfinite(e.margin) ? e.margin : 1e6;
    const double bore = needle.params.count("bore") ? needle.params.at("bore") : 0.0;
    const double wall =
        bore > 0 ? (needle.params.at("diameter") - bore) / 2.0 : needle.params.at("diameter") / 2.0;
    return DesignScore{e.peak_force_n, {(sf - margin) / sf, (min_feature - wall) / min_feature}};
  };
  OptimizerOptions o;
  o.algorithm = a.algorithm;
  o.max_evaluations = a.max_evals;
  o.seed = a.seed;
  o.progress = [&](int n, double best) {
    if (!a.json && n % 10 == 0)
      std::cerr << "evaluation " << n << ": best feasible peak force "
                << (std::isfinite(best) ? format_quantity(best, Dimension::Force) : "none yet")
                << "\n";
  };
  const OptimizerResult r = optimize_design(vars, f, 2, o);
  if (r.best.empty())
    throw SolverError("optimize: every evaluation failed (" + r.stop_reason + ")");

  const NeedleSource best = needle_from_plugin(registry, a.plugin, params_of(r.best));
  const DesignEvaluation e = evaluate_design(best.mesh, scene, material);
  nlohmann::json summary = {
      {"best",
       {{"params", best.params},
        {"puncture_depth_m", nullptr},
        {"peak_force_N", e.peak_force_n},
        {"margin", std::isfinite(e.margin) ? nlohmann::json(e.margin) : nlohmann::json(nullptr)}}},
      {"objective", "peak_force_N"},
      {"evaluations", r.evaluations},
      {"feasible", r.feasible},
      {"algorithm", r.algorithm},
      {"stop_reason", r.stop_reason},
      {"material", material}};
  if (!a.out.empty()) write_outputs(a.out, r, vars, best.mesh, summary);
  if (a.json) {
    std::cout << summary.dump(2) << "\n";
    return;
  }
  std::cout << (r.feasible ? "best design" : "INFEASIBLE: least-violated design") << " of "
            << r.evaluations << " evaluations (" << r.algorithm << ", " << r.stop_reason << ")\n";
  for (const auto& v : vars)
    std::cout << "  " << v.name << " = " << best.params.at(v.name) << " (SI)\n";
  std::cout << "  peak post-puncture force " << format_quantity(e.peak_force_n, Dimension::Force)
            << ", strength margin " << e.margin << " (safety factor " << e.safety_factor << ")\n";
}

}  // namespace

void add_optimize_command(CLI::App& app) {
  auto a = std::make_shared<OptimizeArgs>();
  auto* cmd = app.add_subcommand("optimize", "Search a tip shape's parameters with NLopt");
  cmd->footer(
      "Objective: the peak post-puncture force up to the scene's target depth, subject to\n"
      "strength margin >= safety factor and wall >= --min-feature.\n"
      "Example:\n  mneedle optimize --plugin sharp_bevel --scene designs/scenes/human_skin.toml "
      "\\\n"
      "    --vary bevel_angle,diameter --bound diameter=150um:300um --material silicon --out opt");
  cmd->add_option("--plugin", a->plugin, "Tip-shape plugin")->required();
  cmd->add_option("--scene", a->scene, "Scene file (TOML)")->required();
  cmd->add_option("--vary", a->vary, "Parameters to vary, comma-separated")->required();
  cmd->add_option("--set", a->settings, "Fixed parameter, key=value with unit (repeatable)");
  cmd->add_option("--bound", a->bounds, "Narrower bounds, name=low:high with units (repeatable)");
  cmd->add_option("--material", a->material,
                  "Needle material (default: the scene's, else silicon)");
  cmd->add_option("--algorithm", a->algorithm, "cobyla, bobyqa (in AUGLAG) or isres")
      ->capture_default_str();
  cmd->add_option("--max-evals", a->max_evals, "Evaluation budget")->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed for the global algorithm")->capture_default_str();
  cmd->add_option("--min-feature", a->min_feature, "Smallest manufacturable wall")
      ->capture_default_str();
  cmd->add_option("--out", a->out, "Folder for best.stl (mm), history.csv and summary.json");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_optimize(*a); });
}

}  // namespace mneedle::cli
