#pragma once
// Closed-form cross-section A(h) of the built-in needle shapes at height h above the tip,
// perpendicular to the axis: paper A's crack/contact area of the puncture criterion (section 2.2,
// Fig. 5). All lengths in metres, angles in radians, areas in m^2.

namespace mneedle {

/// Area of the circular segment of a circle of radius R cut off by a chord at signed distance b
/// from the centre: R^2 acos(b/R) - b sqrt(R^2 - b^2), with b/R clamped to [-1, 1]
/// (b = R gives 0, b = -R the full disc). Paper A's dA for the sharp bevel.
double circular_segment_area(double radius, double chord_distance);

enum class TipShape { cylinder, cone, sharp_bevel, blunt_bevel };

struct TipGeometry {
  TipShape shape = TipShape::cylinder;
  double radius_m = 0.0;         ///< outer radius R of the shaft
  double bore_radius_m = 0.0;    ///< inner radius of a hollow needle, 0 when solid
  double bevel_angle_rad = 0.0;  ///< bevel plane to the axis (bevels)
  double flat_width_m = 0.0;     ///< sagitta w of the blunt bevel's flat
  double half_angle_rad = 0.0;   ///< cone half-angle to the axis
  double tip_radius_m = 0.0;     ///< spherical cap of a cone, 0 for a sharp apex
};

/// A(h) of the shape; 0 for h < 0. Throws InputError for a non-positive radius, a bore not
/// inside the shaft, or an angle outside (0, pi/2) where the shape needs it.
///  - cylinder: pi (R^2 - r^2);
///  - sharp bevel: segment(R, b) - segment(r, b), b = R - h tan(theta);
///  - blunt bevel: the sharp bevel truncated by its flat: A_sharp(h + w / tan(theta));
///  - cone: pi rho(h)^2 - pi min(r, rho(h))^2, rho(h) = min(h tan(alpha), R), or with a tangent
///    spherical cap of radius c: rho^2 = 2 c h - h^2 up to h = c (1 - sin(alpha)).
double tip_area(const TipGeometry& geometry, double height_m);

/// Cross-section of the full shaft, pi (R^2 - r^2).
double full_section_area(const TipGeometry& geometry);

}  // namespace mneedle
