// Paper C's plane-strain insertion along a cut (no cohesion): cost and convergence of the energy
// ledger with the cell size, with and without shaft friction, and with the shoulder's radius
// (docs/performance.md, "Plane-strain insertion"; docs/validation.md, "Plane-strain insertion").
// Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 build/<dir>/bench/bench_plane_strain_insertion
// Arguments of each case: cell size (um), mu x 10, shoulder radius (um).
#include <benchmark/benchmark.h>

#include <numbers>

#include "mneedle/fe/plane_strain_insertion.h"

namespace {

using namespace mneedle::fe;

void BM_PaperCWithoutCohesion(benchmark::State& state) {
  PlaneStrainInsertionProblem p;
  p.youngs_modulus_Pa = 7e3;
  p.poisson_ratio = 0.475;
  p.block_width_m = 0.16;
  p.block_depth_m = 0.086;
  p.thickness_m = 0.015;
  p.needle_width_m = 0.008;
  p.tip_angle_rad = 50.0 * std::numbers::pi / 180.0;
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

}  // namespace

BENCHMARK_MAIN();
