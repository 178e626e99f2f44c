#pragma once
// Plane-strain insertion of a rigid needle along a cut through a block (paper C §6: Oldfield,
// Dini, Giordano, Rodriguez y Baena, CMBBE 16(5):530-543, 2013): the needle is a strip of width
// w with a wedge tip and a rounded shoulder, pushed down along the block's mid-plane, where the
// block is either already cut (paper C's run "with no cohesion") or held together by paper C's
// cohesive interface, which fails ahead of the needle. The tip's flank is frictionless, the
// shaft holds the cut faces with Coulomb friction, and friction grows along the shoulder's arc
// between the two. The run records, step by step, the insertion force and the energy ledger:
// external work, strain energy, friction dissipation, cohesive work
// (docs/model.md, "Plane-strain insertion along a cut").
// Half model x >= 0 (the cut on x = 0, the needle's axis), y up, top surface y = 0, bottom
// y = -depth on rollers (u_y = 0), side x = width/2 pinned. Small-strain linear elasticity, the
// bilinear rectangles of the plane-strain crack model. SI units; forces and energies are for
// the whole block (both halves, times the out-of-plane thickness).

#include <vector>

#include "mneedle/fe/cohesive_law.h"

namespace mneedle::fe {

struct PlaneStrainInsertionProblem {
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
  double block_width_m = 0.0;   ///< full width; the cut at its centre
  double block_depth_m = 0.0;   ///< top surface to the bottom supports
  double thickness_m = 0.0;     ///< out of plane
  double needle_width_m = 0.0;  ///< w, shaft width
  double tip_angle_rad = 0.0;   ///< included angle of the wedge tip, in (0, pi)
  /// Coulomb, on the shaft; 0 on the tip's flank, growing along the shoulder's arc between.
  double friction_coefficient = 0.0;
  /// Radius of the arc joining the tip's flank to the shaft, at most w/4; 0: w/4. A sharp
  /// shoulder is not offered: nodes snap off it (docs/model.md, "Plane-strain insertion").
  double shoulder_radius_m = 0.0;
  double travel_m = 0.0;  ///< tip travel from touching the top surface, at most 2 x depth
  CohesiveLaw cohesion;   ///< toughness 0 (the default): the cut runs through the whole block
  /// Travel per step, at most one cell; 0: kInsertionDefaultStepFraction of the cell size.
  double step_m = 0.0;
  /// Cell size along the cut and across the uniform zone; 0: w / 8.
  double element_size_m = 0.0;
  /// Uniform cells from the cut out to this distance, then cells grow by kInsertionGridGrowth to
  /// the side; 0: 4 w (paper C's 32 mm for its 8 mm needle), capped at half the width.
  double uniform_zone_m = 0.0;
};

/// Default step as a fraction of the cell size: the energy ledger's closure is first order in
/// the step (paper C's case, 1.6 mm cells, worst step: 1.5 % at h/8 with friction, 3.4 %
/// frictionless; docs/performance.md).
inline constexpr double kInsertionDefaultStepFraction = 0.125;
/// Growth ratio of neighbouring cells beyond the uniform zone.
inline constexpr double kInsertionGridGrowth = 1.1;
/// Largest mesh (nodes) and largest cut (nodes on x = 0) accepted: the contact problem is dense
/// on the cut's nodes, so their number bounds the work of every step.
inline constexpr double kInsertionMaxNodes = 1.0e6;
inline constexpr double kInsertionMaxCutNodes = 2000.0;
/// Largest friction coefficient accepted: above it the sliding state's upward slip fails.
inline constexpr double kInsertionMaxFriction = 0.6;
/// Cells the cohesive length E G_c / sigma_max^2 must span (the 3-5 elements in the
/// process zone; paper C's 1.6 mm cells give 3.5).
inline constexpr double kInsertionMinCellsPerCohesiveLength = 3.0;
/// Largest number of steps accepted.
inline constexpr double kInsertionMaxSteps = 20000.0;

/// One step's state, for the whole block.
struct PlaneStrainInsertionStep {
  double travel_m = 0.0;
  double force_N = 0.0;            ///< pushing the needle down: tip normal forces + shaft friction
  double friction_force_N = 0.0;   ///< the shaft's share of force_N (the arc's friction is not)
  double normal_force_N = 0.0;     ///< normal force of the cut faces on the shaft (both sides)
  double external_work_J = 0.0;    ///< integral of force over travel (trapezoidal)
  double strain_energy_J = 0.0;    ///< 1/2 u^T K u
  double friction_work_J = 0.0;    ///< sum of mu N times slip, from the slipping nodes
  double cohesive_work_J = 0.0;    ///< work into the cohesive interface (dissipated + stored)
  double fracture_energy_J = 0.0;  ///< the dissipated part of cohesive_work_J
  double crack_depth_m = 0.0;  ///< the crack's end below the surface: initial cut + failed cells
  /// (W_ext - U - W_f - W_coh) / W_ext: the ledger's closure; 0 before the needle has done work.
  double balance_error = 0.0;
  int tip_contacts = 0;    ///< cut nodes on the tip: flank, shoulder arc, apex
  int shaft_contacts = 0;  ///< cut nodes on the shaft
  int sticking = 0;        ///< shaft nodes that stick (the rest slide)
  int active_set_iterations = 0;
};

struct PlaneStrainInsertionResult {
  std::vector<PlaneStrainInsertionStep> steps;  ///< from travel 0
  int nodes = 0;
  int elements = 0;
  int cut_nodes = 0;
  double element_size_m = 0.0;
  double step_m = 0.0;
  double tip_length_m = 0.0;           ///< the sharp wedge's height, (w/2) / tan(angle/2)
  double shoulder_radius_m = 0.0;      ///< the arc's radius actually used
  double max_abs_balance_error = 0.0;  ///< over steps with external work above 1e-3 of the last
  double max_penetration_m = 0.0;      ///< deepest cut node inside the needle or its mirror face
  /// With cohesion: the puncture, where the first cell below the initial cut fails and the crack
  /// starts to run (travel 0 when none fails), and the largest force up to there.
  double puncture_travel_m = 0.0;
  double puncture_force_N = 0.0;
};

/// Runs the insertion. Throws InputError (one line naming the field) on a bad problem and
/// SolverError when the contact set of a step does not settle.
PlaneStrainInsertionResult simulate_plane_strain_insertion(
    const PlaneStrainInsertionProblem& problem);

}  // namespace mneedle::fe
