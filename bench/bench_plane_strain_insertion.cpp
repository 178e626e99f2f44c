// Paper C's plane-strain insertion along a cut (no cohesion): cost and convergence of the energy
// ledger with the cell size, with and without shaft friction, and with the shoulder's radius
// (docs/performance.md, "Plane-strain insertion"; docs/validation.md, "Plane-strain insertion").
// Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 build/<dir>/bench/bench_plane_strain_insertion
// Arguments of each case: cell size (um), mu x 10, shoulder radius (um).
#include <benchmark/benchmark.h>

#include <exception>
#include <numbers>

#include "mneedle/fe/plane_strain_insertion.h"

namespace {

using namespace mneedle::fe;

// Paper C §6: gelatine E 7 kPa, nu 0.475, block 160 x 86 mm, 15 mm thick; needle 8 mm, 50 deg.
PlaneStrainInsertionProblem paper_c_block() {
  PlaneStrainInsertionProblem p;
  p.youngs_modulus_Pa = 7e3;
  p.poisson_ratio = 0.475;
  p.block_width_m = 0.16;
  p.block_depth_m = 0.086;
  p.thickness_m = 0.015;
  p.needle_width_m = 0.008;
  p.tip_angle_rad = 50.0 * std::numbers::pi / 180.0;
  p.travel_m = 0.086;
  return p;
}

void BM_PaperCWithoutCohesion(benchmark::State& state) {
  PlaneStrainInsertionProblem p = paper_c_block();
  p.element_size_m = state.range(0) * 1e-6;
  p.friction_coefficient = state.range(1) / 10.0;
  p.shoulder_radius_m = state.range(2) * 1e-6;
  p.travel_m = 0.086;
  PlaneStrainInsertionResult r;
  for (auto _ : state) r = simulate_plane_strain_insertion(p);
  const PlaneStrainInsertionStep& end = r.steps.back();
  state.counters["nodes"] = r.nodes;
  state.counters["steps"] = static_cast<double>(r.steps.size() - 1);
  state.counters["W_ext_mJ"] = end.external_work_J * 1e3;
  state.counters["U_mJ"] = end.strain_energy_J * 1e3;
  state.counters["W_f_mJ"] = end.friction_work_J * 1e3;
  state.counters["F_N"] = end.force_N;
  state.counters["worst_closure_pct"] = 100.0 * r.max_abs_balance_error;
  state.counters["end_closure_pct"] = 100.0 * end.balance_error;
}

BENCHMARK(BM_PaperCWithoutCohesion)
    ->ArgsProduct({{1600, 800, 400}, {0, 5}, {2000}})
    ->Args({1600, 0, 1000})
    ->Args({800, 0, 1000})
    ->Args({400, 0, 1000})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// With paper C's cohesive interface (G_c 17.43 J/m^2, delta_y 7 mm, delta_0 7.5 mm, 3.2 mm cut
// at the top, mu 0.5). Arguments: cell size (um), viscosity (um).
void BM_PaperCWithCohesion(benchmark::State& state) {
  PlaneStrainInsertionProblem p = paper_c_block();
  p.element_size_m = state.range(0) * 1e-6;
  p.friction_coefficient = 0.5;
  p.travel_m = 0.086;
  p.cohesion.toughness_J_per_m2 = 17.43;
  p.cohesion.peak_opening_m = 7e-3;
  p.cohesion.failure_opening_m = 7.5e-3;
  p.cohesion.initial_cut_m = 3.2e-3;
  p.cohesion.viscosity_m = state.range(1) * 1e-6;
  PlaneStrainInsertionResult r;
  try {
    for (auto _ : state) r = simulate_plane_strain_insertion(p);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const PlaneStrainInsertionStep& end = r.steps.back();
  state.counters["puncture_mm"] = r.puncture_travel_m * 1e3;
  state.counters["puncture_N"] = r.puncture_force_N;
  state.counters["W_ext_mJ"] = end.external_work_J * 1e3;
  state.counters["U_mJ"] = end.strain_energy_J * 1e3;
  state.counters["W_f_mJ"] = end.friction_work_J * 1e3;
  state.counters["fracture_mJ"] = end.fracture_energy_J * 1e3;
  state.counters["crack_mm"] = end.crack_depth_m * 1e3;
  state.counters["worst_closure_pct"] = 100.0 * r.max_abs_balance_error;
}

BENCHMARK(BM_PaperCWithCohesion)
    ->ArgsProduct({{1600, 800, 400}, {500, 0}})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
