#include "mneedle/fe/plane_strain_insertion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

// Paper C §6 (Oldfield et al. 2013): gelatine E 7 kPa, nu 0.475, block 160 mm wide and 86 mm
// deep, 15 mm out of plane, needle 8 mm wide with a 50 degree tip (its shoulder rounded, 2 mm,
// the default), 1.6 mm cells, through the block's depth.
PlaneStrainInsertionProblem paper_c(double mu) {
  PlaneStrainInsertionProblem p;
  p.youngs_modulus_Pa = 7e3;
  p.poisson_ratio = 0.475;
  p.block_width_m = 0.16;
  p.block_depth_m = 0.086;
  p.thickness_m = 0.015;
  p.needle_width_m = 0.008;
  p.tip_angle_rad = 50.0 * std::numbers::pi / 180.0;
  p.friction_coefficient = mu;
  p.element_size_m = 1.6e-3;
  p.travel_m = 0.086;
  return p;
}

const PlaneStrainInsertionResult& paper_c_run() {
  static const PlaneStrainInsertionResult r = simulate_plane_strain_insertion(paper_c(0.5));
  return r;
}

// Paper C's Table 1, "finite element with no cohesion": external work 0.058 J, friction 0.052 J,
// strain energy 0.006 J (mu 0.5, the block's depth). Our absolute level is 23 % lower (a miss,
// docs/validation.md "Plane-strain insertion"); the split of the work is the paper's.
TEST(PlaneStrainInsertion, PaperCRunWithoutCohesionSplitsTheWorkAsItsTable1Row) {
  const PlaneStrainInsertionStep& end = paper_c_run().steps.back();
  ASSERT_DOUBLE_EQ(end.travel_m, 0.086);
  // Friction's share: paper 0.052 / 0.058 = 0.897, each number given to +-0.0005 J, so the
  // share is known to +-2 %; ours 0.897.
  EXPECT_NEAR(end.friction_work_J / end.external_work_J / (0.052 / 0.058), 1.0, 0.02);
  // Strain energy's share: paper 0.006 / 0.058 = 0.103, known to +-9 % (one digit); ours 0.107.
  EXPECT_NEAR(end.strain_energy_J / end.external_work_J / (0.006 / 0.058), 1.0, 0.09);
  // Our converged external work (44.60 mJ on 0.4 mm cells, 44.58 mJ here): 1 % is far above
  // the meshes' difference (0.05 %) and far below the 23 % by which it misses the paper's 58 mJ.
  EXPECT_NEAR(end.external_work_J / 44.60e-3, 1.0, 0.01);
}

TEST(PlaneStrainInsertion, EnergyLedgerClosesAtEveryStepWithFriction) {
  // W_ext (trapezoid of the force) against U + W_f (mu N times each node's slip): independent
  // sums. Measured 1.52 % at 1.6 mm cells, 0.82 % at 0.8 mm, 0.42 % at 0.4 mm (h/8 steps); the
  // bound is paper C's 2 % (the requirement for the cohesive model's ledger).
  EXPECT_LT(paper_c_run().max_abs_balance_error, 0.02);
}

TEST(PlaneStrainInsertion, FrictionlessInsertionStoresTheWorkDone) {
  // Nothing dissipates without friction: W_ext = U. Measured at 1.6 / 0.8 / 0.4 mm cells: at
  // worst over the run 3.4 / 0.57 / 0.035 %, at the end 0.3 %; with a sharp shoulder 27 / 21 /
  // 18 % (nodes snapping off it). Bounds: 5 % over the run and 1 % at the end, each above the
  // measured value by a margin that a sharp shoulder's 27 % cannot meet.
  const PlaneStrainInsertionResult r = simulate_plane_strain_insertion(paper_c(0.0));
  EXPECT_LT(r.max_abs_balance_error, 0.05);
  EXPECT_LT(std::abs(r.steps.back().balance_error), 0.01);
  for (const PlaneStrainInsertionStep& s : r.steps) {
    // mu(n) = 0 makes the tangential rows f_y = 0 up to the LU's round-off.
    EXPECT_NEAR(s.friction_force_N, 0.0, 1e-12 * (1.0 + s.normal_force_N));
    EXPECT_EQ(s.friction_work_J, 0.0);
  }
  // The wedged-open block stores less than with friction (no drag): 2.90 mJ against 4.79 mJ.
  EXPECT_LT(r.steps.back().strain_energy_J, 0.7 * paper_c_run().steps.back().strain_energy_J);
}

