// mneedle optimize: search a plugin's tip parameters (docs/model.md, "Optimisation"). Default
// objective: the puncture depth of the two-stage model at one fixed mesh setting for the whole run;
// or the peak force up to the target depth.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/simulation.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/units.h"
#include "mneedle/design_evaluation.h"
#include "mneedle/design_source.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/geometry/cross_section.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/optimum_report.h"
#include "mneedle/plugin_host.h"
#include "mneedle/screening.h"
#include "mneedle/strength/needle_material.h"
#include "mneedle/tip_optimizer.h"
#include "option_values.h"
#include "report_needles.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct OptimizeArgs {
  std::vector<std::string> plugin_dirs;
  std::string plugin;
  std::string scene;
  std::string vary;
  std::vector<std::string> settings;
  std::vector<std::string> bounds;
  std::string material;
  std::string objective = "puncture-depth";
  std::string fidelity = "fast";
  std::string model = "auto";
  std::string algorithm = "cobyla";
  std::string local = "bobyqa";
  int starts = 1;
  int max_evals = 60;
  std::string max_time;
  unsigned seed = 1;
  std::string min_feature = "5um";
  std::string out;
  std::string report;  // folder for result.json and report.html
  bool json = false;
};

constexpr const char* kConstraintNames[] = {"strength_constraint", "feature_constraint",
                                            "target_depth_constraint"};
constexpr int kConstraints = 3;

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, sep);)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

// A plugin parameter's SI value in its unit for a message: angles in degrees, lengths scaled.
std::string parameter_text(const std::string& unit, double value) {
  if (unit == "rad") return format_quantity(value, Dimension::Angle);
  if (unit == "m") return format_quantity(value, Dimension::Length);
  std::ostringstream out;
  out << value;
  return out.str();
}

// One end of a --bound, in the parameter's unit; errors name --bound, not --set.
double bound_value(const PluginShapeInfo& shape, const std::string& name, const std::string& text,
                   const char* end) {
  try {
    return parse_parameter_settings(shape, {name + "=" + text}).at(name);
  } catch (const InputError& e) {
    std::string why = e.what();
    const std::string prefix = "--set " + name + ": ";
    if (why.rfind(prefix, 0) == 0) why = why.substr(prefix.size());
    throw InputError("--bound " + name + " (" + end + "): " + why);
  }
}

// The plugin's bounds, narrowed by --bound name=lo:hi (values with units).
std::vector<DesignVariable> variables(const PluginShapeInfo& shape, const OptimizeArgs& a) {
  std::map<std::string, std::pair<std::string, std::string>> user;
  for (const auto& b : a.bounds) {
    const auto eq = b.find('='), colon = b.find(':');
    if (eq == std::string::npos || colon == std::string::npos || colon < eq)
      throw InputError("--bound '" + b + "': expected name=low:high, e.g. bevel_angle=10deg:45deg");
    // Once each: the last of two used to win in silence.
    if (!user.emplace(b.substr(0, eq),
                      std::pair{b.substr(eq + 1, colon - eq - 1), b.substr(colon + 1)})
             .second)
      throw InputError("--bound " + b.substr(0, eq) + ": given twice");
  }
  std::vector<DesignVariable> out;
  for (const auto& name : split(a.vary, ',')) {
    if (std::any_of(out.begin(), out.end(), [&](const auto& v) { return v.name == name; }))
      throw InputError("--vary: '" + name + "' given twice");
    const auto it = std::find_if(shape.parameters.begin(), shape.parameters.end(),
                                 [&](const PluginParameter& p) { return p.name == name; });
    if (it == shape.parameters.end())
      throw InputError("--vary: shape '" + shape.name + "' has no parameter '" + name + "'");
    DesignVariable v{name, it->min, it->max};
    if (const auto u = user.find(name); u != user.end()) {
      // Beyond the shape's own range there are no shapes: refused, not narrowed in silence.
      const double low = bound_value(shape, name, u->second.first, "low");
      const double high = bound_value(shape, name, u->second.second, "high");
      const std::string range = " (the shape's range is " + parameter_text(it->unit, it->min) +
                                " to " + parameter_text(it->unit, it->max) + ")";
      if (low < it->min)
        throw InputError("--bound " + name + ": low " + u->second.first +
                         " is below the shape's minimum" + range);
      if (high > it->max)
        throw InputError("--bound " + name + ": high " + u->second.second +
                         " is above the shape's maximum" + range);
      if (!(low < high))
        throw InputError("--bound " + name + ": low " + u->second.first + " must be below high " +
                         u->second.second);
      v.lower = low;
      v.upper = high;
    }
    out.push_back(v);
  }
  if (out.empty()) throw InputError("--vary: name at least one parameter, e.g. --vary bevel_angle");
  // A bound on a parameter that is not varied would be silently ignored.
  for (const auto& [name, range] : user)
    if (std::none_of(out.begin(), out.end(), [&](const auto& v) { return v.name == name; }))
      throw InputError("--bound '" + name + "': not one of the --vary parameters (" + a.vary + ")");
  return out;
}

