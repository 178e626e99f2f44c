#include "mneedle/fe/cohesive_law.h"

#include <algorithm>
#include <cmath>

namespace mneedle::fe {

double cohesive_peak_traction(const CohesiveLaw& law) {
  if (!(law.toughness_J_per_m2 > 0.0)) return 0.0;
  return 2.0 * law.toughness_J_per_m2 / law.failure_opening_m;
}

double cohesive_damage(const CohesiveLaw& law, double largest_opening_m) {
  if (!(law.toughness_J_per_m2 > 0.0) || largest_opening_m <= law.peak_opening_m) return 0.0;
  if (largest_opening_m >= law.failure_opening_m) return 1.0;
  // On the softening branch t = t_peak (delta_0 - delta) / (delta_0 - delta_y).
  const double peak = cohesive_peak_traction(law);
  const double delta = largest_opening_m;
  const double t =
      peak * (law.failure_opening_m - delta) / (law.failure_opening_m - law.peak_opening_m);
  return 1.0 - t / (peak / law.peak_opening_m * delta);
}

double cohesive_traction(const CohesiveLaw& law, double opening_m, double largest_opening_m) {
  if (!(law.toughness_J_per_m2 > 0.0) || !(opening_m > 0.0)) return 0.0;
  const double stiffness0 = cohesive_peak_traction(law) / law.peak_opening_m;
  const double reached = std::max(opening_m, largest_opening_m);
  return (1.0 - cohesive_damage(law, reached)) * stiffness0 * opening_m;
}

double cohesive_dissipated_energy(const CohesiveLaw& law, double largest_opening_m) {
  if (!(law.toughness_J_per_m2 > 0.0) || largest_opening_m <= law.peak_opening_m) return 0.0;
  if (largest_opening_m >= law.failure_opening_m) return law.toughness_J_per_m2;
  const double peak = cohesive_peak_traction(law), delta = largest_opening_m;
  const double y = law.peak_opening_m, zero = law.failure_opening_m;
  const double t = peak * (zero - delta) / (zero - y);
  const double envelope = 0.5 * peak * y + 0.5 * (peak + t) * (delta - y);
  return envelope - 0.5 * t * delta;
}

}  // namespace mneedle::fe
