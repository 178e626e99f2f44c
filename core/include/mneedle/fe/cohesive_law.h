#pragma once
// A bilinear traction-separation law for a crack path fixed in advance (paper C: Oldfield, Dini,
// Giordano, Rodriguez y Baena, CMBBE 16(5):530-543, 2013, its Fig. 3), used by the plane-strain
// insertion along a cut (docs/model.md, "Cohesive interface"). SI units: openings in m,
// tractions in Pa, energies per unit crack area in J/m^2.

namespace mneedle::fe {

/// Paper C's bilinear law: the traction rises linearly to its peak 2 G_c / delta_0 at the
/// opening delta_y, falls linearly to zero at delta_0 (G_c the area under it) and never heals:
/// below the largest opening reached it unloads to the origin.
struct CohesiveLaw {
  double toughness_J_per_m2 = 0.0;  ///< G_c; 0: no cohesion, the block is cut through
  double peak_opening_m = 0.0;      ///< delta_y
  double failure_opening_m = 0.0;   ///< delta_0 > delta_y
  /// Plane-strain insertion only: depth cut before the insertion, from the top surface (paper C
  /// removes two 1.6 mm elements "to enable initial separation").
  double initial_cut_m = 0.0;
  /// Plane-strain insertion only: viscous regularisation (a travel): the damage relaxes towards
  /// the law's over this much travel of the needle, so that a cell failing does not snap the
  /// block open within one step (docs/model.md, "Cohesive interface"). 0: none
  /// (rate-independent; the ledger then misses by the energy of each snap).
  double viscosity_m = 0.5e-3;
};

/// Peak traction 2 G_c / delta_0 (Pa); 0 without cohesion.
double cohesive_peak_traction(const CohesiveLaw& law);

/// The law's damage at the largest opening a cell has reached (m): 0 up to delta_y, then
/// 1 - t(delta)/(K0 delta) on the softening branch, 1 from delta_0; K0 = t_peak / delta_y. It
/// depends on the largest opening only, so it never falls: the crack never heals.
double cohesive_damage(const CohesiveLaw& law, double largest_opening_m);

/// Traction (Pa) across a cell open by `opening_m` that has reached `largest_opening_m` before:
/// the law's envelope while the opening grows past it, (1 - D) K0 opening below it (unloading
/// and reloading along the damaged secant, through the origin). 0 without cohesion.
double cohesive_traction(const CohesiveLaw& law, double opening_m, double largest_opening_m);

/// Energy per unit crack area (J/m^2) the law has dissipated at a cell that has reached
/// `largest_opening_m`: the area under the envelope up to it less what unloading along the
/// damaged secant would return; G_c once the cell has failed, 0 up to delta_y.
double cohesive_dissipated_energy(const CohesiveLaw& law, double largest_opening_m);

}  // namespace mneedle::fe