// Where the search starts: a --set value of a varied parameter, else the plugin's default,
// inside the bounds (the middle of the bounds can be no valid shape at all, e.g. a bevel longer
// than the needle).
std::vector<double> start_values(const PluginShapeInfo& shape,
                                 const std::vector<DesignVariable>& vars,
                                 const std::map<std::string, double>& settings) {
  std::vector<double> start;
  for (const DesignVariable& v : vars) {
    const auto it = std::find_if(shape.parameters.begin(), shape.parameters.end(),
                                 [&](const PluginParameter& p) { return p.name == v.name; });
    const auto set = settings.find(v.name);
    const double value = set != settings.end() ? set->second : it->default_value;
    start.push_back(std::clamp(value, v.lower, v.upper));
  }
  return start;
}

struct Problem {
  const Scene& scene;
  const PluginRegistry& registry;
  const OptimizeArgs& args;
  std::map<std::string, double> fixed;
  std::string material;
  double min_feature = 5e-6;
  EvaluationOptions evaluation;

  NeedleSource needle(const std::map<std::string, double>& values) const {
    auto p = fixed;
    for (const auto& [k, v] : values) p[k] = v;
    return needle_from_plugin(registry, args.plugin, p);
  }

  // The optimiser's cache holds scores; this one keeps the evaluations so the best design's
  // report does not rerun its insertion.
  mutable std::map<std::map<std::string, double>, DesignEvaluation> evaluated;

  DesignEvaluation evaluate(const NeedleSource& n) const {
    if (const auto it = evaluated.find(n.params); it != evaluated.end()) return it->second;
    EvaluationOptions o = evaluation;
    o.symmetry = needle_symmetry(registry, n, "optimize: " + args.plugin);
    return evaluated[n.params] = evaluate_design(n.mesh, scene, material, o);
  }

  // The shaft's thinnest wall, sliced from the generated mesh at 50-90 % of its length (the tip
  // itself always thins to nothing): no parameter name is assumed, so any plugin works.
  double wall(const NeedleSource& n) const {
    const BoundingBox box = bounding_box(n.mesh);
    const double length = box.max[2] - box.min[2];
    const CrossSectionSlicer slicer(n.mesh);
    double thinnest = std::numeric_limits<double>::infinity();
    for (double fraction : {0.5, 0.7, 0.9})
      thinnest = std::min(thinnest, thinnest_wall(slicer.slice(fraction * length).polygons));
    return thinnest;
  }

