#include "mneedle/fe/cohesive_law.h"

#include <gtest/gtest.h>

namespace mneedle::fe {
namespace {

// Paper C's bilinear law (G_c 17.43 J/m^2, delta_y 7 mm, delta_0 7.5 mm; peak traction
// 2 G_c / delta_0 = 4648 Pa): the envelope encloses G_c, a cell unloads and reloads along its
// damaged secant through the origin, and its damage follows the largest opening only, so it
// never heals (docs/model.md, "Cohesive interface").
CohesiveLaw paper_c_law() {
  CohesiveLaw law;
  law.toughness_J_per_m2 = 17.43;
  law.peak_opening_m = 7e-3;
  law.failure_opening_m = 7.5e-3;
  return law;
}

TEST(CohesiveLaw, ACellUnloadsAlongItsDamagedSecantAndNeverHeals) {
  const CohesiveLaw law = paper_c_law();
  const double peak = 2.0 * 17.43 / 7.5e-3;
  // The envelope (loading: the opening is the largest reached) and its area, Simpson on a grid
  // with nodes at delta_y and delta_0, where the law has its corners: exact for linear pieces.
  EXPECT_NEAR(cohesive_traction(law, 7e-3, 7e-3), peak, 1e-9 * peak);
  EXPECT_NEAR(cohesive_traction(law, 7.25e-3, 7.25e-3), 0.5 * peak, 1e-9 * peak);
  EXPECT_EQ(cohesive_traction(law, 7.6e-3, 7.6e-3), 0.0);
  double area = 0.0;
  const int n = 1500;  // steps of 5 um: 1400 up to delta_y, 100 on the softening branch
  for (int i = 0; i < n; ++i) {
    const double a = i * 5e-6, b = (i + 1) * 5e-6, m = 0.5 * (a + b);
    area += (b - a) / 6.0 *
            (cohesive_traction(law, a, a) + 4.0 * cohesive_traction(law, m, m) +
             cohesive_traction(law, b, b));
  }
  EXPECT_NEAR(area, 17.43, 1e-9);
  // Unloading from 7.25 mm: the secant through the origin, half the peak at 7.25 mm.
  const double secant = 0.5 * peak / 7.25e-3;
  for (double delta : {0.0, 1e-3, 3.5e-3, 7.25e-3})
    EXPECT_NEAR(cohesive_traction(law, delta, 7.25e-3), secant * delta, 1e-9 * peak) << delta;
  // Damage: none before delta_y, growing with the largest opening, whole at delta_0; an opening
  // below the largest reached does not lower it.
  EXPECT_EQ(cohesive_damage(law, 6e-3), 0.0);
  EXPECT_LT(cohesive_damage(law, 7.1e-3), cohesive_damage(law, 7.3e-3));
  EXPECT_EQ(cohesive_damage(law, 7.5e-3), 1.0);
  EXPECT_EQ(cohesive_traction(law, 2e-3, 7.5e-3), 0.0);  // failed: no traction on reloading
  // Without cohesion there is no traction at all.
  EXPECT_EQ(cohesive_traction(CohesiveLaw{}, 1e-3, 1e-3), 0.0);
  EXPECT_NEAR(cohesive_peak_traction(law), peak, 1e-9 * peak);
  EXPECT_EQ(cohesive_peak_traction(CohesiveLaw{}), 0.0);
}

// What a cell has dissipated is the work done on it less what unloading returns: 0 up to
// delta_y, G_c once failed, and at 7.25 mm the envelope's area there (G_c - the remaining
// triangle, 17.43 - 0.5 (peak / 2) 0.25 mm) less the secant's 0.5 (peak / 2) 7.25 mm.
TEST(CohesiveLaw, DissipatedEnergyIsTheWorkDoneLessWhatUnloadingReturns) {
  const CohesiveLaw law = paper_c_law();
  const double peak = 2.0 * 17.43 / 7.5e-3;
  EXPECT_EQ(cohesive_dissipated_energy(law, 6e-3), 0.0);
  EXPECT_EQ(cohesive_dissipated_energy(law, 8e-3), 17.43);
  const double work = 17.43 - 0.5 * (0.5 * peak) * 0.25e-3;
  EXPECT_NEAR(cohesive_dissipated_energy(law, 7.25e-3), work - 0.5 * (0.5 * peak) * 7.25e-3, 1e-12);
  EXPECT_EQ(cohesive_dissipated_energy(CohesiveLaw{}, 1e-3), 0.0);
}

}  // namespace
}  // namespace mneedle::fe