TEST(PlaneStrainInsertion, ShaftFrictionIsCoulombsAndGrowsLinearlyWithDepth) {
  const PlaneStrainInsertionResult& r = paper_c_run();
  double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  int n = 0;
  for (const PlaneStrainInsertionStep& s : r.steps) {
    // Never more than mu N; exactly mu N when no shaft node sticks (all slide here).
    EXPECT_LE(s.friction_force_N, 0.5 * s.normal_force_N * (1.0 + 1e-9) + 1e-12);
    if (s.sticking == 0) {
      EXPECT_NEAR(s.friction_force_N, 0.5 * s.normal_force_N, 1e-9);
    }
    if (s.travel_m <= 2.0 * r.tip_length_m) continue;
    sx += s.travel_m, sy += s.friction_force_N, sxx += s.travel_m * s.travel_m;
    sxy += s.travel_m * s.friction_force_N, syy += s.friction_force_N * s.friction_force_N;
    ++n;
  }
  // Paper C eq. 2 takes the friction force as linear in depth (F_max x / d); its FE (§7) finds it
  // "essentially linear". Ours: R^2 = 0.9922 once the shoulder is two tip lengths in; 0.98 is
  // what a force with a 10 % bow would give. And W_f = 0.929 F_f(d) d / 2: the friction work
  // the energy method of eq. 2 would assume is above ours; 0.85-1.0 brackets it.
  const double cov = sxy - sx * sy / n, vx = sxx - sx * sx / n, vy = syy - sy * sy / n;
  EXPECT_GT(cov * cov / (vx * vy), 0.98);
  const PlaneStrainInsertionStep& end = r.steps.back();
  const double eq2 = end.friction_work_J / (0.5 * end.friction_force_N * end.travel_m);
  EXPECT_GT(eq2, 0.85);
  EXPECT_LT(eq2, 1.0);
}

TEST(PlaneStrainInsertion, NoCutNodeEntersTheNeedleOrItsMirrorImage) {
  // Contact is enforced exactly at the nodes; the active set accepts 1e-9 w = 8e-12 m.
  EXPECT_LT(paper_c_run().max_penetration_m, 8e-12);
  EXPECT_GT(paper_c_run().steps.back().shaft_contacts, 40);  // 54 cut nodes, most on the shaft
}

// Paper C's run with cohesion (§6): G_c 17.43 J/m^2, delta_y 7 mm, delta_0 7.5 mm, two 1.6 mm
// cells cut at the top; our viscosity 0.5 mm (the default).
PlaneStrainInsertionProblem paper_c_cohesive() {
  PlaneStrainInsertionProblem p = paper_c(0.5);
  p.cohesion.toughness_J_per_m2 = 17.43;
  p.cohesion.peak_opening_m = 7e-3;
  p.cohesion.failure_opening_m = 7.5e-3;
  p.cohesion.initial_cut_m = 3.2e-3;
  return p;
}

const PlaneStrainInsertionResult& paper_c_cohesive_run() {
  static const PlaneStrainInsertionResult r = simulate_plane_strain_insertion(paper_c_cohesive());
  return r;
}

// Paper C's Table 1, "finite element with cohesion": external work 0.084 J, cutting 0.022 J,
// friction 0.059 J, strain energy 0.004 J; the issue asks 15 %. External work and cutting are
// within it on every mesh (-8.1 % / -7.5 % here, -8.2 % / -7.1 % on 0.4 mm cells). Friction and
// strain energy miss (converged -15.9 % and +53 %, docs/validation.md "Plane-strain insertion"):
// they are pinned to our converged values, 2 % being above the meshes' spread (1.4 %, 0.2 %).
TEST(PlaneStrainInsertion, PaperCRunWithCohesionMatchesItsTable1RowInWorkAndCutting) {
  const PlaneStrainInsertionStep& end = paper_c_cohesive_run().steps.back();
  EXPECT_NEAR(end.external_work_J / 0.084, 1.0, 0.15);
  EXPECT_NEAR(end.fracture_energy_J / 0.022, 1.0, 0.15);
  EXPECT_NEAR(end.friction_work_J / 49.61e-3, 1.0, 0.02);
  EXPECT_NEAR(end.strain_energy_J / 6.10e-3, 1.0, 0.02);
}

TEST(PlaneStrainInsertion, EnergyLedgerClosesWithCohesion) {
  // W_ext = U + W_f + W_coh at every step. Measured 1.02 % / 0.48 % / 0.26 % at 1.6 / 0.8 /
  // 0.4 mm cells; without the viscosity 5.6 % at 1.6 mm (each failing cell snaps the block open
  // within a step, and the friction of that snap is not resolved). Bound: paper C's 2 %.
  EXPECT_LT(paper_c_cohesive_run().max_abs_balance_error, 0.02);
}

TEST(PlaneStrainInsertion, FractureEnergyPerCrackAreaIsTheToughnessPlusTheProcessZone) {
  // Dissipated energy over the area failed below the initial cut: at least G_c; above it by the
  // cells past the peak that have not failed yet (the process zone along the flank) and by the
  // viscosity's overshoot. Measured 1.19 G_c; 1.3 would mean energy dissipated elsewhere.
  const PlaneStrainInsertionStep& end = paper_c_cohesive_run().steps.back();
  const double area = 0.015 * (end.crack_depth_m - 3.2e-3);
  const double g = end.fracture_energy_J / area;
  EXPECT_GT(g, 17.43);
  EXPECT_LT(g, 1.3 * 17.43);
}

