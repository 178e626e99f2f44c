// Speed against accuracy of the two-stage insertion (docs/speed-accuracy.md): paper A's three
// needles in human skin and in the silicone phantom, at each fidelity, on the analytic path, with
// each reduction of the scene planner switched on and off and with two explicit overrides, every
// run compared with a reference run of its scene. Writes speed-accuracy.md and speed-accuracy.svg.
// Run on demand, never from ctest:
//   bench_speed_accuracy [--quick] [--out DIR]
// --quick: human skin only and no fine level (the reference drops to standard, named so).
// --out: where the two files go (default: the source tree's docs/).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "mneedle/design_source.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "speed_accuracy_report.h"

namespace {

using namespace mneedle;
using mneedle::bench::RunOutcome;

namespace fs = std::filesystem;

// Tight Newton tolerance of the reference (the levels use 1e-8).
constexpr double kTightTolerance = 1e-10;

struct Options {
  bool quick = false;
  fs::path out = fs::path(MNEEDLE_SOURCE_ROOT) / "docs";
};

struct Case {
  std::string label;
  std::string group;
  InsertionRunOptions run;
  bool reference = false;
};

struct SceneEntry {
  std::string tissue;  // "skin", "silicone"
  std::string needle;  // file suffix and needle name
  bool axisymmetric() const { return needle == "cylinder"; }
  fs::path file() const {
    return fs::path(MNEEDLE_SOURCE_ROOT) / "designs" / "scenes" /
           ("paper_a_" + tissue + "_" + needle + ".toml");
  }
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      o.quick = true;
    } else if (a == "--out" && i + 1 < argc) {
      o.out = argv[++i];
    } else {
      std::cerr << "usage: bench_speed_accuracy [--quick] [--out DIR]\n";
      std::exit(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  return o;
}

InsertionRunOptions base_options(const Scene& scene, fe::Fidelity fidelity) {
  InsertionRunOptions r;
  r.fidelity = fidelity;
  r.contact = scene.model.contact;
  r.criterion = scene.model.criterion;
  return r;
}

// Largest radius of a body-of-revolution needle (m).
double needle_radius(const PreparedNeedle& needle) {
  return needle.axisymmetric ? needle.axisymmetric->max_radius() : 0.0;
}

Case level(const Scene& scene, const char* label, fe::Fidelity f) {
  return {label, label, base_options(scene, f)};
}

// The contact zone and tip size of a pointed tip's reference, per criterion length: cells of
// L/4 (asking 0.3 L gives the starting boxes' halving at or below it) graded to L/32 at the tip,
// finer than the fine level's own zone (1.2 L, graded to 0.12 L at the tip).
constexpr double kZonePerLength = 0.3;
constexpr double kTipPerLength = 0.03;
// The 3-D references' growth: the fine level's until 2026-12-07 (1.6 since).
constexpr double kReferenceGrowth = 1.35;

// The top layer's criterion length (m; 0 without one).
double criterion_length(const Scene& scene) {
  if (scene.tissue.layers.empty() || !scene.tissue.layers.front().strength) return 0.0;
  return scene.tissue.layers.front().strength->length;
}

// True when the needle's lowest point is a single vertex (a pointed tip: a bevel's, a cone's).
bool pointed(const PreparedNeedle& needle) {
  const auto& v = needle.mesh.vertices;
  if (v.empty()) return false;
  double lowest = v.front()[2];
  for (const auto& p : v) lowest = std::min(lowest, static_cast<double>(p[2]));
  int at_lowest = 0;
  for (const auto& p : v) at_lowest += p[2] <= lowest + 1e-9 ? 1 : 0;
  return at_lowest == 1;
}

std::string format_um(double m) {
  char text[32];
  std::snprintf(text, sizeof text, "%g um", m * 1e6);
  return text;
}

// The finest run affordable on a 2-core machine in a few minutes, with a tight Newton tolerance.
// A bevel: the 3-D model (TET10) at the fine level on the half block (exact by symmetry; the
// table shows the half model against the full one). The cylinder: the axisymmetric model (T6) at
// twice the fine level's resolution; the 3-D model at fine is far coarser than it (2.5 elements
// per radius against 32). --quick: the standard level (bevels) and the fine level (cylinder).
Case reference(const SceneEntry& entry, const Scene& scene, const PreparedNeedle& needle,
               bool quick) {
  Case c;
  c.reference = true;
  c.group = "reference";
  c.run.overrides.tolerance = kTightTolerance;
  if (entry.axisymmetric()) {
    c.run = base_options(scene, fe::Fidelity::Fine);
    c.run.model = PreModel::Axisymmetric;
    c.run.overrides.tolerance = kTightTolerance;
    // Fine: 16 elements per contact radius; twice that here (full mode only).
    if (!quick) c.run.overrides.tip_size_m = needle_radius(needle) / 32.0;
    c.label = std::string(quick ? "fine" : "2 x fine") + ", axisymmetric T6, tolerance 1e-10";
    return c;
  }
  c.run = base_options(scene, quick ? fe::Fidelity::Standard : fe::Fidelity::Fine);
  c.run.model = PreModel::Full3d;
  c.run.overrides.order = 2;
  c.run.overrides.tolerance = kTightTolerance;
  c.label = std::string(quick ? "standard" : "fine") + ", 3-D half TET10, tolerance 1e-10";
  // The references keep the fine level's former, finer grading (docs/model.md, "Fine's growth"),
  // so that fine is measured against something finer than itself.
  if (!quick) {
    c.run.overrides.growth = kReferenceGrowth;
    c.label = "fine graded at 1.35, 3-D half TET10, tolerance 1e-10";
  }
  // A pointed tip under the stress criterion: the contact zone graded down to the tip converges
  // it (docs/validation.md, "The 3-D model under a point load, resolved": 63.4-63.8 um over zones
  // of L/4 and L/8 at growth 1.35); the fine level's own zone is coarser (1.2 L, to 0.12 L at the
  // tip).
  const double length = criterion_length(scene);
  if (!quick && c.run.criterion == PunctureCriterion::Stress && length > 0.0 && pointed(needle)) {
    c.run.overrides.contact_zone_size_m = kZonePerLength * length;
    c.run.overrides.contact_zone_tip_size_m = kTipPerLength * length;
    c.label = "fine graded at 1.35, 3-D half TET10, its tip resolved (zone " +
              format_um(kZonePerLength * length) + ", tip " + format_um(kTipPerLength * length) +
              "), tolerance 1e-10";
  }
  return c;
}

std::vector<Case> cases_for(const SceneEntry& entry, const Scene& scene,
                            const PreparedNeedle& needle, bool quick) {
  using fe::Fidelity;
  std::vector<Case> cases{reference(entry, scene, needle, quick)};
  Case analytic = level(scene, "analytic", Fidelity::Standard);
  analytic.run.model = PreModel::Analytic;
  cases.push_back(analytic);
  // The planner's own choice at each level: axisymmetric for the cylinder, half 3-D for a bevel
  // (whose fine level is graded coarser than the reference, and takes a coarser tip zone where
  // the reference resolves a pointed tip).
  cases.push_back(level(scene, "fast", Fidelity::Fast));
  cases.push_back(level(scene, "standard", Fidelity::Standard));
  if (!quick) cases.push_back(level(scene, "fine", Fidelity::Fine));
  // Each reduction switched off at fast and standard: the cylinder in 3-D (half block), a bevel on
  // the full block.
  for (Fidelity f : {Fidelity::Fast, Fidelity::Standard}) {
    const std::string name = f == Fidelity::Fast ? "fast" : "standard";
    Case off{name, "unreduced", base_options(scene, f)};
    if (entry.axisymmetric()) {
      off.label += ", 3-D half instead of axisymmetric";
      off.run.model = PreModel::Full3d;
    } else {
      off.label += ", full block instead of half";
      off.run.allow_reductions = false;
    }
    cases.push_back(off);
  }
  // Explicit overrides: linear elements (3-D), and the domain cut (the planner cuts no domain
  // itself: a block half as wide, or an axisymmetric cylinder of half the radius, stands in).
  Case tet4{entry.axisymmetric() ? "fast, 3-D half TET4" : "fast, TET4", "override",
            base_options(scene, Fidelity::Fast)};
  tet4.run.overrides.order = 1;
  if (entry.axisymmetric()) tet4.run.model = PreModel::Full3d;
  cases.push_back(tet4);
  Case cut{"standard, domain cut to 0.5x", "override", base_options(scene, Fidelity::Standard)};
  cut.run.overrides.domain_scale = 0.5;
  cases.push_back(cut);
  return cases;
}

double cpu_seconds() {
  return static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
}

std::string describe(const InsertionRun& run) {
  std::ostringstream s;
  s << (run.models_run.empty() ? std::string("none") : run.models_run.front());
  // The planner's reductions that changed the domain (the axisymmetric one shows in the model).
  for (const Reduction& r : run.reductions) {
    if (r.name == "half_model") s << " half";
    if (r.name == "domain_cut") s << " cut";
    if (r.name == "layer_merge") s << " merged";
  }
  if (run.nodes > 0) {
    s << ", "
      << (run.axisymmetric ? "T6"
          : run.order == 1 ? "TET4"
                           : "TET10")
      << ", " << run.nodes << " nodes";
  }
  return s.str();
}

RunOutcome run_case(const SceneEntry& entry, const Scene& scene,
                    const std::vector<PreparedNeedle>& needles, const Case& c) {
  RunOutcome o;
  o.scene = entry.tissue;
  o.needle = entry.needle;
  o.label = c.label;
  o.group = c.group;
  o.is_reference = c.reference;
  const auto wall = std::chrono::steady_clock::now();
  const double cpu = cpu_seconds();
  try {
    const InsertionRun run = run_insertion(scene, needles, c.run);
    const NeedleRun& n = run.needles.front();
    if (n.puncture) {
      o.puncture_depth_m = n.puncture->depth_m;
      o.puncture_force_N = n.puncture->force_N;
    }
    std::vector<bench::CurvePoint> curve;
    for (const RunPoint& p : n.curve) curve.push_back({p.depth_m, p.force_N});
    o.probe_force_N = bench::force_at(curve, bench::kProbeDepth_m);
    o.model = describe(run);
  } catch (const std::exception& e) {
    o.error = e.what();
  }
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
  o.cpu_seconds = cpu_seconds() - cpu;
  return o;
}

std::string first_line_of(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0) {
      const auto colon = line.find(':');
      std::string v = colon == std::string::npos ? line : line.substr(colon + 1);
      while (!v.empty() && v.front() == ' ') v.erase(v.begin());
      return v;
    }
  return "unknown";
}

std::string load_average() {
  double load[3] = {0.0, 0.0, 0.0};
  if (getloadavg(load, 3) != 3) return "unknown";
  char b[64];
  std::snprintf(b, sizeof b, "%.2f / %.2f / %.2f", load[0], load[1], load[2]);
  return b;
}

std::string machine() {
  std::ostringstream s;
  s << first_line_of("/proc/cpuinfo", "model name") << ", " << std::thread::hardware_concurrency()
    << " logical cores, " << first_line_of("/proc/meminfo", "MemTotal") << " RAM";
  return s.str();
}

std::string today() {
  const std::time_t t = std::time(nullptr);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return b;
}

std::string group_summary(const std::vector<RunOutcome>& runs) {
  std::map<std::string, std::vector<std::pair<double, double>>> by_group;  // time, worst error
  for (const RunOutcome& r : runs) {
    const RunOutcome* ref = bench::reference_for(runs, r);
    if (r.is_reference || !r.error.empty() || ref == nullptr) continue;
    const auto worst = bench::worst_error(bench::errors_against(r, *ref));
    if (worst) by_group[r.group].push_back({r.seconds, *worst});
  }
  std::ostringstream s;
  s << "| Group | Runs | Median time [s] | Median worst error % | Largest worst error % |\n"
       "|---|--:|--:|--:|--:|\n";
  for (const char* g : {"analytic", "fast", "standard", "fine", "unreduced", "override"}) {
    auto it = by_group.find(g);
    if (it == by_group.end()) continue;
    std::vector<double> t, e;
    for (const auto& [time, error] : it->second) t.push_back(time), e.push_back(error);
    std::sort(t.begin(), t.end());
    std::sort(e.begin(), e.end());
    char b[160];
    std::snprintf(b, sizeof b, "| %s | %zu | %.3g | %.3g | %.3g |\n", g, t.size(), t[t.size() / 2],
                  e[e.size() / 2] * 100.0, e.back() * 100.0);
    s << b;
  }
  return s.str();
}

std::string markdown(const std::vector<RunOutcome>& runs, const Options& o, double total,
                     const std::string& load_before, const std::string& load_after) {
  std::ostringstream s;
  s << "# Speed against accuracy\n\n"
       "<!-- Generated by bench/speed_accuracy.cpp; do not edit by hand: regenerate. -->\n\n"
       "What each fidelity level, the analytic path, each reduction of the scene planner and two "
       "explicit overrides cost, and what they give up, on paper A's three needles (sharp bevel, "
       "blunt bevel, flat cylinder; 230 µm, bore 90 µm) in human skin and in the silicone "
       "phantom (`designs/scenes/paper_a_*.toml`, each scene's criterion: stress in skin, "
       "pressure in the silicone; sticking contact). Each run is the whole two-stage insertion "
       "(`run_insertion`): the pre-puncture model until the criterion fires, then the "
       "post-puncture loads. In skin the analytic path takes the stress criterion as a plate "
       "pressed at one point (docs/model.md, \"The stress criterion on the analytic path\"): "
       "the sharp bevel runs, the blunt bevel and the cylinder (flat ends) are errors that say "
       "so.\n\n"
       "Errors are relative to the **reference** row of the same tissue and needle, the finest "
       "run this 2-core machine affords in a few minutes, with a Newton tolerance of 1e-10 "
       "instead of 1e-8. A bevel: "
    << (o.quick ? "the standard level (this was a `--quick` run: no fine level)"
                : "the fine level graded at 1.35 (fine's own growth until 2026-12-07, 1.6 since: "
                  "docs/model.md, \"Fine's growth\")")
    << ", 3-D, TET10, on the half block (exact by symmetry)"
    << (o.quick ? ""
                : ", so that each fine row shows fine's own error; a pointed tip under the "
                  "stress criterion (the sharp bevel in skin) also gets a "
                  "finer contact zone than the fine level's own, 0.3 L graded down to 0.03 L at "
                  "the tip (L the criterion's length; docs/validation.md, \"The 3-D model under "
                  "a point load, resolved\")")
    << ". The cylinder: the axisymmetric model (T6) at "
    << (o.quick ? "the fine level" : "twice the fine level's resolution (32 elements per radius)")
    << ", finer than any affordable 3-D mesh. "
    << (o.quick
            ? "No reference is mesh-converged in a `--quick` run"
            : "In skin the sharp bevel's reference is mesh-converged within 1-2 % and the "
              "blunt bevel's within 2 % (its flat in cells of 2 L graded at 1.35 reads 85.7 µm, "
              "in cells of L and of 5 µm 84.0 and 85.1 µm; docs/validation.md, \"How fine the "
              "flat must be\")")
    << "; the others' own discretisation error is not in the table. F(200 µm) is the force on "
       "the run's "
       "curve at 200 µm, post-puncture when the needle has punctured before. The error plotted "
       "is the worst of the three columns.\n\n"
       "Reductions: *axisymmetric* (the planner's choice for the cylinder) is compared with the "
       "3-D model (half block), *half model* (its choice for a bevel) with the full block. The "
       "planner's *domain cut* keeps 10 x (needle radius + insertion depth) around the needles "
       "and *layer merge* joins layers deeper than that: both reach past these blocks, so "
       "neither fires here (the \"What ran\" column would say *cut* or *merged*); the *domain "
       "cut* rows instead shrink the block laterally to half (`domain_scale = 0.5`) to show "
       "what a cut costs. Time is wall time of `run_insertion`; CPU is the "
       "process CPU time over the same call (all threads).\n\n";
  s << "Regenerate (about " << static_cast<int>(total / 60.0 + 0.5) << " min):\n\n"
    << "```sh\ncmake --build --preset release --target bench_speed_accuracy\n"
    << "build/release/bench/bench_speed_accuracy" << (o.quick ? " --quick" : "")
    << "   # --out DIR\n"
    << "```\n\n";
  s << "Machine: " << machine() << "; run " << today() << ", total " << static_cast<int>(total)
    << " s; load average (1/5/15 min) " << load_before << " before, " << load_after
    << " after (a load above the core count means other work shared the machine: wall times are "
       "then upper bounds, CPU times less so).\n\n";
  s << "![error against time](speed-accuracy.svg)\n\n";
  s << "## By group\n\n" << group_summary(runs) << "\n";
  s << "## Every run\n\n" << bench::markdown_table(runs) << "\n";
  return s.str();
}

void write(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

void report(const RunOutcome& r) {
  std::fprintf(stderr, "%-8s %-11s %-48s %8.2f s  %s\n", r.scene.c_str(), r.needle.c_str(),
               r.label.c_str(), r.seconds, r.error.empty() ? r.model.c_str() : r.error.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  const auto start = std::chrono::steady_clock::now();
  const std::string load_before = load_average();
  std::vector<SceneEntry> scenes;
  for (const char* tissue : {"skin", "silicone"}) {
    if (options.quick && std::string(tissue) != "skin") continue;
    for (const char* needle : {"sharp_bevel", "blunt_bevel", "cylinder"})
      scenes.push_back({tissue, needle});
  }
  try {
    const PluginRegistry registry = PluginRegistry::discover();
    std::vector<RunOutcome> runs;
    for (const SceneEntry& entry : scenes) {
      Scene scene = load_scene(entry.file());
      // Messages name the scene as the repository does, not by this checkout's absolute path.
      scene.source_name = fs::relative(entry.file(), MNEEDLE_SOURCE_ROOT).string();
      const std::vector<PreparedNeedle> needles = prepare_needles(registry, scene);
      for (Case c : cases_for(entry, scene, needles.front(), options.quick)) {
        runs.push_back(run_case(entry, scene, needles, c));
        report(runs.back());
        if (c.reference && !runs.back().error.empty()) {
          // Without a reference the scene has no errors at all: keep the failure as a row and
          // fall back to the level's own Newton tolerance.
          runs.back().is_reference = false;
          c.run.overrides.tolerance.reset();
          c.label += " failed; tolerance 1e-8 instead";
          runs.push_back(run_case(entry, scene, needles, c));
          report(runs.back());
        }
      }
    }
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fs::create_directories(options.out);
    write(options.out / "speed-accuracy.md",
          markdown(runs, options, total, load_before, load_average()));
    plot::write_svg(options.out / "speed-accuracy.svg", bench::speed_accuracy_figure(runs));
    std::fprintf(stderr, "total %.1f s; wrote %s\n", total,
                 (options.out / "speed-accuracy.md").c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_speed_accuracy: %s\n", e.what());
    return 1;
  }
  return 0;
}
