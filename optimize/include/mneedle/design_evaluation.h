#pragma once
// Everything mneedle can say about one needle design in one scene: its geometry, where it
// punctures the tissue and the force on it up to the target depth (the two-stage model of
// run_insertion), its strength and margin. Screening ranks these; the optimiser minimises over
// them.

#include <optional>
#include <string>
#include <vector>

#include "mneedle/design_source.h"
#include "mneedle/fe/axisymmetric.h"
#include "mneedle/fe/fidelity.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/insertion/surface_loads.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/scene/scene.h"
#include "mneedle/strength/needle_material.h"
#include "mneedle/strength/needle_strength.h"

namespace mneedle {

struct DesignGeometry {
  std::size_t triangles = 0;
  double volume_m3 = 0.0;
  double area_m2 = 0.0;
  double length_m = 0.0;
  double tip_length_m = 0.0;  // height where the section reaches its shaft value
  double alpha_area_m2 = 0.0;
  double beta_area_m2 = 0.0;
};

/// Where the puncture criterion fired (run_insertion's Puncture, criterion as text).
struct PunctureSummary {
  double depth_m = 0.0;
  double force_N = 0.0;       // pre-puncture force at that depth
  double post_force_N = 0.0;  // post-puncture model's force at that depth
  std::string criterion;      // pressure | energy | stress | penetration | cohesive
  /// The criterion fired at the first depth step (docs/model.md, "Criteria"): the depth is the
  /// step's, not the tissue's; ranked after every resolved puncture, never an objective.
  bool at_first_contact = false;
  /// Penetration criterion on a flat-ended needle (Puncture::flat_tip): the depth is a lower
  /// bound; ranked after every resolved puncture, before those at first contact.
  bool lower_bound = false;
};

/// One point of the two-stage force curve as screening and optimisation report it (the full
/// RunPoint stays inside run_insertion: a row keeps what a reader plots).
struct CurveSample {
  double depth_m = 0.0;
  double force_N = 0.0;
  Stage stage = Stage::Pre;
};

struct DesignEvaluation {
  DesignGeometry geometry;
  double depth_m = 0.0;            // target depth (requirements.target_depth, else insertion.depth)
  double force_at_depth_n = 0.0;   // two-stage curve at depth_m
  double peak_force_n = 0.0;       // largest force of the two-stage curve up to depth_m
  std::vector<CurveSample> curve;  // the two-stage curve up to depth_m, as run_insertion gave it
  std::optional<PunctureSummary> puncture;  // empty: no puncture up to depth_m
  /// The puncture depth, or, without a puncture, a value beyond depth_m that falls as the
  /// criterion comes closer to firing: depth_m (2 − r), r = max criterion value / threshold (< 1;
  /// r = 0 when the criterion's value is not on the curve). Continuous where the puncture
  /// reaches depth_m, so an optimiser can walk towards designs that puncture.
  double puncture_objective_m = 0.0;
  bool reaches_target = false;          // punctures at or above depth_m
  std::string fidelity;                 // fast | standard | fine
  std::vector<std::string> models_run;  // run_insertion's models, e.g. fe_3d, surface_loads
  std::vector<std::string> reductions;  // run_insertion's planner decisions (names)
  double insertion_seconds = 0.0;
  StrengthReport strength;
  std::string material;
  double margin = 0.0;  // capacity / peak force
  double safety_factor = 1.5;
  bool passes = false;             // reaches the target depth and margin >= safety factor
  std::vector<std::string> notes;  // why a design fails, what was not modelled
};

struct EvaluationOptions {
  std::optional<SectionProfile> section_hook;  // analytic sections (plugin); else sliced mesh
  fe::Fidelity fidelity = fe::Fidelity::Fast;
  PreModel model = PreModel::Auto;
  fe::FidelityOverrides overrides;  // e.g. one tip element size for a whole optimisation
  /// Bodies of revolution and mirror planes: needle_symmetry(), as simulate takes them.
  NeedleSymmetry symmetry;
};

/// Evaluates a validated mesh in the needle frame, placed where the scene's first needle is (the
/// block's centre when the scene has none). `needle_material` names a built-in material or one of
/// the scene's [[materials]]. Throws InputError for inconsistent input (a needle shorter than the
/// depth, an unknown material) and SolverError when the FE stage fails.
DesignEvaluation evaluate_design(const TriangleMesh& mesh, const Scene& scene,
                                 const std::string& needle_material,
                                 const EvaluationOptions& options = {});

/// The needle material a design is evaluated in: `chosen` (--material) if given, else the first
/// of the scene's needles that names one, else silicon.
std::string design_material(const Scene& scene, const std::optional<std::string>& chosen);

/// The scene's needle materials as NeedleMaterial values (fracture mode assumed for user ones).
std::vector<NeedleMaterial> scene_needle_materials(const Scene& scene);

/// Largest distance of the mesh from its axis (z) up to `height_m` above the tip (m).
double max_radius_up_to(const TriangleMesh& mesh, double height_m);

fe::Fidelity parse_fidelity(const std::string& text);  // fast | standard | fine, else InputError
PreModel parse_pre_model(const std::string& text);     // auto | analytic | axisymmetric | 3d
std::string to_string(PreModel model);

}  // namespace mneedle
