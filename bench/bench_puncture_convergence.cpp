// Mesh convergence of the puncture depth and of the force at fixed depths (docs/validation.md,
// "The penetration criterion"; docs/performance.md, "Puncture-depth convergence"). Paper A's
// silicone scenes through run_insertion, the same call `simulate` makes, at fast, standard, fine
// and one further refinement ("finer": fine with 7.5 instead of 5.5 node spacings per needle
// radius at the tip and a growth of 1.25 instead of 1.35).
// Run on demand, never from ctest (finer: several minutes and several GB per needle):
//   bench_puncture_convergence [--criterion penetration|pressure|energy|stress]
//       [--no-finer] [--finest] [--refine N] [--tissue silicone|skin] [--frictionless] [--model3d]
//       [--contact-zone UM] [--zone-reach K] [--tip-size UM] [--resolution N]
//       [--level LABEL=FIDELITY,SPACINGS,GROWTH,REFINE[,STEPS]]... [sharp_bevel] [blunt_bevel]
//       [cylinder] [cone]   (none: sharp_bevel; cone: a solid 15-degree cone, 230 um, in the
//       sharp bevel's scene)
// --refine N: every level's grid built 2^N coarser and bisected back along the needle's path
// (refinement_levels; 0 is the plain tensor grid; default: the level's, docs/model.md "Tissue
// block and mesh"); --model3d: the 3-D model even where the planner would run the axisymmetric one;
// --finest: a level beyond finer (10.5 spacings per radius, growth 1.2); --contact-zone UM: the
// top layer around the needle's first contact bisected to UM micrometres in the 3-D model
// (FidelityOverrides::contact_zone_size_m, docs/validation.md "The stress criterion in skin");
// --zone-reach K: its lateral reach in multiples of max(UM, the criterion length)
// (contact_zone_reach); --tip-size UM: inside the zone, elements graded down to UM toward a
// pointed first contact (contact_zone_tip_size_m); --through-top N: N elements through the top
// layer's thickness (elements_through_top); --resolution N: the needle plugin's polygon segments
// (default 64).
// --level LABEL=FIDELITY,SPACINGS,GROWTH,REFINE[,STEPS] (repeatable): run these levels instead of
// the fidelities (errors are against the last one listed; --refine does not apply; SPACINGS are
// TET10 node spacings per radius), each the given fidelity with its tip size, growth,
// refinement_levels and, given STEPS, its depth steps per horizon rung replaced
// (a sweep of the choices behind a fidelity level, docs/validation.md "The penetration
// criterion").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "mneedle/base/memory.h"
#include "mneedle/design_source.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"