  // Objective (m or N) and constraints, each satisfied when <= 0 and scaled to be O(1):
  // margin >= safety factor, wall >= minimum feature, puncture at or above the target depth.
  DesignScore score(const std::map<std::string, double>& values) const {
    NeedleSource n;
    try {
      n = needle(values);
    } catch (const InvalidShapeError& e) {
      throw InfeasibleDesign(e.what());  // a bevel longer than the needle is a design property
    }
    const DesignEvaluation e = evaluate(n);
    const double sf = e.safety_factor;
    const double margin = std::isfinite(e.margin) ? e.margin : 1e6;
    const double objective =
        args.objective == "peak-force" ? e.peak_force_n : e.puncture_objective_m;
    return DesignScore{objective,
                       {(sf - margin) / sf, (min_feature - wall(n)) / min_feature,
                        (e.puncture_objective_m - e.depth_m) / e.depth_m}};
  }
};

std::string objective_text(const std::string& objective, double value) {
  if (!std::isfinite(value)) return "none yet";
  return objective == "peak-force" ? "peak force " + format_quantity(value, Dimension::Force)
                                   : "puncture depth " + format_quantity(value, Dimension::Length);
}

// history.csv, one row per distinct design as soon as it is evaluated (flushed), so a killed run
// keeps every design it paid for; full precision, so the history compares with the summary. The
// first line is the run's provenance as a comment (docs/cli.md, "Provenance").
class HistoryWriter {
 public:
  HistoryWriter(const std::filesystem::path& file, const std::vector<DesignVariable>& vars,
                const std::string& objective_key)
      : file_(file), out_(file), vars_(vars) {
    if (!out_) throw InputError("--out: cannot write '" + file.string() + "'");
    out_ << provenance_comment() << "\n" << std::setprecision(17);
    for (const auto& v : vars_) out_ << v.name << "_SI,";
    out_ << objective_key;
    for (const char* c : kConstraintNames) out_ << "," << c;
    out_ << ",feasible,failed,impossible,start,seconds,error\n" << std::flush;
  }

  void write(const EvaluationRecord& e) {
    std::vector<double> numbers;
    std::vector<std::string> columns;
    for (const auto& v : vars_) {
      numbers.push_back(e.values.at(v.name));
      columns.push_back(v.name);
    }
    require_finite_row(numbers, columns, "history row", "optimize");
    for (double x : numbers) out_ << x << ",";
    // A failed or impossible point has no objective or constraint values: empty fields.
    const bool valued = !e.failed && !e.impossible;
    if (valued) out_ << e.objective;
    for (int i = 0; i < kConstraints; ++i) {
      out_ << ",";
      if (valued) out_ << e.constraints[i];
    }
    std::string error = e.error;
    std::replace(error.begin(), error.end(), '"', '\'');
    std::replace(error.begin(), error.end(), '\n', ' ');
    out_ << "," << e.feasible << "," << e.failed << "," << e.impossible << "," << e.start << ","
         << e.seconds << ",\"" << error << "\"\n"
         << std::flush;
    if (!out_) throw InputError("--out: writing '" + file_.string() + "' failed");
  }

 private:
  std::filesystem::path file_;
  std::ofstream out_;
  const std::vector<DesignVariable>& vars_;
};

void write_outputs(const std::filesystem::path& dir, const TriangleMesh& best_mesh,
                   const nlohmann::json& summary) {
  write_stl_binary(best_mesh, dir / "best.stl", 1e-3, "mneedle optimize best design unit=mm");
  require_finite_json(summary, "optimize");
  std::ofstream(dir / "summary.json") << with_provenance(summary).dump(2) << "\n";
}

// The optimum's place (bound, constraint, interior) and the failures, for JSON.
nlohmann::json optimum_json(const OptimumReport& report,
                            const std::vector<std::string>& shape_limit) {
  const auto names = [](const std::vector<int>& indices) {
    nlohmann::json list = nlohmann::json::array();
    for (int i : indices) list.push_back(kConstraintNames[i]);
    return list;
  };
  const auto causes = [](const std::vector<FailureCount>& counts) {
    nlohmann::json list = nlohmann::json::array();
    for (const FailureCount& f : counts) list.push_back({{"error", f.error}, {"count", f.count}});
    return list;
  };
  return {{"interior", report.interior()},
          {"on_lower_bound", report.on_lower_bound},
          {"on_upper_bound", report.on_upper_bound},
          {"on_shape_limit", shape_limit},
          {"active_constraints", names(report.active_constraints)},
          {"violated_constraints", names(report.violated_constraints)},
          {"failed_evaluations", report.failed},
          {"failures", causes(report.failures)},
          {"impossible_designs", report.impossible},
          {"impossible_causes", causes(report.impossible_causes)}};
}

