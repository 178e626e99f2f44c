#pragma once
// The stress criterion in closed form, for the analytic path: a top layer much stiffer than the
// layers beneath (skin's stratum corneum) bends as a thin plate on them and a sharp tip presses
// it at one point. The force is then linear in the depth and the stress the criterion averages
// is linear in the force (docs/model.md, "The stress criterion on the
// analytic path"). SI units.

#include "mneedle/fe/axisymmetric.h"
#include "mneedle/scene/scene.h"

namespace mneedle {

struct PlateContact {
  double stiffness_N_per_m = 0.0;  ///< F / d, the contact staying where it started
  /// The top layer's maximum principal stress averaged over its strength_length around the
  /// underside below the contact, per newton of needle force (Pa/N).
  double stress_per_force_Pa_per_N = 0.0;
  double bending_length_m = 0.0;       ///< l = (2 D / E*_f)^(1/3)
  double foundation_modulus_Pa = 0.0;  ///< E*_f = E / (1 - nu^2) of the layer beneath
};

/// A top layer bends as a plate when the plate's length l is at least this many thicknesses:
/// Kirchhoff's theory needs the thickness small beside the bending length.
inline constexpr double kPlateLengthPerThickness = 5.0;

/// The top layer of `tissue` as a Kirchhoff plate bonded to the layer beneath, taken for an
/// elastic half-space, loaded at one point by a pointed tip (`contact_radius_m`, the radius of
/// the needle's end, at most the layer's strength_length L). The stress is averaged over L, as
/// the FE stress probe averages it. Throws InputError, naming the layer and the value, when the
/// tissue has fewer than two layers, the top layer has no strength, l < kPlateLengthPerThickness
/// thicknesses (the layer does not bend as a plate) or the end is a flat wider than 2 L (a rigid
/// edge concentrates stress beyond a plate's reach): the FE models answer those.
PlateContact plate_contact(const Tissue& tissue, double contact_radius_m);

/// The tip's local indentation of the top layer, in series with the plate's bending: Sneddon's
/// frictionless punch of the needle's profile on a half-space of the top layer's E and nu
/// (docs/model.md, "The stress criterion on the analytic path"). The tip travel at force F is
/// F / k_p + delta(F); these give it both ways (N and m).
double plate_depth_at_force(const PlateContact& plate, const Tissue& tissue,
                            const fe::AxisymmetricNeedle& needle, double force_N);
double plate_force_at_depth(const PlateContact& plate, const Tissue& tissue,
                            const fe::AxisymmetricNeedle& needle, double depth_m);

/// Deflection of the plate at radius r over its deflection under the point, w(r) / w(0).
double plate_deflection_shape(const PlateContact& plate, double radius_m);

/// The deepest tip travel (m) at which the needle still touches the bent plate at its tip only:
/// the smallest h(r) / (1 - w(r)/w(0)) over the needle's profile, h(r) the needle's height above
/// its tip at radius r (infinite when its flank never meets the plate).
double point_contact_depth_limit(const PlateContact& plate, const fe::AxisymmetricNeedle& needle);

}  // namespace mneedle
