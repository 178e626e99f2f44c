#include "mneedle/insertion/energy_check.h"

#include <cmath>
#include <cstddef>

#include "mneedle/base/error.h"

namespace mneedle {

std::optional<EnergyCheck> check_energy(const std::vector<double>& depth_m,
                                        const std::vector<double>& force_N,
                                        const std::vector<double>& strain_energy_J) {
  if (depth_m.size() != force_N.size() || depth_m.size() != strain_energy_J.size())
    throw InputError("energy check: depth, force and energy arrays differ in length");
  if (depth_m.size() < 2) return std::nullopt;
  double work = 0.0, previous_depth = 0.0, previous_force = 0.0;
  for (std::size_t i = 0; i < depth_m.size(); ++i) {
    if (depth_m[i] < previous_depth) throw InputError("energy check: depths must not decrease");
    work += 0.5 * (force_N[i] + previous_force) * (depth_m[i] - previous_depth);
    previous_depth = depth_m[i];
    previous_force = force_N[i];
  }
  const double stored = strain_energy_J.back();
  if (!(stored > 0.0) || !(work > 0.0) || !std::isfinite(work)) return std::nullopt;
  EnergyCheck check;
  check.depth_m = depth_m.back();
  check.work_J = work;
  check.strain_energy_J = stored;
  check.relative_difference = (stored - work) / work;
  check.passes = std::abs(check.relative_difference) <= kEnergyCheckTolerance;
  return check;
}

}  // namespace mneedle
