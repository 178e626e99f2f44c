// Hot paths and limits (docs/performance.md, "Hot paths"): the closed-form indentation, slicing and
// classification of needle meshes up to 5 million faces (generated here, written to a temporary
// binary STL and read back through load + validate, the path of `mneedle inspect`), and the 3-D
// tissue problem's memory growth with size (for the largest problem that fits in 24 GiB). Peak
// memory: the process's getrusage maximum resident set, so run one size per process for clean
// figures:
//   build/<dir>/bench/bench_extremes --benchmark_filter='LargeStl/5000000'
// Figures: docs/performance.md, "Hot paths, a 5-million-face STL and the largest 3-D problem".
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "mneedle/fe/indentation3d.h"
#include "mneedle/geometry/surface_groups.h"
#include "mneedle/insertion/analytic_indentation.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/needle/mesh_validation.h"
#include "mneedle/strength/section_table.h"

namespace {

using mneedle::TriangleMesh;
constexpr double kPi = std::numbers::pi;

double peak_rss_gib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / (1024.0 * 1024.0);  // ru_maxrss is in KiB
}

// Closed cone (tip at the origin, body to +z): `segments` around, `rings` along the slope, plus a
// base fan; 2 * segments * rings faces in all (the first ring is a fan at the tip).
TriangleMesh cone_mesh(int segments, int rings, double radius = 115e-6, double length = 1e-3) {
  TriangleMesh m;
  m.vertices.push_back({0.0, 0.0, 0.0});
  for (int k = 1; k <= rings; ++k) {
    const double t = static_cast<double>(k) / rings;
    for (int i = 0; i < segments; ++i) {
      const double phi = 2 * kPi * i / segments;
      m.vertices.push_back({t * radius * std::cos(phi), t * radius * std::sin(phi), t * length});
    }
  }
  const auto at = [&](int k, int i) {
    return static_cast<std::uint32_t>(1 + (k - 1) * segments + (i % segments));
  };
  for (int i = 0; i < segments; ++i) m.triangles.push_back({0, at(1, i + 1), at(1, i)});
  for (int k = 1; k < rings; ++k)
    for (int i = 0; i < segments; ++i) {
      m.triangles.push_back({at(k, i), at(k, i + 1), at(k + 1, i + 1)});
      m.triangles.push_back({at(k, i), at(k + 1, i + 1), at(k + 1, i)});
    }
  m.vertices.push_back({0.0, 0.0, length});
  const auto centre = static_cast<std::uint32_t>(m.vertices.size() - 1);
  for (int i = 0; i < segments; ++i)
    m.triangles.push_back({centre, at(rings, i), at(rings, i + 1)});
  return m;
}

mneedle::Tissue paper_a_skin() {
  mneedle::Tissue t;
  t.size = {3e-3, 3e-3, 1.15e-3};
  const auto layer = [](const char* name, double thickness, double E) {
    mneedle::TissueLayer l;
    l.name = name;
    l.thickness = thickness;
    l.material.youngs_modulus = E;
    l.material.poisson_ratio = 0.4;
    return l;
  };
  t.layers = {layer("stratum corneum", 20e-6, 1e9), layer("epidermis", 100e-6, 0.134e6),
              layer("dermis", 1030e-6, 0.08e6)};
  return t;
}

// Paper A's cone in paper A's skin, 200 depths to 200 um.
void BM_AnalyticIndentation(benchmark::State& state) {
  const auto needle = mneedle::fe::AxisymmetricNeedle::cone(std::atan(0.115), 115e-6);
  std::vector<double> depths;
  for (int i = 1; i <= 200; ++i) depths.push_back(200e-6 * i / 200);
  const mneedle::Tissue skin = paper_a_skin();
  for (auto _ : state)
    benchmark::DoNotOptimize(mneedle::analytic_indentation(skin, needle, depths));
  state.counters["depths"] = 200;
}
BENCHMARK(BM_AnalyticIndentation)->Unit(benchmark::kMillisecond);

