#include <benchmark/benchmark.h>

#include <cmath>

#include "mneedle/needle/mesh.h"

namespace {

// A closed cylinder of n segments around, as a stand-in for a needle shaft.
mneedle::TriangleMesh cylinder(int n) {
  mneedle::TriangleMesh m;
  const double pi = std::acos(-1.0);
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < n; ++i)
      m.vertices.push_back({std::cos(2 * pi * i / n), std::sin(2 * pi * i / n), double(ring)});
  const auto c0 = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.push_back({0, 0, 0});
  m.vertices.push_back({0, 0, 1});
  for (std::uint32_t i = 0; i < std::uint32_t(n); ++i) {
    const std::uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, j + n});
    m.triangles.push_back({i, j + n, i + n});
    m.triangles.push_back({c0, j, i});
    m.triangles.push_back({c0 + 1, i + n, j + n});
  }
  return m;
}

void BM_SignedVolume(benchmark::State& state) {
  const auto mesh = cylinder(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(mneedle::signed_volume(mesh));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(mesh.triangles.size()));
}
BENCHMARK(BM_SignedVolume)->Arg(64)->Arg(1024)->Arg(16384);

}  // namespace

BENCHMARK_MAIN();
