// Axisymmetric insertion benchmark: paper A's cone (base diameter 230 um, length 1000 um)
// pressed 200 um into paper A's three-layer skin (3000 x 3000 x 1150 um block as the
// equal-area cylinder), per fidelity, linear and neo-Hookean layers.
// Run: OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 build/<dir>/bench/bench_axisymmetric
// (MNEEDLE_BENCH_VERBOSE=1 prints every step: depth, force, Newton iterations, contact nodes).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "mneedle/fe/axisymmetric.h"

namespace {

using namespace mneedle::fe;
using mneedle::MaterialModel;

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
  int iterations = 0;
  for (const InsertionStep& s : last.steps) {
    iterations += s.newton_iterations;
    if (std::getenv("MNEEDLE_BENCH_VERBOSE"))
      std::printf("depth %.1f um force %.4f mN iterations %d contacts %d\n", s.depth_m * 1e6,
                  s.force_N * 1e3, s.newton_iterations, s.contact_nodes);
  }
  state.counters["newton_iterations"] = iterations;
}

// (model, fidelity): Linear = 0, NeoHookean = 2; Fast = 0, Standard = 1, Fine = 2.
BENCHMARK(BM_ConeIntoSkin)
    ->ArgsProduct({{0, 2}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Study of the frictionless 60 deg cone against Sneddon (docs: axi-validation.md): the ratio
// F / ((2/pi) E* tan(alpha) d^2) per nu, depth and cylinder scale (args: nu in %, depth in um,
// domain scale in %), standard mesh, linear.
void BM_FrictionlessConeVsSneddon(benchmark::State& state) {
  const double nu = state.range(0) / 100.0, depth = state.range(1) * 1e-6, E = 1e5;
  const double alpha = 3.14159265358979323846 / 3.0;
  MaterialParameters m;
  m.E = E;
  m.nu = nu;
  AxisymmetricProblem p;
  p.layers = {{5e-3, m}};
  p.radius_m = 5e-3;
  p.needle = AxisymmetricNeedle::cone(alpha, 1e-3);
  p.depth_m = depth;
  p.contact = ContactMode::Frictionless;
  p.output_steps = 1;
  p.overrides.domain_scale = state.range(2) / 100.0;
  InsertionResult last;
  for (auto _ : state) last = simulate_axisymmetric(p);
  const double sneddon =
      2.0 / 3.14159265358979323846 * E / (1 - nu * nu) * std::tan(alpha) * depth * depth;
  state.counters["ratio"] = last.steps.back().force_N / sneddon;
  state.counters["nodes"] = static_cast<double>(last.nodes);
}

BENCHMARK(BM_FrictionlessConeVsSneddon)
    ->ArgsProduct({{30, 45}, {10, 100}, {100, 200}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