// Slicing: section table (201 slices) and the equivalent needle (201 slices) of a cone.
void BM_Slicing(benchmark::State& state) {
  const TriangleMesh mesh = cone_mesh(static_cast<int>(state.range(0)), 64);
  for (auto _ : state) {
    benchmark::DoNotOptimize(mneedle::SectionTable::from_mesh(mesh, 200));
    benchmark::DoNotOptimize(mneedle::equivalent_axisymmetric_needle(mesh, 1e-3, 200));
  }
  state.counters["faces"] = static_cast<double>(mesh.triangles.size());
}
BENCHMARK(BM_Slicing)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond)->Iterations(1);

// Classification of every face into the load groups.
void BM_Classification(benchmark::State& state) {
  const TriangleMesh mesh = cone_mesh(static_cast<int>(state.range(0)), 256);
  for (auto _ : state) benchmark::DoNotOptimize(mneedle::classify_surface(mesh));
  state.counters["faces"] = static_cast<double>(mesh.triangles.size());
}
BENCHMARK(BM_Classification)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond);

// The inspect path on a large STL: write, load (assimp + weld), validate (CGAL: closed,
// manifold, orientation, self-intersections), classify, slice. Arg: faces (approximately).
void BM_LargeStl(benchmark::State& state) {
  const auto faces = static_cast<double>(state.range(0));
  const int segments = static_cast<int>(std::sqrt(faces / 2.0));
  const int rings = static_cast<int>(faces / (2.0 * segments));
  const auto file = std::filesystem::temp_directory_path() /
                    ("mneedle_bench_" + std::to_string(state.range(0)) + ".stl");
  mneedle::write_stl_binary(cone_mesh(segments, rings), file, 1e-3, "bench_extremes");
  for (auto _ : state) {
    const TriangleMesh mesh = mneedle::load_mesh(file, 1e-3);
    const auto validation = mneedle::validate_mesh(mesh);
    if (!validation.valid) state.SkipWithError(validation.errors.front().c_str());
    benchmark::DoNotOptimize(mneedle::classify_surface(mesh));
    benchmark::DoNotOptimize(mneedle::SectionTable::from_mesh(mesh, 200));
    state.counters["faces"] = static_cast<double>(mesh.triangles.size());
  }
  std::filesystem::remove(file);
  state.counters["peak_rss_GiB"] = peak_rss_gib();
}
BENCHMARK(BM_LargeStl)
    ->Arg(50'000)
    ->Arg(500'000)
    ->Arg(5'000'000)
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// 3-D linear flat punch (TET10) on a homogeneous block at a growing size: meshing, assembly,
// one factorisation, contact; nodes, dofs and the process's peak memory. Arg: tip element size
// in um (smaller: larger problem).
void BM_Tissue3dMemory(benchmark::State& state) {
  using namespace mneedle::fe;
  using mneedle::MaterialModel;
  TissueBlockSpec block;
  block.size_x = block.size_y = 2e-3;
  block.layers = {{"block", 1e-3, {MaterialModel::Linear, 1e5, 0.45, 0.0, 0.0}}};
  Simulation3dOptions options;
  options.fidelity = Fidelity::Standard;
  options.depth = 2e-6;
  options.steps = 1;
  options.overrides.tip_size_m = static_cast<double>(state.range(0)) * 1e-6;
  const std::vector<Needle3d> needles{{"punch", cone_mesh(48, 4, 100e-6, 1e-3), 0.0, 0.0}};
  for (auto _ : state) {
    const Simulation3dResult r = simulate_3d(block, needles, options);
    state.counters["nodes"] = r.nodes;
    state.counters["dofs"] = 3.0 * r.nodes;
    state.counters["factorization_s"] = r.timing.factorization_s;
    state.counters["F_N"] = r.steps.back().needles.at(0).force_N;
  }
  state.counters["peak_rss_GiB"] = peak_rss_gib();
}
BENCHMARK(BM_Tissue3dMemory)->Arg(40)->Arg(20)->Arg(10)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