// The bounds the optimum sits on that are the shape's own range (no --bound can widen them).
std::vector<std::string> on_shape_limit(const OptimumReport& report, const PluginShapeInfo& shape,
                                        const std::vector<DesignVariable>& vars) {
  std::vector<std::string> out;
  const auto limit = [&](const std::string& name, bool upper) {
    for (const DesignVariable& v : vars) {
      if (v.name != name) continue;
      for (const PluginParameter& p : shape.parameters)
        if (p.name == name && (upper ? v.upper == p.max : v.lower == p.min)) return true;
    }
    return false;
  };
  for (const auto& n : report.on_lower_bound)
    if (limit(n, false)) out.push_back(n);
  for (const auto& n : report.on_upper_bound)
    if (limit(n, true)) out.push_back(n);
  return out;
}

// One line: where the optimum is. A bound means the box stopped the search, not the physics; a
// shape's own limit cannot be widened. Points that made no valid shape are a boundary the
// search cannot see as a constraint: an "interior" optimum may lie on it.
std::string optimum_text(const OptimumReport& report, const std::vector<std::string>& shape_limit) {
  const auto own = [&](const std::string& n) {
    return std::find(shape_limit.begin(), shape_limit.end(), n) != shape_limit.end()
               ? " (the shape's own limit)"
               : "";
  };
  if (report.interior())
    return report.impossible > 0
               ? "interior among valid shapes (no bound and no constraint is active; " +
                     std::to_string(report.impossible) +
                     " points made no valid shape, so it may lie on the edge of what the shape "
                     "allows)"
               : "interior (no bound and no constraint is active)";
  std::vector<std::string> parts;
  for (const auto& n : report.on_lower_bound) parts.push_back("lower bound of " + n + own(n));
  for (const auto& n : report.on_upper_bound) parts.push_back("upper bound of " + n + own(n));
  const auto constraint = [](int i) {
    const std::string c = kConstraintNames[i];
    return c.substr(0, c.size() - std::string("_constraint").size()) + " constraint";
  };
  for (int i : report.active_constraints) parts.push_back(constraint(i));
  std::string text;
  for (std::size_t i = 0; i < parts.size(); ++i) text += (i ? ", the " : "on the ") + parts[i];
  for (std::size_t i = 0; i < report.violated_constraints.size(); ++i)
    text += (i              ? ", the "
             : text.empty() ? "beyond the "
                            : "; beyond the ") +
            constraint(report.violated_constraints[i]);
  if (report.on_lower_bound.size() + report.on_upper_bound.size() > shape_limit.size())
    text += " (widen --bound to search further)";
  return text;
}

// Each parameter's SI unit as the plugin declares it ("m", "rad", "1").
nlohmann::json parameter_units(const PluginShapeInfo& shape) {
  nlohmann::json units = nlohmann::json::object();
  for (const auto& p : shape.parameters) units[p.name] = p.unit;
  return units;
}

// The varied parameters and their bounds (SI), in the order of the search.
nlohmann::json variables_json(const std::vector<DesignVariable>& vars) {
  nlohmann::json list = nlohmann::json::array();
  for (const DesignVariable& v : vars)
    list.push_back({{"name", v.name}, {"lower", v.lower}, {"upper", v.upper}});
  return list;
}

