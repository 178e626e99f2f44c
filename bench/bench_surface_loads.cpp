// Paper A's post-puncture curve F(z) of a sharp bevel over 100 depths: the designer's loop.
#include <benchmark/benchmark.h>

#include <numbers>
#include <vector>

#include "../tests/core/needle_shapes.h"
#include "mneedle/insertion/surface_loads.h"

namespace {

mneedle::LoadConstants silicone() {
  mneedle::LoadConstants c;
  mneedle::LoadLayer layer;
  layer.youngs_modulus_Pa = 0.2e6;
  layer.poisson_ratio = 0.48;
  c.layers = {layer};
  return c;
}

std::vector<double> hundred_depths() {
  std::vector<double> depths;
  for (int i = 1; i <= 100; ++i) depths.push_back(10e-6 * i);
  return depths;
}

mneedle::TriangleMesh bevel(int segments) {
  mneedle::test::ShapeOptions o;
  o.segments = segments;
  return mneedle::test::sharp_bevel(o, std::numbers::pi / 6.0);
}

// Precompute once, evaluate 100 depths (argument: segments around the axis).
void BM_CurveOf100Depths(benchmark::State& state) {
  const auto mesh = bevel(static_cast<int>(state.range(0)));
  const mneedle::SurfaceLoadModel model(mesh, silicone());
  const auto depths = hundred_depths();
  for (auto _ : state) benchmark::DoNotOptimize(model.curve(depths));
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
}
BENCHMARK(BM_CurveOf100Depths)->Arg(64)->Arg(256)->Arg(1024)->Unit(benchmark::kMillisecond);

// Building the model (per-face data) for one needle.
void BM_BuildModel(benchmark::State& state) {
  const auto mesh = bevel(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(mneedle::SurfaceLoadModel(mesh, silicone()));
}
BENCHMARK(BM_BuildModel)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
