// One sharp-bevel needle (230 um) pressed 200 um into paper A's 3000 x 3000 x 1150 um three-layer
// skin, 3-D, at each fidelity; counters split the time (docs/performance.md, "3-D performance").
#include <benchmark/benchmark.h>

#include <cstdio>
#include <numbers>

#include "../tests/core/fe/needle_meshes.h"
#include "mneedle/fe/indentation3d.h"
#include "mneedle/plugin_host.h"

namespace {

using namespace mneedle::fe;
using mneedle::MaterialModel;

mneedle::TriangleMesh sharp_bevel() {
  try {
    return mneedle::PluginRegistry::discover().generate("sharp_bevel", {{"diameter", 230e-6}});
  } catch (const std::exception& error) {
    std::fprintf(stderr,
                 "bench_fe3d: sharp_bevel plugin unavailable (%s); using a built-in bevel\n",
                 error.what());
    return mneedle::test::bevel_needle(115e-6, std::numbers::pi / 6, 1000e-6, 64);
  }
}

TissueBlockSpec paper_a_skin(MaterialModel model) {
  TissueBlockSpec block;
  block.size_x = block.size_y = 3000e-6;
  block.layers = {{"stratum corneum", 15e-6, {model, 1e9, 0.4, 0.0, 0.0}},
                  {"epidermis", 100e-6, {model, 0.134e6, 0.4, 0.0, 0.0}},
                  {"dermis", 1035e-6, {model, 0.08e6, 0.4, 0.0, 0.0}}};
  return block;
}

void run(benchmark::State& state, MaterialModel model, bool half = false,
         ContactMode contact = ContactMode::Sticking) {
  const auto fidelity = static_cast<Fidelity>(state.range(0));
  const int order = static_cast<int>(state.range(1));
  const std::vector<Needle3d> needles{{"sharp bevel", sharp_bevel(), 0.0, 0.0}};
  Simulation3dOptions options;
  options.fidelity = fidelity;
  options.order = order;
  options.depth = 200e-6;
  options.steps = 10;
  options.half_model = half;
  options.contact = contact;
  Simulation3dResult result;
  for (auto _ : state) result = simulate_3d(paper_a_skin(model), needles, options);
  state.SetLabel(to_string(fidelity) + (order == 1 ? " TET4" : " TET10") + (half ? " half" : "") +
                 (contact == ContactMode::Frictionless ? " frictionless" : ""));
  state.counters["nodes"] = result.nodes;
  state.counters["elements"] = result.elements;
  state.counters["force_N"] = result.steps.back().needles[0].force_N;
  state.counters["mesh_s"] = result.timing.meshing_s;
  state.counters["assembly_s"] = result.timing.assembly_s;
  state.counters["factor_s"] = result.timing.factorization_s;
  state.counters["contact_s"] = result.timing.contact_s;
  state.counters["total_s"] = result.timing.total_s;
  state.counters["factorizations"] = result.timing.factorizations;
  state.counters["captured"] = result.steps.back().needles[0].captured_nodes;
  state.counters["min_dihedral_deg"] = result.quality.min_dihedral_deg;
}

void linear_skin(benchmark::State& state) {
  run(state, MaterialModel::Linear);
}
void st_venant_skin(benchmark::State& state) {
  run(state, MaterialModel::StVenantKirchhoff);
}

// The half model (mirror plane y = 0 through the bevel's axis) and frictionless contact.
void linear_skin_half(benchmark::State& state) {
  run(state, MaterialModel::Linear, true);
}
void linear_skin_frictionless(benchmark::State& state) {
  run(state, MaterialModel::Linear, false, ContactMode::Frictionless);
}

BENCHMARK(linear_skin_half)->ArgsProduct({{0, 1}, {2}})->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(linear_skin_frictionless)
    ->ArgsProduct({{0}, {2}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK(linear_skin)->ArgsProduct({{0, 1, 2}, {2, 1}})->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK(st_venant_skin)->ArgsProduct({{0, 1}, {2, 1}})->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