// Every distinct design the search evaluated, in order (the JSON twin of history.csv; the report
// draws it). A failed or impossible point has no objective or constraints: null.
nlohmann::json history_json(const std::vector<EvaluationRecord>& history) {
  nlohmann::json rows = nlohmann::json::array();
  for (const EvaluationRecord& e : history) {
    const bool valued = !e.failed && !e.impossible;
    nlohmann::json constraints = nlohmann::json::object();
    for (int i = 0; i < kConstraints; ++i)
      constraints[kConstraintNames[i]] =
          valued && i < static_cast<int>(e.constraints.size()) && std::isfinite(e.constraints[i])
              ? nlohmann::json(e.constraints[i])
              : nlohmann::json(nullptr);
    rows.push_back({{"values", e.values},
                    {"objective", valued && std::isfinite(e.objective) ? nlohmann::json(e.objective)
                                                                       : nlohmann::json(nullptr)},
                    {"constraints", constraints},
                    {"feasible", e.feasible},
                    {"failed", e.failed},
                    {"impossible", e.impossible},
                    {"start", e.start},
                    {"seconds", e.seconds},
                    {"error", e.error}});
  }
  return rows;
}

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

// One element size at the tip for every design of the run, so that the tissue mesh does not jump
// between designs and the objective stays smooth: the 3-D size of the start design's radius. One
// case is left to the model's own rule: a pointed tip on the axisymmetric model under the stress
// criterion, which that model sizes from the criterion's length, not from the design
// (docs/model.md, "Mesh"); an imposed size would switch the rule off, and the start design would
// no longer puncture where `simulate` punctures it (the cone in skin read 56.4 against 62.8 um).
// Returns no size then, and for the analytic model, which has no mesh.
std::optional<double> fixed_tip_size(const Problem& p, const std::vector<DesignVariable>& vars,
                                     const std::vector<double>& start) {
  std::map<std::string, double> at_start;
  for (std::size_t i = 0; i < vars.size(); ++i) at_start[vars[i].name] = start[i];
  NeedleSource n;
  try {
    n = p.needle(at_start);
  } catch (const std::exception&) {
    n = p.needle({});  // the start is not a valid shape: the plugin's defaults are
  }
  const PreModel model = p.evaluation.model;
  if (model == PreModel::Analytic) return std::nullopt;
  const auto& layers = p.scene.tissue.layers;
  const double length = p.scene.model.criterion == PunctureCriterion::Stress && !layers.empty() &&
                                layers.front().strength
                            ? layers.front().strength->length
                            : 0.0;
  // The planner's rule (run_insertion): one needle of revolution on the block's axis runs
  // axisymmetric; a design is evaluated alone, in the place of the scene's first needle.
  const auto& at = p.scene.needles.front().at;
  const auto profile = needle_symmetry(p.registry, n, "optimize: " + p.args.plugin).axisymmetric;
  const bool axisymmetric =
      model == PreModel::Axisymmetric ||
      (model == PreModel::Auto && std::hypot(at[0], at[1]) < 1e-12 && profile.has_value());
  if (axisymmetric && length > 0.0 && profile &&
      profile->radii_m.front() <= 1e-9 * profile->max_radius())
    return std::nullopt;
  const double depth = p.scene.requirements.target_depth.value_or(p.scene.insertion.depth);
  const double block = std::max(p.scene.tissue.size[0], p.scene.tissue.size[1]);
  // The stress criterion's length caps the tip element as in every run (docs/model.md, "Tissue
  // block and mesh"); a scene without the criterion's data has none (it may have no puncture data
  // at all, and then runs without a criterion).
  return fe::mesh_sizing(p.evaluation.fidelity, 2, max_radius_up_to(n.mesh, depth), block, {},
                         length)
      .fine_size;
}

