// Bed-of-nails study (docs/performance.md, "Array spacing"): force per needle of a 2 x 2 array of
// paper A's flat-ended 230 um needles pressed 100 um into its silicone (E 0.2 MPa, nu 0.49,
// linear), against the same needle alone, as the gap between neighbouring needles shrinks. For a
// flat punch in linear tissue the mean contact pressure is proportional to the force, so the
// pressure-criterion puncture depth scales with 1 / (force ratio). Olatunji et al. found the
// spacing to matter only below ~150 um. Figures in docs/performance.md, "Array spacing
// (bed-of-nails) study". Run: bench_array_spacing [--benchmark_filter=]
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "mneedle/insertion/insertion_run.h"
#include "mneedle/scene/scene.h"

namespace {

using namespace mneedle;

constexpr double kRadius = 115e-6;
constexpr double kDepth = 100e-6;

TriangleMesh cylinder(double r, double l, int segments = 48) {
  TriangleMesh m;
  m.vertices.push_back({0, 0, 0});
  m.vertices.push_back({0, 0, l});
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * M_PI * i / segments;
    m.vertices.push_back({r * std::cos(a), r * std::sin(a), 0});
    m.vertices.push_back({r * std::cos(a), r * std::sin(a), l});
  }
  auto lo = [](int i) { return static_cast<std::uint32_t>(2 + 2 * i); };
  auto hi = [](int i) { return static_cast<std::uint32_t>(3 + 2 * i); };
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    m.triangles.push_back({0, lo(j), lo(i)});
    m.triangles.push_back({1, hi(i), hi(j)});
    m.triangles.push_back({lo(i), lo(j), hi(j)});
    m.triangles.push_back({lo(i), hi(j), hi(i)});
  }
  return m;
}

// The block is as wide as paper A's 1600 um array needs plus 1.5 mm around it, whatever the
// spacing, so that only the spacing changes between the runs.
Scene scene(int needles, double pitch) {
  std::string text = R"([tissue]
size = ["4000 um", "4000 um", "1500 um"]
[[tissue.layers]]
name = "silicone"
material = { model = "linear", E = "0.2 MPa", nu = 0.49 }
)";
  for (int i = 0; i < needles; ++i) {
    const double x = needles == 1 ? 0.0 : (i % 2 == 0 ? -0.5 : 0.5) * pitch;
    const double y = needles == 1 ? 0.0 : (i / 2 == 0 ? -0.5 : 0.5) * pitch;
    text += "[[needles]]\nname = \"n" + std::to_string(i) +
            "\"\ngeometry = { plugin = \"cylinder\", diameter = \"230 um\" }\nat = [\"" +
            std::to_string(x * 1e6) + " um\", \"" + std::to_string(y * 1e6) + " um\"]\n";
  }
  text += "[insertion]\ndepth = \"" + std::to_string(kDepth * 1e6) +
          " um\"\n[model]\nfidelity = \"fast\"\noutputs = [\"force_curve\", \"puncture\"]\n";
  return parse_scene(text, "bench_array_spacing");
}

InsertionRun run(int needles, double pitch, fe::Fidelity fidelity) {
  const Scene s = scene(needles, pitch);
  std::vector<PreparedNeedle> prepared;
  for (const NeedleSpec& spec : s.needles) {
    PreparedNeedle n;
    n.name = spec.name;
    n.mesh = cylinder(kRadius, 1e-3);
    n.x = spec.at[0];
    n.y = spec.at[1];
    n.mirror_symmetric_y0 = n.mirror_symmetric_x0 = true;  // the arrays run as quarter models
    prepared.push_back(n);
  }
  InsertionRunOptions o;
  o.fidelity = fidelity;
  o.model = PreModel::Full3d;  // the single needle on the same 3-D model as the arrays
  o.steps = 10;
  return run_insertion(s, prepared, o);
}

// Pre-puncture force at the insertion depth (no fracture data: the FE runs to full depth).
double pre_force(const NeedleRun& n) {
  double f = 0.0;
  for (const RunPoint& p : n.curve)
    if (p.stage == Stage::Pre) f = p.force_N;
  return f;
}

void BM_ArraySpacing(benchmark::State& state) {
  const double gap = static_cast<double>(state.range(0)) * 1e-6;  // edge to edge
  const auto fidelity = state.range(1) == 0 ? fe::Fidelity::Fast : fe::Fidelity::Standard;
  const double pitch = gap + 2.0 * kRadius;
  const InsertionRun single = run(1, 0.0, fidelity);
  InsertionRun array;
  for (auto _ : state) array = run(4, pitch, fidelity);
  state.counters["standard"] = static_cast<double>(state.range(1));
  state.counters["gap_um"] = gap * 1e6;
  state.counters["pitch_um"] = pitch * 1e6;
  double per_needle = 0.0;
  for (const NeedleRun& n : array.needles) per_needle += pre_force(n) / 4.0;
  state.counters["force_per_needle_mN"] = per_needle * 1e3;
  state.counters["single_force_mN"] = pre_force(single.needles[0]) * 1e3;
  state.counters["ratio"] = per_needle / pre_force(single.needles[0]);
  state.counters["elements"] = array.elements;
  state.counters["single_elements"] = single.elements;
}

// Gap (um) x fidelity (0 fast, 1 standard).
BENCHMARK(BM_ArraySpacing)
    ->ArgsProduct({{20, 50, 100, 150, 250, 500, 1370},  // 1370: paper A, 1600 um centre to centre
                   {0, 1}})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
