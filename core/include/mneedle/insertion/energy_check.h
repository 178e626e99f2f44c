#pragma once
// The pre-puncture energy ledger (docs/model.md, "Energy check"): an elastic tissue pushed by a
// rigid needle stores what the needle's axial force did on it, U(d) = integral of F from 0 to d.
// A run whose stored energy departs from that work has a defect in its contact or its mesh; it is
// reported with every run and warned about, never hidden.

#include <optional>
#include <vector>

namespace mneedle {

/// Relative difference between stored energy and work above which a run is flagged: the
/// trapezoid rule over the run's depth steps is within 1 % of the integral for F ~ d^2 from
/// ten steps on, and what remains is the contact's own error.
inline constexpr double kEnergyCheckTolerance = 0.05;

struct EnergyCheck {
  double depth_m = 0.0;              ///< the deepest pre-puncture depth checked
  double work_J = 0.0;               ///< integral of the axial force from the surface to depth_m
  double strain_energy_J = 0.0;      ///< stored in the tissue at depth_m
  double relative_difference = 0.0;  ///< (strain energy - work) / work
  bool passes = true;                ///< |relative_difference| <= kEnergyCheckTolerance
};

/// The ledger of one pre-puncture curve, given as parallel arrays (depths increasing, in m; the
/// total axial force in N; the tissue's strain energy in J). The work is the trapezoid rule from
/// (0, 0) through the points. Empty when there is nothing to check: fewer than two points, no
/// strain energy (analytic models) or no work.
std::optional<EnergyCheck> check_energy(const std::vector<double>& depth_m,
                                        const std::vector<double>& force_N,
                                        const std::vector<double>& strain_energy_J);

}  // namespace mneedle