// "  3 of 20 evaluations failed: 2x "…"; 1x "…"": the commonest causes first, at most three.
void print_causes(int count, int evaluations, const char* what,
                  const std::vector<FailureCount>& causes) {
  if (count == 0) return;
  std::cout << "  " << count << " of " << evaluations << " evaluations " << what << ":";
  const std::size_t shown = std::min<std::size_t>(causes.size(), 3);
  for (std::size_t i = 0; i < shown; ++i)
    std::cout << (i ? ";" : "") << " " << causes[i].count << "x \"" << causes[i].error << "\"";
  if (causes.size() > shown) std::cout << "; " << causes.size() - shown << " other causes";
  std::cout << "\n";
}

void run_optimize(const OptimizeArgs& a) {
  const Scene scene = load_scene(a.scene);
  record_scene(scene, a.scene);
  const auto registry = PluginRegistry::discover({a.plugin_dirs.begin(), a.plugin_dirs.end()});
  const PluginShapeInfo& shape = registry.shape(a.plugin);
  Problem problem{scene,      registry,
                  a,          parse_parameter_settings(shape, a.settings),
                  a.material, option_quantity("--min-feature", a.min_feature, Dimension::Length),
                  {},         {}};
  const auto vars = variables(shape, a);
  if (!(problem.min_feature > 0.0))
    throw InputError("--min-feature: must be a positive length, got '" + a.min_feature + "'");
  if (problem.material.empty())
    for (const auto& n : scene.needles)
      if (n.material && problem.material.empty()) problem.material = *n.material;
  if (problem.material.empty()) problem.material = "silicon";
  // Checked once here: an unknown name would otherwise fail every evaluation of the search.
  try {
    find_needle_material(problem.material, scene_needle_materials(scene));
  } catch (const InputError& e) {
    throw InputError(std::string(a.material.empty() ? "optimize: the scene's needle material: "
                                                    : "optimize: --material: ") +
                     e.what());
  }
  problem.evaluation.fidelity = parse_fidelity(a.fidelity);
  problem.evaluation.model = parse_pre_model(a.model);
  const std::vector<double> start = start_values(shape, vars, problem.fixed);
  problem.evaluation.overrides.tip_size_m = fixed_tip_size(problem, vars, start);

  OptimizerOptions o;
  o.start = start;
  o.algorithm = a.algorithm;
  o.local_algorithm = a.local;
  o.starts = a.starts;
  if (a.max_evals < 1)
    throw InputError("--max-evals " + std::to_string(a.max_evals) + ": must be at least 1");
  o.max_evaluations = a.max_evals;
  o.seed = a.seed;
  // Recorded only when something random runs (docs/cli.md, "Provenance": null otherwise): the
  // scattered starts, ISRES and MLSL; a single local run from the start point draws nothing.
  const bool random = a.starts > 1 || a.algorithm == "isres" || a.algorithm == "mlsl";
  if (random) run_provenance().seed = a.seed;
  if (!a.max_time.empty()) {
    o.max_time_s = option_quantity("--max-time", a.max_time, Dimension::Time);
    if (!(o.max_time_s > 0.0))
      throw InputError("--max-time: must be a positive time, got '" + a.max_time + "'");
  }
  o.progress = [&](const OptimizerProgress& p) {
    std::fprintf(stderr, "optimize: %d evaluations, %.0f s, best %s (%s), start %d of %d\n",
                 p.evaluations, p.elapsed_s, objective_text(a.objective, p.best_objective).c_str(),
                 p.feasible ? "feasible" : "none feasible yet", p.start, p.starts);
  };
  const std::string objective_key =
      a.objective == "peak-force" ? "peak_force_N" : "puncture_depth_m";
  if (!a.report.empty()) create_output_folder(a.report, "--report");  // before the search
  std::unique_ptr<HistoryWriter> history;
  if (!a.out.empty()) {
    create_output_folder(a.out, "--out");
    append_provenance_line(a.out);
    history = std::make_unique<HistoryWriter>(std::filesystem::path(a.out) / "history.csv", vars,
                                              objective_key);
    o.on_evaluation = [&](const EvaluationRecord& e) { history->write(e); };
  }
  const OptimizerResult r = optimize_design(
      vars, [&](const auto& values) { return problem.score(values); }, kConstraints, o);
  if (r.best.empty()) {
    // Name the first failure: the same cause usually sinks them all.
    std::string first;
    for (const EvaluationRecord& e : r.history)
      if ((e.failed || e.impossible) && !e.error.empty()) {
        first = "; the first: " + e.error;
        break;
      }
    throw SolverError(
        "optimize: every evaluation failed (" + r.stop_reason + ")" + first +
        (history ? "; each is in " + (std::filesystem::path(a.out) / "history.csv").string()
                 : std::string()));
  }
  const OptimumReport report = describe_optimum(vars, r);

  const NeedleSource best = problem.needle(r.best);
  const DesignEvaluation e = problem.evaluate(best);
  // The small-strain top layer's warning of `simulate` and `screen`, at the best design (not on a
  // closed-form run, small strain whatever the layer; docs/validation.md, "Finite strain in a
  // stiff top layer").
  std::vector<std::string> warnings;
  const bool analytic =
      std::find(e.models_run.begin(), e.models_run.end(), "analytic") != e.models_run.end();
  if (e.puncture && !e.puncture->at_first_contact && !analytic)
    if (const auto w =
            small_strain_warning(scene, e.puncture->depth_m, "the best design before it punctures"))
      warnings.push_back(*w);
  for (const std::string& w : warnings) std::cerr << "mneedle: warning: " << w << "\n";
  nlohmann::json summary = {
      {"best",
       {{"params", best.params},
        {"puncture_depth_m", e.puncture ? nlohmann::json(e.puncture->depth_m) : nullptr},
        {"puncture_force_N", e.puncture ? nlohmann::json(e.puncture->force_N) : nullptr},
        {"target_depth_m", e.depth_m},
        {"reaches_target_depth", e.reaches_target},
        {"peak_force_N", e.peak_force_n},
        {"capacity_N", e.strength.capacity_n},
        {"margin", number_or_null(e.margin)},
        {"safety_factor", e.safety_factor},
        {"models_run", e.models_run},
        {"curve", curve_json(e.curve)},
        {"mesh_sha256", mesh_sha256(best.mesh)}}},
      {"plugin", a.plugin},
      {"parameter_units", parameter_units(shape)},
      {"variables", variables_json(vars)},
      {"objective", objective_key},
      {"evaluations", r.evaluations},
      {"feasible", r.feasible},
      {"algorithm", r.algorithm},
      {"local_algorithm", a.algorithm == "mlsl" ? nlohmann::json(a.local) : nullptr},
      {"starts", r.starts.size()},
      {"stop", to_string(r.stop)},
      {"stop_reason", r.stop_reason},
      {"seconds", r.seconds},
      {"fidelity", a.fidelity},
      {"tip_element_size_m", problem.evaluation.overrides.tip_size_m
                                 ? nlohmann::json(*problem.evaluation.overrides.tip_size_m)
                                 : nlohmann::json(nullptr)},
      {"material", problem.material},
      {"optimum", optimum_json(report, on_shape_limit(report, shape, vars))},
      {"history", history_json(r.history)},
      {"warnings", warnings}};
  if (!a.out.empty()) write_outputs(a.out, best.mesh, summary);
  // The report after what is printed: one that cannot be written loses none of it.
  if (a.json) {
    print_checked_json(std::cout, summary, "optimize");
    std::cout.flush();
    if (!a.report.empty()) write_report_folder(a.report, summary, a.plugin_dirs);
    return;
  }
  std::cout << (r.feasible ? "best design" : "INFEASIBLE: least-violated design") << " of "
            << r.evaluations << " evaluations in " << static_cast<int>(std::round(r.seconds))
            << " s (" << r.algorithm << "; " << r.stop_reason << ")\n";
  for (const auto& v : vars) {
    // The plugin declares each parameter's SI unit: "m", "rad" or "1".
    std::string unit = "1";
    for (const auto& p : shape.parameters)
      if (p.name == v.name) unit = p.unit;
    const double value = best.params.at(v.name);
    std::cout << "  " << v.name << " = "
              << (unit == "m"     ? format_quantity(value, Dimension::Length)
                  : unit == "rad" ? format_quantity(value, Dimension::Angle)
                                  : std::to_string(value))
              << "\n";
  }
  std::cout << "  puncture "
            << (e.puncture
                    ? "at " + format_quantity(e.puncture->depth_m, Dimension::Length) + " under " +
                          format_quantity(e.puncture->force_N, Dimension::Force) +
                          (e.puncture->at_first_contact
                               ? " (at first contact: the depth is the first step's, not "
                                 "resolved; docs/model.md, \"Criteria\")"
                               : "")
                    : "not reached before " + format_quantity(e.depth_m, Dimension::Length))
            << "\n  peak force " << format_quantity(e.peak_force_n, Dimension::Force)
            << ", strength margin " << e.margin << " (safety factor " << e.safety_factor << ")\n"
            << "  optimum " << optimum_text(report, on_shape_limit(report, shape, vars)) << "\n";
  // Why a design scores as it does (a puncture at first contact scores as none: docs/cli.md,
  // "Optimisation").
  for (const std::string& note : e.notes) std::cout << "  note: " << note << "\n";
  print_causes(report.failed, r.evaluations, "failed", report.failures);
  print_causes(report.impossible, r.evaluations, "were no valid shape (infeasible)",
               report.impossible_causes);
  std::cout.flush();
  if (!a.report.empty()) write_report_folder(a.report, summary, a.plugin_dirs);
}

}  // namespace