TEST(PlaneStrainInsertion, PunctureIsWhereTheCrackStartsToRun) {
  const PlaneStrainInsertionResult& r = paper_c_cohesive_run();
  // The first cell below the cut fails at 24.29 mm (0.777 N); 22.89 and 22.10 mm on 0.8 and
  // 0.4 mm cells (bench/bench_plane_strain_insertion): converging, the 1.6 mm cells 10 % late.
  // 1 % pins this mesh's value against a change of the model.
  EXPECT_NEAR(r.puncture_travel_m / 24.29e-3, 1.0, 0.01);
  EXPECT_NEAR(r.puncture_force_N / 0.777, 1.0, 0.01);
  for (const PlaneStrainInsertionStep& s : r.steps) {
    if (s.travel_m < r.puncture_travel_m) {
      EXPECT_DOUBLE_EQ(s.crack_depth_m, 3.2e-3);
    } else {
      EXPECT_GT(s.crack_depth_m, 3.2e-3);
    }
  }
  // The cut block has no puncture.
  EXPECT_EQ(paper_c_run().puncture_travel_m, 0.0);
}

void expect_refused(const std::function<void(PlaneStrainInsertionProblem&)>& edit,
                    const std::string& field) {
  PlaneStrainInsertionProblem p = paper_c(0.5);
  edit(p);
  try {
    simulate_plane_strain_insertion(p);
    ADD_FAILURE() << "accepted a bad " << field;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(PlaneStrainInsertion, BadProblemIsRefusedNamingTheField) {
  expect_refused([](auto& p) { p.youngs_modulus_Pa = -1.0; }, "youngs_modulus_Pa");
  expect_refused([](auto& p) { p.poisson_ratio = 0.5; }, "poisson_ratio");
  expect_refused([](auto& p) { p.tip_angle_rad = std::numbers::pi; }, "tip_angle_rad");
  expect_refused([](auto& p) { p.shoulder_radius_m = 3e-3; }, "shoulder_radius_m");
  expect_refused([](auto& p) { p.friction_coefficient = std::nan(""); }, "friction_coefficient");
  // At 0.7 stick and slip cycle ("the contact set did not settle at travel 8.8 mm").
  expect_refused([](auto& p) { p.friction_coefficient = 0.7; }, "friction_coefficient");
  expect_refused([](auto& p) { p.travel_m = 0.2; }, "travel_m");
  expect_refused([](auto& p) { p.block_width_m = 0.02; }, "block_width_m");
  expect_refused([](auto& p) { p.element_size_m = 3e-3; }, "element_size_m");
  expect_refused([](auto& p) { p.step_m = 2e-3; }, "step_m");
  expect_refused(
      [](auto& p) {
        p.cohesion.toughness_J_per_m2 = 17.43;
        p.cohesion.peak_opening_m = 7e-3;
        p.cohesion.failure_opening_m = 7e-3;
      },
      "cohesion.failure_opening_m");
  expect_refused(
      [](auto& p) {
        p.cohesion.toughness_J_per_m2 = 17.43;
        p.cohesion.peak_opening_m = 0.0;
      },
      "cohesion.peak_opening_m");
  expect_refused([](auto& p) { p.cohesion.toughness_J_per_m2 = -1.0; }, "cohesion.toughness");
  expect_refused(
      [](auto& p) {
        p.cohesion = {17.43, 7e-3, 7.5e-3, 0.086, 0.5e-3};
      },
      "cohesion.initial_cut_m");
  expect_refused(
      [](auto& p) {
        p.cohesion = {17.43, 7e-3, 7.5e-3, 3.2e-3, -1e-3};
      },
      "cohesion.viscosity_m");
  expect_refused([](auto& p) { p.uniform_zone_m = 1e-12; }, "uniform_zone_m");
  // Cohesive length 7 kPa x 17.43 / (4648 Pa)^2 = 5.65 mm: 2 mm cells span 2.8 of it.
  expect_refused(
      [](auto& p) {
        p.cohesion = {17.43, 7e-3, 7.5e-3, 3.2e-3, 0.5e-3};
        p.element_size_m = 2e-3;
      },
      "cohesive length");
  // The step is checked against the cells the mesh has (the depth divided evenly: 2.4 mm in
  // 1 mm cells gives 0.8 mm cells), not the size asked for.
  expect_refused(
      [](auto& p) {
        p.block_depth_m = 2.4e-3;
        p.element_size_m = 1e-3;
        p.step_m = 1e-3;
        p.travel_m = 2e-3;
      },
      "step_m");
  // A tiny cell is refused before any allocation: the cut's nodes bound every step's work.
  expect_refused([](auto& p) { p.element_size_m = 1e-6; }, "element_size_m");
}

}  // namespace
}  // namespace mneedle::fe