namespace {

using namespace mneedle;
namespace fs = std::filesystem;

// Depths where every level is still before its puncture (the sharp bevel fires at 170-190 um
// with the penetration criterion) and that are depth steps of every level on the 200 um rung
// (20, 10 and 5 um steps): the force is compared there without interpolation error. The
// criterion's value at a depth moves by the same percentage (F_p is a closed form of depth).
constexpr double kProbeDepths_m[] = {40e-6, 100e-6, 160e-6};

struct Options {
  PunctureCriterion criterion = PunctureCriterion::Penetration;
  bool finer = true;
  std::optional<int> refine;  // refinement_levels of every level; empty: each level's default
  bool finest = false;
  std::string tissue = "silicone";  // paper_a_<tissue>_<needle>.toml
  std::optional<Contact> contact;   // empty: the scene's
  bool full3d = false;              // --model3d: the 3-D model even where the planner would not
  std::optional<double>
      contact_zone_m;                // --contact-zone UM: FidelityOverrides::contact_zone_size_m
  std::optional<double> zone_reach;  // --zone-reach K: FidelityOverrides::contact_zone_reach
  std::optional<int> through_top;    // --through-top N: FidelityOverrides::elements_through_top
  std::optional<double> tip_size_m;  // --tip-size UM: FidelityOverrides::contact_zone_tip_size_m
  std::optional<int> resolution;     // --resolution N: the plugin's segments
  std::vector<std::string> needles;
  // --level LABEL=FIDELITY,SPACINGS,GROWTH,REFINE[,STEPS]: levels of one's own instead of the
  // fidelities (a fidelity's steps and layers through the top, with node spacings per needle radius
  // at the tip, growth ratio and refinement_levels replaced), for sweeps of the mesh choices behind
  // a fidelity level.
  struct Custom {
    std::string label;
    fe::Fidelity base = fe::Fidelity::Fine;
    double spacings = 0.0, growth = 0.0;
    int refine = 0;
    int steps = 0;  // depth steps per horizon rung; 0: the fidelity's
  };
  std::vector<Custom> custom;
};

struct Level {
  std::string label;
  InsertionRunOptions run;
};

struct Outcome {
  std::string label;
  std::optional<double> depth_m, force_N;
  bool at_first_contact = false;
  std::vector<std::optional<double>> probe_force_N;  // pre-puncture force at kProbeDepths_m
  std::vector<RunPoint> curve;                       // pre-puncture points
  std::size_t nodes = 0;
  double seconds = 0.0;
  double peak_gb = 0.0;  // the process's peak so far: the levels run in order, finest last
  std::string error;
  std::string reductions;  // the planner's, as run
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--no-finer") {
      o.finer = false;
    } else if (a == "--refine" && i + 1 < argc) {
      o.refine = std::atoi(argv[++i]);
    } else if (a == "--tissue" && i + 1 < argc) {
      o.tissue = argv[++i];
    } else if (a == "--level" && i + 1 < argc) {
      const std::string spec = argv[++i];
      Options::Custom c;
      const auto eq = spec.find('=');
      // FIDELITY,SPACINGS,GROWTH,REFINE then, optionally, ",STEPS": every character consumed.
      char fidelity[16] = {};
      int used = -1, more = -1;
      const char* rest = eq == std::string::npos ? "" : spec.c_str() + eq + 1;
      bool parsed = std::sscanf(rest, "%15[a-z],%lf,%lf,%d%n", fidelity, &c.spacings, &c.growth,
                                &c.refine, &used) == 4 &&
                    used > 0;
      if (parsed && rest[used] != '\0')
        parsed = std::sscanf(rest + used, ",%d%n", &c.steps, &more) == 1 && more > 0 &&
                 rest[used + more] == '\0' && c.steps >= 1;
      const std::string f = fidelity;
      if (!parsed || (f != "fast" && f != "standard" && f != "fine") || !(c.spacings > 0.0) ||
          !(c.growth >= 1.0) || c.refine < 0) {
        std::cerr << "bench_puncture_convergence: --level wants "
                     "LABEL=fast|standard|fine,SPACINGS,GROWTH,REFINE[,STEPS] (spacings > 0, "
                     "growth >= 1, refine >= 0, steps >= 1 when given), got '"
                  << spec << "'\n";
        std::exit(2);
      }
      c.base = fe::parse_fidelity(f);
      c.label = spec.substr(0, eq);
      o.custom.push_back(c);
    } else if (a == "--finest") {
      o.finest = true;
    } else if (a == "--model3d") {
      o.full3d = true;
    } else if (a == "--contact-zone" && i + 1 < argc) {
      o.contact_zone_m = std::atof(argv[++i]) * 1e-6;
    } else if (a == "--through-top" && i + 1 < argc) {
      o.through_top = std::atoi(argv[++i]);
    } else if (a == "--tip-size" && i + 1 < argc) {
      o.tip_size_m = std::atof(argv[++i]) * 1e-6;
    } else if (a == "--zone-reach" && i + 1 < argc) {
      o.zone_reach = std::atof(argv[++i]);
    } else if (a == "--resolution" && i + 1 < argc) {
      o.resolution = std::atoi(argv[++i]);
    } else if (a == "--frictionless") {
      o.contact = Contact::Frictionless;
    } else if (a == "--criterion" && i + 1 < argc) {
      const std::string c = argv[++i];
      if (c == "penetration")
        o.criterion = PunctureCriterion::Penetration;
      else if (c == "pressure")
        o.criterion = PunctureCriterion::Pressure;
      else if (c == "energy")
        o.criterion = PunctureCriterion::Energy;
      else if (c == "stress")
        o.criterion = PunctureCriterion::Stress;
      else {
        std::cerr << "bench_puncture_convergence: unknown criterion '" << c << "'\n";
        std::exit(2);
      }
    } else if (a == "sharp_bevel" || a == "blunt_bevel" || a == "cylinder" || a == "cone") {
      o.needles.push_back(a);
    } else {
      std::cerr << "usage: bench_puncture_convergence [--criterion C] [--no-finer] [--finest] "
                   "[--refine N] [--tissue silicone|skin] [--frictionless] [--model3d] "
                   "[--contact-zone UM] [--zone-reach K] [--tip-size UM] [--through-top N] "
                   "[--resolution N] "
                   "[--level LABEL=FIDELITY,SPACINGS,GROWTH,REFINE[,STEPS]]... [sharp_bevel] "
                   "[blunt_bevel] "
                   "[cylinder] [cone]\n";
      std::exit(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  if (o.needles.empty()) o.needles = {"sharp_bevel"};
  return o;
}

// Largest distance of the needle's surface from its axis (m): the radius the mesh is sized by.
double needle_radius(const PreparedNeedle& n) {
  double r = 0.0;
  for (const auto& v : n.mesh.vertices) r = std::max(r, std::hypot(v[0], v[1]));
  return r;
}

std::vector<Level> levels(const Scene& scene, const PreparedNeedle& needle, const Options& o) {
  std::vector<Level> out;
  auto base = [&](fe::Fidelity f) {
    InsertionRunOptions r;
    r.fidelity = f;
    r.contact = o.contact.value_or(scene.model.contact);
    r.criterion = o.criterion;
    r.overrides.refinement_levels = o.refine;
    r.overrides.contact_zone_size_m = o.contact_zone_m;
    r.overrides.contact_zone_reach = o.zone_reach;
    r.overrides.contact_zone_tip_size_m = o.tip_size_m;
    r.overrides.elements_through_top = o.through_top;
    if (o.full3d) r.model = PreModel::Full3d;
    return r;
  };
  if (!o.custom.empty()) {
    const double block = std::max(scene.tissue.size[0], scene.tissue.size[1]);
    const double radius = needle_radius(needle);
    for (const Options::Custom& c : o.custom) {
      // The base fidelity's steps and cells through the top; the tip size (as spacings per
      // radius: the fine level's size scaled), the growth and the refinement are the sweep's.
      Level l{c.label, base(c.base)};
      l.run.overrides.tip_size_m =
          fe::mesh_sizing(fe::Fidelity::Fine, 2, radius, block).fine_size * 5.5 / c.spacings;
      l.run.overrides.growth = c.growth;
      l.run.overrides.refinement_levels = c.refine;
      if (c.steps > 0) l.run.overrides.steps = c.steps;
      out.push_back(l);
    }
    return out;
  }
  out.push_back({"fast", base(fe::Fidelity::Fast)});
  out.push_back({"standard", base(fe::Fidelity::Standard)});
  out.push_back({"fine", base(fe::Fidelity::Fine)});
  if (o.finer) {
    // One step beyond fine: 7.5 instead of 5.5 node spacings per radius, growth 1.25 (not 1.35).
    Level finer{"finer", base(fe::Fidelity::Fine)};
    const double block = std::max(scene.tissue.size[0], scene.tissue.size[1]);
    const double fine_size =
        fe::mesh_sizing(fe::Fidelity::Fine, 2, needle_radius(needle), block).fine_size;
    finer.run.overrides.tip_size_m = fine_size * 5.5 / 7.5;
    finer.run.overrides.growth = 1.25;
    out.push_back(finer);
  }
  if (o.finest) {
    // Two steps beyond fine: 10.5 spacings per radius, growth 1.2 (a graded mesh's level).
    Level finest{"finest", base(fe::Fidelity::Fine)};
    const double block = std::max(scene.tissue.size[0], scene.tissue.size[1]);
    finest.run.overrides.tip_size_m =
        fe::mesh_sizing(fe::Fidelity::Fine, 2, needle_radius(needle), block).fine_size * 5.5 / 10.5;
    finest.run.overrides.growth = 1.2;
    out.push_back(finest);
  }
  return out;
}

// Linear interpolation on the pre-puncture points of the curve; empty before the first one and
// past the last one.
template <class Get>
std::optional<double> at_depth(const std::vector<RunPoint>& curve, double depth, Get get) {
  const RunPoint* prev = nullptr;
  for (const RunPoint& p : curve) {
    if (p.stage != Stage::Pre) break;
    if (p.depth_m >= depth) {
      if (prev == nullptr) return p.depth_m == depth ? std::optional<double>(get(p)) : std::nullopt;
      const double t = (depth - prev->depth_m) / (p.depth_m - prev->depth_m);
      return get(*prev) + t * (get(p) - get(*prev));
    }
    prev = &p;
  }
  return std::nullopt;
}

Outcome run_level(const Scene& scene, const std::vector<PreparedNeedle>& needles, const Level& l) {
  Outcome o;
  o.label = l.label;
  const auto start = std::chrono::steady_clock::now();
  try {
    const InsertionRun run = run_insertion(scene, needles, l.run);
    const NeedleRun& n = run.needles.front();
    if (n.puncture) {
      o.depth_m = n.puncture->depth_m;
      o.force_N = n.puncture->force_N;
      o.at_first_contact = n.puncture->at_first_contact;
    }
    for (double d : kProbeDepths_m)
      o.probe_force_N.push_back(at_depth(n.curve, d, [](const RunPoint& p) { return p.force_N; }));
    for (const RunPoint& p : n.curve)
      if (p.stage == Stage::Pre) o.curve.push_back(p);
    o.nodes = static_cast<std::size_t>(run.nodes);
    for (const Reduction& r : run.reductions) o.reductions += " " + r.name + ": " + r.detail + ";";
  } catch (const std::exception& e) {
    o.error = e.what();
  }
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.peak_gb = static_cast<double>(peak_memory_bytes()) / 1e9;
  return o;
}

std::string percent_against(std::optional<double> v, std::optional<double> ref) {
  if (!v || !ref || *ref == 0.0) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%+.1f %%", 100.0 * (*v / *ref - 1.0));
  return b;
}

std::string number(std::optional<double> v, double scale, const char* format) {
  if (!v) return "-";
  char b[32];
  std::snprintf(b, sizeof b, format, *v * scale);
  return b;
}

void print_table(const std::string& needle, const std::vector<Outcome>& runs) {
  // The finest level that ran is the reference.
  const auto finest =
      std::find_if(runs.rbegin(), runs.rend(), [](const Outcome& r) { return r.error.empty(); });
  if (finest == runs.rend()) {
    std::printf("\n### %s: every level failed\n", needle.c_str());
    return;
  }
  const Outcome& ref = *finest;
  std::printf("\n### %s (errors against %s)\n\n", needle.c_str(), ref.label.c_str());
  std::printf("| level | nodes | time [s] | peak so far [GB] | puncture depth [um] | force [mN] |");
  for (double d : kProbeDepths_m) std::printf(" F at %.0f um [mN] |", d * 1e6);
  std::printf("\n|---|--:|--:|--:|--:|--:|");
  for (std::size_t i = 0; i < std::size(kProbeDepths_m); ++i) std::printf("--:|");
  std::printf("\n");
  for (const Outcome& r : runs) {
    if (!r.error.empty()) {
      std::printf("| %s | failed: %s |\n", r.label.c_str(), r.error.c_str());
      continue;
    }
    std::printf("| %s | %zu | %.1f | %.2f | %s (%s)%s | %s |", r.label.c_str(), r.nodes, r.seconds,
                r.peak_gb, number(r.depth_m, 1e6, "%.1f").c_str(),
                percent_against(r.depth_m, ref.depth_m).c_str(),
                r.at_first_contact ? " first contact" : "", number(r.force_N, 1e3, "%.3f").c_str());
    for (std::size_t i = 0; i < r.probe_force_N.size(); ++i)
      std::printf(" %s (%s) |", number(r.probe_force_N[i], 1e3, "%.4g").c_str(),
                  percent_against(r.probe_force_N[i], ref.probe_force_N[i]).c_str());
    std::printf("\n");
    std::fflush(stdout);
  }
}

// F/d² of every pre-puncture step: constant for a self-similar tip (a cone, a bevel before its
// heel) in a linear half-space, so its scatter from step to step shows the mesh's own noise.
void print_curves(const std::vector<Outcome>& runs) {
  std::printf("\nF / d^2 [N/m^2] at each step (depth in um):\n\n");
  for (const Outcome& r : runs) {
    std::printf("%s:", r.label.c_str());
    for (const RunPoint& p : r.curve)
      std::printf(" %.0f:%.4g", p.depth_m * 1e6, p.force_N / (p.depth_m * p.depth_m));
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  try {
    const PluginRegistry registry = PluginRegistry::discover();
    for (const std::string& needle : options.needles) {
      // "cone": the sharp bevel's scene with paper A's needle replaced by a solid 15-degree cone
      // of the same diameter (a pointed tip on the axis, solved in 3-D with --model3d).
      const bool cone = needle == "cone";
      const fs::path file =
          fs::path(MNEEDLE_SOURCE_ROOT) / "designs" / "scenes" /
          ("paper_a_" + options.tissue + "_" + (cone ? "sharp_bevel" : needle) + ".toml");
      Scene scene = load_scene(file);
      if (cone)
        scene.needles.front().geometry = PluginGeometry{"cone",
                                                        {{"diameter", parse_quantity("230 um")},
                                                         {"length", parse_quantity("1000 um")},
                                                         {"half_angle", parse_quantity("15 deg")}}};
      if (options.resolution) {
        auto* plugin = std::get_if<PluginGeometry>(&scene.needles.front().geometry);
        if (plugin == nullptr) throw std::runtime_error("--resolution needs a plugin needle");
        plugin->parameters["resolution"] = parse_quantity(std::to_string(*options.resolution));
      }
      const std::vector<PreparedNeedle> needles = prepare_needles(registry, scene);
      std::vector<Outcome> runs;
      for (const Level& l : levels(scene, needles.front(), options)) {
        runs.push_back(run_level(scene, needles, l));
        std::fprintf(stderr, "%s %s: %.1f s %s\n", needle.c_str(), l.label.c_str(),
                     runs.back().seconds, runs.back().error.c_str());
      }
      print_table(needle + ", criterion " + std::string(to_string(options.criterion)) +
                      (options.contact ? ", frictionless contact" : ", the scene's contact"),
                  runs);
      print_curves(runs);
      std::printf("\nReductions of the scene planner:\n\n");
      for (const Outcome& r : runs) std::printf("- %s:%s\n", r.label.c_str(), r.reductions.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_puncture_convergence: %s\n", e.what());
    return 1;
  }
  return 0;
}
