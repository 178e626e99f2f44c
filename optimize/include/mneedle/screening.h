#pragma once
// Batch screening of needle designs: collect designs from files, folders and design lists,
// evaluate them in parallel, write each result the moment it is done, resume a killed run.

#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/design_evaluation.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "mneedle/uncertainty.h"

namespace mneedle {

/// One design to screen: a mesh file, or a plugin shape with parameters (a design-list entry).
struct DesignInput {
  std::string name;
  std::filesystem::path file;                  // mesh file, or the design list it came from
  double metres_per_unit = 1e-3;               // mesh files only
  std::optional<std::string> plugin;           // design-list entries only
  std::map<std::string, Quantity> parameters;  // design-list entries only, as written
};

/// Mesh files (STL, OBJ, PLY, OFF) as given, every mesh file of a folder (sorted, not recursive)
/// and every [[designs]] entry of a TOML design list. InputError for a path that does not exist,
/// a design list with an error (naming file:line) or inputs that hold no design (naming them).
std::vector<DesignInput> collect_designs(const std::vector<std::filesystem::path>& inputs,
                                         double metres_per_unit);

struct ScreeningOptions {
  int jobs = 1;
  std::optional<std::string> material;       // overrides the scene's needle material
  std::optional<std::filesystem::path> out;  // folder for results.csv and results.jsonl
  bool resume = false;                       // skip designs already in out/results.jsonl
  std::string fidelity = "fast";  // fast | standard | fine: the FE stage of run_insertion
  std::string model = "auto";     // auto | analytic | axisymmetric | 3d
  std::string axis = "auto";      // mesh files: auto | x | y | z | a,b,c (parse_axis_choice)
  bool repair = false;            // mesh files: repair_mesh before validation
  /// screen --uncertainty (docs/cli.md): with `vary` given, every design is also run in
  /// uncertainty.samples scenes with those values drawn — the same draws for every design, so
  /// that designs differ by their geometry, not by their luck — and ranked by its probability of
  /// passing. uncertainty.jobs is ignored (the designs share the jobs).
  std::vector<VariedValue> vary;
  UncertaintyOptions uncertainty;
};

/// The checks of a screen before any design runs (InputError): the scene's own needles built and
/// placed as `scene check` does, and `options.material` a known needle material.
void check_screening_scene(const Scene& scene, const PluginRegistry& registry,
                           const ScreeningOptions& options);

/// A two-stage curve as screening rows and optimize's summary write it: [{depth_m, force_N,
/// stage}], SI, stage "pre" or "post".
nlohmann::json curve_json(const std::vector<CurveSample>& curve);

/// One row of a screening: an evaluation or the reason there is none. `json` is the row as
/// written to results.jsonl (with units in its keys), which is what --resume reads back.
struct ScreeningRow {
  std::string design;
  std::string hash;  // of the design's bytes, the scene's bytes, fidelity and material
  bool ok = false;
  bool resumed = false;
  /// Failed for want of memory, not for the design: --resume evaluates it again (a design that
  /// fails for itself, such as an open mesh, keeps its row).
  bool retry = false;
  std::string error;
  std::string json;
  std::optional<double> puncture_depth_m;  // empty: no puncture up to the target depth
  double puncture_force_n = 0.0;
  bool puncture_at_first_contact = false;  // the depth is unresolved: ranked after the others
  bool puncture_lower_bound = false;       // the depth is a lower bound: ranked after resolved ones
  double peak_force_n = 0.0;
  double margin = 0.0;
  bool passes = false;
  std::string frame_note;  // mesh files: how the axis, tip and a holder were found (or empty)
  std::optional<double> pass_probability;  // screen --uncertainty: share of samples that pass
  std::optional<double> median_puncture_depth_m;  // screen --uncertainty: of resolved punctures
};

/// Screens `designs` on `scene` (its file is `scene_file`, for the hash). Every design gets a row,
/// in input order; a design that fails gets an error row and the others go on. When `out` is
/// set, each row is appended to out/results.jsonl and out/results.csv as soon as it is finished.
/// `on_row` (optional) is called for each finished row, serialised.
std::vector<ScreeningRow> screen_designs(
    const std::vector<DesignInput>& designs, const Scene& scene,
    const std::filesystem::path& scene_file, const PluginRegistry& registry,
    const ScreeningOptions& options, const std::function<void(const ScreeningRow&)>& on_row = {});

/// Sorted for the table: successful rows first; with --uncertainty by probability of passing
/// (highest first), then median puncture depth; else (and between equal probabilities) designs
/// that puncture by puncture depth, then puncture force; designs that never puncture after them
/// (by peak force); error rows last in input order. Pass/fail does not reorder: it is a column.
std::vector<ScreeningRow> rank_rows(std::vector<ScreeningRow> rows);

}  // namespace mneedle
