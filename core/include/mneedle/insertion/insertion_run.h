#pragma once
// The full two-stage insertion of paper A (§2.2, §4): the pre-puncture finite element stage until
// the scene's puncture criterion fires, then the post-puncture distributed-load model for the rest
// of the depth. A scene planner decides which models run (no FE when only post-puncture forces are
// asked for, axisymmetric or half models where the geometry allows, FE only up to puncture when
// only the puncture is asked for) and reports what it decided. SI units throughout.

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mneedle/fe/axisymmetric.h"
#include "mneedle/fe/fidelity.h"
#include "mneedle/fe/indentation3d.h"
#include "mneedle/insertion/energy_check.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/scene/scene.h"

namespace mneedle {

/// A needle ready to simulate: its validated mesh in the needle frame (tip at the origin, body
/// along +z, metres) and, when it is a body of revolution, its axisymmetric profile.
struct PreparedNeedle {
  std::string name;
  TriangleMesh mesh;
  double x = 0.0;  ///< m, tip position on the surface (scene frame)
  double y = 0.0;
  std::optional<fe::AxisymmetricNeedle> axisymmetric;  ///< set for cylinder/cone shapes
  bool mirror_symmetric_y0 = false;  ///< mesh symmetric about its y = 0 plane (bevels)
  bool mirror_symmetric_x0 = false;  ///< mesh symmetric about its x = 0 plane (cones)
  std::string frame_note;  ///< mesh files: how the axis, tip and a holder were found (or empty)
};

/// Which model computes the pre-puncture stage.
enum class PreModel { Auto, Analytic, Axisymmetric, Full3d };

struct InsertionRunOptions {
  fe::Fidelity fidelity = fe::Fidelity::Standard;
  fe::FidelityOverrides overrides;
  Contact contact = Contact::Sticking;
  PunctureCriterion criterion = PunctureCriterion::Pressure;
  /// The energy criterion's crack faces in contact: run_insertion sets it from the scene's
  /// [model] crack_faces, so every command runs the scene's choice.
  bool crack_face_contact = true;
  PreModel model = PreModel::Auto;
  bool allow_reductions = true;  ///< half models, layer merging
  /// The 3-D model's ladder starts one rung below the closed form's crossing (docs/model.md,
  /// "Pre-puncture horizon"); false climbs it from rung 0 (to check that the skipped rungs would
  /// not have fired).
  bool start_from_closed_form = true;
  /// When the pre-puncture FE stops (a SolverError: Newton, an inverted element, the crack's
  /// faces) after at least one depth step, return what it reached, with InsertionRun::stopped
  /// set, instead of throwing (docs/cli.md, "simulate"). False for every command that ranks or
  /// optimises: a run that stopped is not a result to rank. Running out of memory always throws.
  bool keep_reached = false;
  /// Largest relative force change a measured reduction may cause; empty: from the fidelity
  /// (fast 5 %, standard 2 %, fine 1 %).
  std::optional<double> reduction_tolerance;
  int steps = 0;  ///< output depth steps; 0: from the fidelity
  /// The cohesive criterion's ring cells (m); empty: from its law and the fidelity (docs/model.md,
  /// "The cohesive criterion"). For convergence studies and tests; `tip_size_m` does not set them.
  std::optional<double> cohesive_cell_m;
  /// Work limit checked before any FE is built: more needles in one FE model than this is an
  /// InputError (a 10 x 10 array needs GBs of memory and tens of minutes at fast).
  std::size_t max_fe_needles = 16;
  std::string vtu_directory;  ///< fields per step when set (or when the scene asks for them)
  std::string vtu_comment;    ///< written into every VTU file and the .pvd (provenance)
  /// When set (3-D model, linear layers, sticking contact), the problem of the last FE step not
  /// deeper than inp_depth_m is written there as a CalculiX/Abaqus deck (docs/cli.md,
  /// "mneedle export"); InsertionRun::exported says what was written.
  std::string inp_path;
  double inp_depth_m = 0.0;
  std::vector<std::string> inp_comment;
  /// Called after every step of a pre-puncture FE model, the reference runs that check a
  /// reduction included (each starts again at step 1); not by the closed form, which takes
  /// milliseconds. Gives the model's name
  /// ("fe_3d", "fe_axisymmetric"), the step and the number planned, its depth and the total
  /// force on the needles.
  std::function<void(const std::string& model, int step, int steps, double depth_m, double force_N)>
      on_progress;
};

enum class Stage { Pre, Post };
std::string_view to_string(Stage s);  ///< "pre", "post"

struct RunPoint {
  double depth_m = 0.0;
  double force_N = 0.0;
  Stage stage = Stage::Pre;
  // Pre-puncture (FE or analytic) quantities; zero after puncture.
  double lateral_force_N[2] = {0.0, 0.0};
  double contact_area_m2 = 0.0;      ///< FE: captured surface projected on z = 0 (mesh-bound)
  double contact_pressure_Pa = 0.0;  ///< force_N / contact_area_m2
  /// Area inside the needle's outer outline at the undeformed surface (the section at the
  /// tip's travel below z = 0, bores filled) and force_N over it: the pressure criterion's
  /// quantity, independent of the mesh (docs/model.md, "Criteria").
  double section_area_m2 = 0.0;
  double section_pressure_Pa = 0.0;
  double strain_energy_J = 0.0;
  /// Criterion quantities, computed only for the criterion in use (else 0).
  double tip_stress_Pa = 0.0;                 ///< stress: averaged max principal stress
  double energy_release_rate_J_per_m2 = 0.0;  ///< energy: G of the crack under the tip
  /// energy: how far one crack face has passed through the other (m; 0 while the faces are in
  /// contact, docs/model.md "Crack faces in contact")
  double crack_face_overlap_m = 0.0;
  /// penetration: F_p of the section at the surface (docs/model.md, "Penetration criterion")
  double penetration_force_N = 0.0;
  /// cohesive (docs/model.md, "The cohesive criterion"): the ring crack's failed depth, the lower
  /// end of its damaged cells (m below the surface), the cells of its process zone and the
  /// energy its law has dissipated (J)
  double cohesive_crack_m = 0.0;
  double cohesive_zone_m = 0.0;
  int process_zone_cells = 0;
  double fracture_energy_J = 0.0;
  double cohesive_failed_fraction = 0.0;  ///< share of the ring's face area failed (0..1)
  // Post-puncture split (paper A eqs. 18-20, friction); zero before puncture.
  double alpha_N = 0.0;
  double beta_N = 0.0;
  double friction_N = 0.0;
  /// The broken top layer's share while it still grips the shaft (docs/model.md, "The broken top
  /// layer"); alpha_N, beta_N and friction_N are then the layers' below it. force_N is the sum of
  /// the four.
  double collar_N = 0.0;
};

struct Puncture {
  double depth_m = 0.0;       ///< located between steps (interpolated, bisected or a force's peak)
  double force_N = 0.0;       ///< pre-puncture force at that depth
  double post_force_N = 0.0;  ///< post-puncture model's force at that depth
  PunctureCriterion criterion = PunctureCriterion::Pressure;
  /// The criterion was already above its threshold at the first depth step: it fires on
  /// contact for this tip and tissue (a pressure singular at the tip), so the depth reflects
  /// the step, not the tissue. Never rank or optimise on such a depth.
  bool at_first_contact = false;
  /// Penetration criterion only: the needle ends in a flat (its outline 1 nm above the tip is a
  /// circle of radius above 0.5 um). F_p is the sharp tip's mode-I force; a flat end needs a
  /// ring crack at a higher force, so this depth is a lower bound (docs/model.md, "Penetration
  /// criterion").
  bool flat_tip = false;
};

struct NeedleRun {
  std::string name;
  std::vector<RunPoint> curve;
  std::optional<Puncture> puncture;  ///< empty: it never punctures within the insertion depth
  double max_force_N = 0.0;
};

/// One decision of the planner and, where it was measured, what it changes.
struct Reduction {
  std::string name;    ///< "axisymmetric", "half_model", "domain_cut", "layer_merge", ...
  std::string detail;  ///< human-readable: what was cut and why
  std::optional<double> measured_effect;  ///< relative change of the force it was checked on
};

/// Where a run's wall time went (s), summed over every model it ran: each rung of the horizon
/// ladder and the planner's checks (docs/cli.md, "simulate --json"). The 3-D phases are those of
/// fe::Timing3d; what is left of `seconds` is the planner, the needles and the post-puncture
/// stage.
struct RunSeconds {
  double fe_3d_s = 0.0;            ///< 3-D FE runs, whole
  double axisymmetric_fe_s = 0.0;  ///< axisymmetric FE runs, the planner's proxies included
  double meshing_s = 0.0;          ///< of the 3-D runs: the tissue mesh
  double assembly_s = 0.0;         ///< of the 3-D runs: stiffness assembly
  double factorization_s = 0.0;    ///< of the 3-D runs: ordering and Cholesky factorisation
  double contact_s = 0.0;          ///< of the 3-D runs: capture, compliance columns, contact
  double stress_s = 0.0;           ///< of the 3-D runs: the stress criterion's probe
  int factorizations = 0;          ///< of the 3-D runs
  int shifted_factorizations = 0;  ///< of the 3-D runs: past a bifurcation (docs/model.md)
  int fe_runs = 0;                 ///< FE runs (3-D and axisymmetric) started
};

/// Where and why a pre-puncture FE run stopped before its last depth step
/// (InsertionRunOptions::keep_reached).
struct RunStop {
  double depth_m = 0.0;  ///< its deepest depth step, the curves' last point
  std::string reason;    ///< the solver's message, naming the depth it could not reach
};

struct InsertionRun {
  std::vector<NeedleRun> needles;
  std::vector<RunPoint> total_curve;    ///< sum over the needles (stage of the first needle)
  std::vector<std::string> models_run;  ///< "analytic", "axisymmetric_fe", "fe_3d", "surface_loads"
  std::vector<Reduction> reductions;
  fe::Fidelity fidelity = fe::Fidelity::Standard;
  /// The criterion evaluated; empty when the scene has no puncture data (pre-puncture stage only)
  /// or no pre-puncture model ran.
  std::optional<PunctureCriterion> criterion;
  std::optional<double> threshold;  ///< the criterion's threshold (Pa or J/m^2)
  /// energy criterion: depth of the crack G is computed with; cohesive: of the ring crack's line
  double crack_depth_m = 0.0;
  /// Depth the pre-puncture model was built for (docs/model.md, "Pre-puncture horizon"): a rung
  /// of 100 um x 2^k, the first whose run fired the criterion or covered the requested depth (for
  /// the cohesive criterion: a step beyond it, inside the block).
  double horizon_m = 0.0;
  double first_step_m = 0.0;  ///< the pre-puncture model's depth step on that rung
  /// Every rung's horizon that ran, in order (docs/model.md, "Pre-puncture horizon"): from rung 0
  /// up; for the 3-D model from the rung covering the closed form's crossing over its margin (and
  /// from rung 0 again when that start fired within the rung below it); without a criterion, the
  /// rung covering the requested depth alone.
  std::vector<double> rungs_m;
  // Mesh summary of the FE stage (zeros when none ran).
  int nodes = 0;
  int elements = 0;
  int order = 0;
  bool axisymmetric = false;
  double min_dihedral_deg = 0.0;  ///< 3-D mesh quality (0 for the axisymmetric model)
  double max_aspect_ratio = 0.0;
  /// m; the 3-D mesh's contact zone (0: none), and the flat first contacts whose stress
  /// criterion asked for one and did not get it (docs/model.md, "Tissue block and mesh").
  double contact_zone_m = 0.0;
  int unresolved_flats = 0;
  double seconds = 0.0;
  /// Stored energy against the needle's work over the pre-puncture curve (empty for analytic
  /// runs); docs/model.md, "Energy check".
  std::optional<EnergyCheck> energy_check;
  RunSeconds seconds_by_stage;
  /// The process's peak resident memory at the end of the run (bytes; 0 where not measurable).
  std::size_t peak_memory_bytes = 0;
  /// What InsertionRunOptions::inp_path received (3-D model only).
  std::optional<fe::InpExport> exported;
  /// Set when the pre-puncture FE stopped and keep_reached asked for what it reached: the curves
  /// end at stopped->depth_m, a puncture before it is one, and none means none before it. The
  /// mesh summary and the phase timings are those of the run that stopped.
  std::optional<RunStop> stopped;
};

/// The scene's [model] choices as run options: fidelity, contact and criterion (every other
/// option at its default). Commands start from this and apply their command line on top.
InsertionRunOptions scene_run_options(const Scene& scene);

/// Whether a top layer broken by `criterion` keeps its grip on the shaft after the puncture
/// (docs/model.md, "The broken top layer"): the stress criterion, two layers or more, the top
/// one stiffer than the next (`layer_moduli_Pa`: each layer's E, top first). `simulate` then
/// continues the pre-puncture curve; `force`, which runs no pre-puncture model, says that its
/// loads leave the grip out.
bool top_layer_grips(PunctureCriterion criterion, const std::vector<double>& layer_moduli_Pa);

/// Runs the scene's insertion for the prepared needles (one per scene needle, same order).
/// Throws InputError for a scene that cannot be run as asked and SolverError (naming the depth)
/// when the FE stage fails.
InsertionRun run_insertion(const Scene& scene, const std::vector<PreparedNeedle>& needles,
                           const InsertionRunOptions& options = {});

/// What enters the tissue fits in the block and no two needles share tissue: InputError naming
/// the scene line and the needle otherwise (a mesh read in the wrong unit, a copied `at`). Every
/// command that puts the scene's needles in the block calls it.
void check_needle_placement(const Scene& scene, const std::vector<PreparedNeedle>& needles);

}  // namespace mneedle
