// Axisymmetric insertion benchmark: paper A's cone (base diameter 230 um, length 1000 um)
// pressed 200 um into paper A's three-layer skin (3000 x 3000 x 1150 um block as the
// equal-area cylinder), per fidelity, linear and neo-Hookean layers.
// Run: build/<dir>/bench/bench_axisymmetric --benchmark_min_time=1
#include <benchmark/benchmark.h>

#include <cmath>

#include "mneedle/fe/axisymmetric.h"

namespace {

using namespace mneedle::fe;

AxisymmetricProblem skin_problem(MaterialModel model, Fidelity fidelity) {
  auto layer = [model](double thickness, double E) {
    MaterialParameters p;
    p.model = model;
    p.E = E;
    p.nu = 0.4;
    return AxisymmetricLayer{thickness, p};
  };
  AxisymmetricProblem p;
  p.layers = {layer(20e-6, 1e9), layer(100e-6, 0.134e6), layer(1030e-6, 0.08e6)};
  p.radius_m = equal_area_radius(3e-3);
  p.needle = AxisymmetricNeedle::cone(std::atan(115.0 / 1000.0), 115e-6);
  p.depth_m = 200e-6;
  p.fidelity = fidelity;
  return p;
}

void BM_ConeIntoSkin(benchmark::State& state) {
  const auto model = static_cast<MaterialModel>(state.range(0));
  const auto fidelity = static_cast<Fidelity>(state.range(1));
  const AxisymmetricProblem problem = skin_problem(model, fidelity);
  InsertionResult last;
  for (auto _ : state) {
    last = simulate_axisymmetric(problem);
    benchmark::DoNotOptimize(last.steps.back().force_N);
  }
  state.counters["nodes"] = static_cast<double>(last.nodes);
  state.counters["factorizations"] = last.factorizations;
  state.counters["mesh_s"] = last.mesh_seconds;
  state.counters["solve_s"] = last.solve_seconds;
  state.counters["force_mN"] = last.steps.back().force_N * 1e3;
}

// (model, fidelity): Linear = 0, NeoHookean = 2; Fast = 0, Standard = 1, Fine = 2.
BENCHMARK(BM_ConeIntoSkin)
    ->ArgsProduct({{0, 2}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
