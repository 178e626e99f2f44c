#pragma once
// `simulate` as a library call: the settings a user gives (the CLI's options, the Python
// keywords) turned into run options, and a finished run turned into the JSON tree both print.
// One tree for both, so the CLI and Python give the same keys and the same numbers
// (docs/cli.md, "simulate"; docs/python.md).

#include <cstddef>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/insertion/insertion_run.h"
#include "mneedle/scene/scene.h"

namespace mneedle {

/// What may override the scene's own choices; an empty string keeps the scene's.
struct SimulateSettings {
  std::string fidelity;        // fast | standard | fine
  std::string contact;         // sticking | frictionless
  std::string criterion;       // pressure | energy | stress | penetration | cohesive
  std::string model = "auto";  // auto | analytic | axisymmetric | 3d
  std::string axis;            // the scene's STL needles' axis (parse_axis_choice)
  std::size_t max_needles = 16;
  bool no_reductions = false;
  /// Return what a stopped pre-puncture FE reached, with "stopped" set, instead of failing
  /// (InsertionRunOptions::keep_reached; docs/cli.md, "A run whose solver stops").
  bool keep_reached = false;
};

/// Checks every setting (one-line InputError naming it) and applies `axis` to the scene's mesh
/// file needles.
void apply_simulate_settings(Scene& scene, const SimulateSettings& settings);

/// The scene's run options with the settings applied (fields output is the caller's).
InsertionRunOptions simulate_run_options(const Scene& scene, const SimulateSettings& settings);

/// Where the run's criterion does not hold, one line each, naming the scene. Penetration
/// (docs/model.md, "Penetration criterion"): a top layer thinner than the needle's diameter (no
/// half-space), a layer so brittle against the needle that F_p is an upper bound. Energy
/// ("Crack faces in contact"): crack faces that passed through each other (their contact is not
/// modelled on that path). Stress: a probe that read nothing, flat ends without a contact zone.
/// Any criterion: a linear (small-strain) top layer at least kStiffTopLayerContrast times stiffer
/// than the layer beneath, pushed deeper than its own thickness before puncture
/// (docs/validation.md, "Finite strain in a stiff top layer"). The CLI prints them on stderr,
/// Python raises them as RuntimeWarnings.
std::vector<std::string> criterion_warnings(const InsertionRun& run, const Scene& scene);

/// The small-strain warning of criterion_warnings for a top layer pushed `pushed_m` deep before
/// puncture under `under` (e.g. "needle 'cone' before it punctures"), or nullopt when it does
/// not apply (the top layer not linear, not kStiffTopLayerContrast times stiffer than the next,
/// or not pushed past its thickness). `screen` gives it the deepest design's puncture.
std::optional<std::string> small_strain_warning(const Scene& scene, double pushed_m,
                                                const std::string& under);

/// E of the top layer over E of the one beneath from which a small-strain top layer pushed
/// beyond its thickness is warned about: a stiff film on a soft base, which bends and stretches
/// like a plate (the stratum corneum over the epidermis: 7463).
inline constexpr double kStiffTopLayerContrast = 10.0;

/// The run as `simulate --json` prints it (without provenance): needles with curves and
/// punctures, mesh, total curve, models, reductions, criterion, loads, energy check, memory and
/// time; each needle's mesh hash; `axis` when the settings gave one; `warnings`
/// (criterion_warnings). Checked finite (SolverError naming the first NaN or Inf).
nlohmann::json simulation_json(const InsertionRun& run, const Scene& scene,
                               const std::vector<PreparedNeedle>& needles,
                               const SimulateSettings& settings);

}  // namespace mneedle
