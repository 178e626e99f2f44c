#pragma once
// Puncture criteria (docs/model.md, "Criteria"; paper A §2.2): which quantity of the pre-puncture
// stage must reach which threshold, and where along the insertion it first does. The crossing is
// located between depth steps (linear interpolation, or bisection when the caller can re-evaluate
// the criterion at any depth) so that the puncture depth varies continuously with the design. SI
// units: Pa for pressure and stress, J/m^2 for the energy release rate.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/scene/scene.h"

namespace mneedle {

/// The threshold one criterion reads from the scene's top layer (the layer the tip enters).
struct PunctureThreshold {
  PunctureCriterion criterion = PunctureCriterion::Pressure;
  double threshold = 0.0;  ///< Pa (pressure, stress), J/m^2 (energy) or 1 (penetration: F/F_p)
  double average_length_m = 0.0;  ///< stress: the layer's strength length; else 0
  std::size_t layer = 0;          ///< index of the layer the data comes from
  /// cohesive: the law's peak traction sigma_c (Pa) and delta_y / delta_0 (the threshold is
  /// G_c, J/m^2, reported; the criterion itself is the force's first peak)
  double cohesive_strength_Pa = 0.0;
  double cohesive_peak_ratio = 0.0;
};

/// True when the top layer has any puncture data (fracture or strength). Without any, a run stays
/// in the pre-puncture stage for the whole depth (the behaviour before criteria existed).
bool has_puncture_data(const Scene& scene);

/// The criterion's threshold. Throws InputError "<file>:<line>: tissue.layers[0] '<name>':
/// <key>: missing (the <criterion> criterion needs it)" when the top layer lacks the value.
PunctureThreshold puncture_threshold(const Scene& scene, PunctureCriterion criterion);

/// Quantities of one pre-puncture depth step that the criteria read.
struct CriterionSample {
  double depth_m = 0.0;
  double contact_pressure_Pa = 0.0;           ///< F / A_sec: force over the outline area at z = 0
  double tip_stress_Pa = 0.0;                 ///< peak averaged max principal stress (Pa)
  double energy_release_rate_J_per_m2 = 0.0;  ///< G of a crack under the tip
  /// F / F_p: the force over the steady mode-I penetration force of the needle's section at
  /// the surface (penetration_force.h); dimensionless, the criterion fires at 1.
  double penetration_ratio = 0.0;
  double force_N = 0.0;  ///< the axial force (the cohesive criterion reads its peak)
  /// cohesive: the share of the ring crack's face area failed (1: cut through)
  double cohesive_failed_fraction = 0.0;
};

/// The cohesive criterion's second event: its ring, cut down to the top layer's bottom, has
/// failed throughout (a share of its face area of at least this).
inline constexpr double kCutThrough = 1.0 - 1e-9;  // the sum of shares, to round-off

/// The sample's value of the quantity the criterion compares with its threshold.
double criterion_value(PunctureCriterion criterion, const CriterionSample& sample);

/// Where a sequence of criterion values first reaches the threshold.
struct Crossing {
  double depth_m = 0.0;
  std::size_t step = 0;   ///< index of the first step at or above the threshold
  double fraction = 0.0;  ///< position in (previous step, step], 1 = at the step
};

/// First crossing of `threshold` by values[i] at depths[i] (ascending, > 0). Before the first
/// step the value is taken as 0 at depth 0 (no contact). Between the last step below and the
/// first at or above, the depth is interpolated linearly in the value, or, when `resolve` is
/// given (value at any depth), bisected to `depth_tolerance_m`. nullopt: never reached.
/// Throws InputError for unequal lengths, non-ascending depths, NaN or a threshold <= 0.
std::optional<Crossing> first_crossing(const std::vector<double>& depths_m,
                                       const std::vector<double>& values, double threshold,
                                       const std::function<double(double)>& resolve = {},
                                       double depth_tolerance_m = 0.0);

/// The cohesive criterion's puncture (docs/model.md, "The cohesive criterion"): the force's first
/// peak, where the crack's growth turns unstable. A peak is confirmed by the first step whose
/// force falls below the one before (by more than 1e-9 of it); it is placed at the vertex of the
/// parabola through the highest step and its two neighbours (0 at depth 0 before the first step),
/// so that it moves continuously with the design. `step` is the step whose interval (previous
/// step, step] holds the vertex; `peak_force_N`, when given, receives the parabola's value there.
/// nullopt: the force never fell. Throws InputError as first_crossing for bad sequences.
std::optional<Crossing> force_peak(const std::vector<double>& depths_m,
                                   const std::vector<double>& forces_N,
                                   double* peak_force_N = nullptr);

/// Index of the step that confirms a force peak (force_peak): the first whose force falls below
/// the one before by more than 1e-9 of it; nullopt when none does.
std::optional<std::size_t> force_drop_step(const std::vector<double>& forces_N);

/// Linear interpolation of a quantity tabulated at ascending depths (0 before the first step, the
/// last value beyond the last step).
double interpolate_at(const std::vector<double>& depths_m, const std::vector<double>& values,
                      double depth_m);

/// Depth of the planar (3-D) or ring (axisymmetric) crack used for G: the needle's diameter,
/// at least two tip elements so the mesh resolves it (docs/model.md, "Criteria").
double crack_depth_for(double needle_radius_m, double tip_element_size_m);

}  // namespace mneedle