void add_optimize_command(CLI::App& app) {
  auto a = std::make_shared<OptimizeArgs>();
  auto* cmd = app.add_subcommand("optimize", "Search a tip shape's parameters with NLopt");
  cmd->footer(
      "Objective: the puncture depth (two-stage model, one tissue mesh for the whole run) or the\n"
      "peak force up to the target depth, subject to strength margin >= safety factor,\n"
      "wall >= --min-feature and puncture before the scene's target depth.\n"
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
  cmd->add_option("--objective", a->objective, "puncture-depth or peak-force")
      ->capture_default_str()
      ->check(CLI::IsMember({"puncture-depth", "peak-force"}));
  cmd->add_option("--fidelity", a->fidelity, "FE mesh level: fast, standard or fine")
      ->capture_default_str()
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_option("--model", a->model, "Pre-puncture model: auto, analytic, axisymmetric or 3d")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "analytic", "axisymmetric", "3d"}));
  cmd->add_option("--algorithm", a->algorithm,
                  "cobyla, bobyqa (in AUGLAG), isres (global) or mlsl (global, with --local)")
      ->capture_default_str()
      ->check(CLI::IsMember({"cobyla", "bobyqa", "isres", "mlsl"}));
  cmd->add_option("--local", a->local, "mlsl's local search: cobyla or bobyqa")
      ->capture_default_str()
      ->check(CLI::IsMember({"cobyla", "bobyqa"}));
  cmd->add_option("--starts", a->starts,
                  "cobyla/bobyqa: runs from the start point and scattered points, best kept")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--max-evals", a->max_evals, "Evaluation budget (distinct designs)")
      ->capture_default_str();
  cmd->add_option("--max-time", a->max_time, "Wall-time budget with a unit, e.g. 300s");
  cmd->add_option("--seed", a->seed, "Seed of the scattered starts, ISRES and MLSL")
      ->capture_default_str();
  cmd->add_option("--plugin-dir", a->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->add_option("--min-feature", a->min_feature, "Smallest manufacturable wall")
      ->capture_default_str();
  cmd->add_option("--out", a->out, "Folder for best.stl (mm), history.csv and summary.json");
  cmd->add_option("--report", a->report,
                  "Folder for result.json and report.html (history, curve, 3-D best design)");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_optimize(*a); });
}

}  // namespace mneedle::cli
