#pragma once
// The steady penetration force of a sharp needle that advances by wedging open a planar mode-I
// crack (Shergold & Fleck 2004, sharp-tipped punch; Montanari et al. 2023), in a linear elastic
// tissue: one unit of advance stores the strain energy of one unit length of wedged crack and
// costs the fracture work of that much crack, so
//     F_p(r) = min over w̄ > 2r of [ U_ε(w̄, r) + Γ w̄ ],
// with U_ε from the plane-strain model of fe/plane_strain_crack.h. It is the threshold of the
// "penetration" puncture criterion (docs/model.md, "Penetration criterion"). SI units.

#include <array>
#include <vector>

namespace mneedle {

/// Crack widths w̄ / (2r) at which U_ε is tabulated. The first is 1 % wider than the needle
/// (the plane-strain model needs 2r < w̄); the last bounds the search.
inline constexpr std::array<double, 12> kWedgeWidthRatios = {1.01, 1.05, 1.1, 1.2, 1.35, 1.5,
                                                             1.75, 2.0,  2.5, 3.0, 4.0,  6.0};

/// U_ε / (E r²) at each of kWedgeWidthRatios for Poisson's ratio ν (dimensionless). U_ε scales
/// exactly as E r² (linear elasticity, a mesh and block similar to the crack), so one table per
/// ν serves every modulus and radius: it is computed once per ν and process (12 plane-strain
/// solves, about 4 s) and kept. Thread-safe: the solves run outside the lock, so a thread asking
/// for a table already made never waits. Throws InputError for ν outside [0, 0.5).
const std::vector<double>& wedged_crack_energy_table(double poisson_ratio);

struct PenetrationForce {
  double force_N = 0.0;                ///< F_p = U_ε + Γ w̄ at the minimising width
  double crack_width_m = 0.0;          ///< w̄ at the minimum
  double strain_energy_J_per_m = 0.0;  ///< U_ε there
  double fracture_work_J_per_m = 0.0;  ///< Γ w̄ there
  /// The minimum lies at the narrowest tabulated crack (1 % wider than the needle): the
  /// toughness is high against E r and the crack stays as wide as the needle.
  bool at_narrowest_crack = false;
  /// The minimum lies at the widest tabulated crack (12 r): the true minimum may be wider and
  /// its force lower, so F_p is an upper bound there (a brittle layer, Γ ≪ E r).
  bool at_widest_crack = false;
};

/// F_p for a needle of radius r [m] in a tissue of Young's modulus E [Pa], Poisson's ratio ν and
/// toughness Γ [J/m², energy per unit crack area]. Minimised over the tabulated widths (U_ε
/// linear between them, so the minimum is at a tabulated width); continuous in every argument.
/// r = 0 gives 0 (without the table). Throws InputError for E ≤ 0, Γ ≤ 0, r < 0 or a non-finite
/// value.
PenetrationForce sharp_penetration_force(double youngs_modulus_Pa, double poisson_ratio,
                                         double toughness_J_per_m2, double radius_m);

}  // namespace mneedle
