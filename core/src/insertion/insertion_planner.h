#pragma once
// PRIVATE to mneedle::core: the scene planner of run_insertion (docs/model.md, "Scene planner").
// From the scene's outputs, its needles' geometry and the run options it decides which pre-puncture
// model runs, on which (possibly reduced) domain, and records every decision as a Reduction.

#include <optional>
#include <string>
#include <vector>

#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/insertion/puncture.h"

namespace mneedle::detail {

enum class PreKind { None, Analytic, Axisymmetric, Full3d };

struct RunPlan {
  PreKind pre = PreKind::Full3d;
  std::optional<PunctureThreshold> threshold;  ///< none: the scene has no puncture data
  bool post_stage = true;                      ///< continue after puncture with surface loads
  bool half_model = false;                     ///< 3-D: mirror plane y = 0
  bool mirror_x = false;  ///< 3-D: mirror plane x = 0 (with half_model, a quarter model)
  std::vector<fe::TissueLayer> layers;       ///< after merging deep layers
  std::vector<fe::TissueLayer> full_layers;  ///< as the scene gives them
  double block_x_m = 0.0;
  double block_y_m = 0.0;
  double full_block_x_m = 0.0;  ///< as the scene gives it (block_x_m after a domain cut)
  double full_block_y_m = 0.0;
  double axisymmetric_radius_m = 0.0;
  double depth_m = 0.0;  ///< the requested insertion depth: where the curve ends
  /// Progress lines and VTU steps end with the first step at or beyond this depth when the run
  /// goes deeper than depth_m to decide where the ladder starts (docs/model.md, "Pre-puncture
  /// horizon"), as a run asked for that depth ends; 0: they end with the run.
  double shown_depth_m = 0.0;
  double horizon_m = 0.0;  ///< the pre-puncture model's depth (a rung of pre_puncture_horizon)
  /// The cohesive criterion's ring crack: its line's depth below the surface, and whether it
  /// ends at the top layer's bottom, so that its failing throughout is a puncture (run_pre sets
  /// both)
  double cohesive_depth_m = 0.0;
  bool cohesive_through_layer = false;
  int steps = 0;                 ///< pre-puncture depth steps over the horizon
  double needle_radius_m = 0.0;  ///< largest needle radius reaching the horizon
  std::string vtu_directory;
  std::string vtu_comment;  ///< the run's provenance, into every VTU file
  std::string inp_path;     ///< InsertionRunOptions::inp_path (3-D model only)
  double inp_depth_m = 0.0;
  std::vector<std::string> inp_comment;
  std::vector<Reduction> reductions;
  /// False for the reference runs that measure a reduction: no early stop at the crossing, but
  /// the criterion's data kept, so that the mesh is the one the run being checked had (the
  /// stress criterion's length sizes the axisymmetric tip).
  bool stop_at_crossing = true;
  /// Where every model run of this plan and its copies adds its time (the run's record).
  RunSeconds* seconds = nullptr;
};

/// Accuracy the reductions must keep, relative force change, per fidelity (fast 5 %, standard
/// 2 %, fine 1 %): the tests check each reduction against the full model at this level.
double reduction_tolerance(fe::Fidelity fidelity);

/// Depth below which layers no longer matter (m): kInfluenceDepths times (radius + depth).
double influence_depth(double needle_radius_m, double insertion_depth_m);

inline constexpr double kInfluenceDepths = 10.0;

/// Half-width of the block kept around the needles (m): kDomainReach times (radius + depth).
double domain_reach(double needle_radius_m, double insertion_depth_m);

inline constexpr double kDomainReach = 10.0;

/// The pre-puncture model is built for a depth that depends on neither the requested insertion
/// depth nor the outputs, so that the puncture is a property of the needle and the tissue
/// (docs/model.md, "Pre-puncture horizon"): rung k is kFirstHorizon * 2^k. run_insertion climbs
/// the rungs until the criterion fires or a rung covers the requested depth.
inline constexpr double kFirstHorizon = 100e-6;
double pre_puncture_horizon(int rung);
/// The first rung whose horizon reaches `depth_m`.
int rung_covering(double depth_m);

/// Scene layers as FE layers; InputError names file:line of a layer with invalid constants.
std::vector<fe::TissueLayer> fe_layers(const Scene& scene);

/// The plan for one rung: the pre-puncture model to `horizon_m`, the curve to the scene's depth.
RunPlan plan_insertion(const Scene& scene, const std::vector<PreparedNeedle>& needles,
                       const InsertionRunOptions& options, double horizon_m);

}  // namespace mneedle::detail
