// `mneedle force SCENE [--json|--csv] [--step 10um]`: paper A's post-puncture force curve of
// every needle of a scene, as if it had punctured at the surface.
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/loads_json.h"
#include "mneedle/base/error.h"
#include "mneedle/base/text.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/insertion/puncture.h"
#include "mneedle/insertion/surface_loads.h"
#include "mneedle/plot/figure.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "option_values.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct ForceOptions {
  std::string scene;
  bool json = false;
  bool csv = false;
  std::string step = "10um";
  std::string plot;  // SVG of force against depth
  long max_points = 1'000'000;
  std::size_t max_needles = kDefaultMaxNeedles;
  std::vector<std::filesystem::path> plugin_dirs;
};

struct NeedleCurve {
  std::string name;
  std::vector<LoadSample> curve;
  double beta_length_m = 0.0;
};

struct ForceResult {
  Scene scene;
  std::vector<NeedleCurve> curves;
  std::vector<std::string> notes;  // what the curves leave out that `simulate` keeps
};

// The broken top layer's grip (docs/model.md, "The broken top layer") needs the pre-puncture
// curve, which `force` does not run: say so, or the table's stratum corneum loads (tens of mN
// from the first micrometres) read as what `simulate` reports.
std::vector<std::string> grip_notes(const Scene& scene) {
  std::vector<double> moduli;
  for (const TissueLayer& layer : scene.tissue.layers)
    moduli.push_back(layer.material.youngs_modulus);
  // As `simulate` plans it: a pre-puncture model runs (outputs other than the curve alone) and
  // the scene holds the criterion's constants.
  const bool pre_puncture_runs =
      scene.model.wants(Output::Puncture) || scene.model.wants(Output::Fields);
  if (!pre_puncture_runs || !has_puncture_data(scene) ||
      !top_layer_grips(scene.model.criterion, moduli))
    return {};
  return {"layer '" + scene.tissue.layers.front().name +
          "' is stiffer than the one below and the scene's criterion is stress: after the "
          "puncture `simulate` keeps it gripped to the shaft, continuing the pre-puncture curve "
          "until its own loads are exceeded (docs/model.md, \"The broken top layer\"); these "
          "curves are the distributed loads alone, as if the needle had punctured at the surface"};
}

// 0, step, 2 step, ... up to the scene's insertion depth, which is always the last point.
std::vector<double> depth_grid(double max_depth, double step, double max_points) {
  // Checked before any point is made: --step 1e-15m once asked for 10^11 points.
  if (!(max_depth / step <= max_points))
    throw InputError("--step " + format_quantity(step, Dimension::Length) + " over " +
                     format_quantity(max_depth, Dimension::Length) + " is " +
                     count_text(max_depth / step) + " points, above the limit of " +
                     std::to_string(static_cast<long>(max_points)) +
                     " (raise it with --max-points)");
  std::vector<double> depths;
  const auto count = static_cast<long>(std::floor(max_depth / step * (1.0 + 1e-12)));
  for (long i = 0; i <= count; ++i) depths.push_back(static_cast<double>(i) * step);
  if (max_depth - depths.back() > 1e-9 * step) depths.push_back(max_depth);
  return depths;
}

ForceResult compute(const ForceOptions& options) {
  ForceResult result{load_scene(options.scene), {}, {}};
  const Scene& scene = result.scene;
  const double step = option_quantity("--step", options.step, Dimension::Length);
  if (!(step > 0.0)) throw InputError("--step " + options.step + ": must be a positive length");
  if (!(scene.insertion.depth > 0.0)) {
    throw InputError(scene.source_name + ": insertion.depth must be positive for a force curve");
  }
  const std::vector<double> depths =
      depth_grid(scene.insertion.depth, step, static_cast<double>(options.max_points));
  const LoadConstants constants = load_constants(scene);
  // Plugins are searched only when a needle needs one, so STL-only scenes run without them.
  const PluginRegistry registry =
      needs_plugins(scene) ? PluginRegistry::discover(options.plugin_dirs) : PluginRegistry();
  // The same placement checks as `simulate`: a needle wider than the block or two needles on
  // the same tissue would otherwise give curves for a scene that cannot exist.
  const std::vector<PreparedNeedle> needles = prepare_needles(registry, scene, options.max_needles);
  record_scene(scene, options.scene);
  record_plugin_meshes(scene, needles);
  check_needle_placement(scene, needles);
  for (const PreparedNeedle& needle : needles) {
    const SurfaceLoadModel model(needle.mesh, constants);
    result.curves.push_back({needle.name, model.curve(depths), model.beta_length_m()});
  }
  result.notes = grip_notes(scene);
  return result;
}

nlohmann::json to_json(const ForceResult& result) {
  nlohmann::json needles = nlohmann::json::array();
  for (const NeedleCurve& c : result.curves) {
    nlohmann::json points = nlohmann::json::array();
    for (const LoadSample& s : c.curve) {
      points.push_back({{"depth_m", s.depth_m},
                        {"force_N", s.force_N},
                        {"alpha_N", s.alpha_N},
                        {"beta_N", s.beta_N},
                        {"friction_N", s.friction_N}});
    }
    needles.push_back({{"name", c.name}, {"beta_length_m", c.beta_length_m}, {"curve", points}});
  }
  return nlohmann::json{
      {"loads", resolved_loads_json(result.scene)}, {"needles", needles}, {"notes", result.notes}};
}

void print_csv(const ForceResult& result) {
  const std::vector<NeedleCurve>& curves = result.curves;
  std::cout << provenance_comment() << "\n";
  for (const std::string& note : result.notes) std::cout << "# note: " << note << "\n";
  std::cout << "needle,depth_m,force_N,alpha_N,beta_N,friction_N\n" << std::setprecision(10);
  for (const NeedleCurve& c : curves) {
    for (const LoadSample& s : c.curve) {
      std::cout << c.name << ',' << s.depth_m << ',' << s.force_N << ',' << s.alpha_N << ','
                << s.beta_N << ',' << s.friction_N << '\n';
    }
  }
}

void print_table(const ForceResult& result) {
  std::cout << "pressure scale per layer (docs/model.md, \"Pressure scale\"):\n"
            << resolved_loads_text(result.scene);
  for (const std::string& note : result.notes) std::cout << "note: " << note << "\n";
  for (const NeedleCurve& c : result.curves) {
    std::cout << c.name << " (beta length " << format_quantity(c.beta_length_m, Dimension::Length)
              << ")\n  depth_um    force_mN    alpha_mN     beta_mN  friction_mN\n";
    for (const LoadSample& s : c.curve) {
      std::cout << std::fixed << std::setprecision(4) << std::setw(10) << s.depth_m * 1e6
                << std::setw(12) << s.force_N * 1e3 << std::setw(12) << s.alpha_N * 1e3
                << std::setw(12) << s.beta_N * 1e3 << std::setw(13) << s.friction_N * 1e3 << "\n";
    }
  }
}

}  // namespace

void add_force_command(CLI::App& app) {
  auto options = std::make_shared<ForceOptions>();
  CLI::App* cmd = app.add_subcommand(
      "force", "Post-puncture force curve of each needle of a scene (paper A distributed loads)");
  cmd->footer("Example:\n  mneedle force designs/scenes/silicone_phantom.toml --step 250um --csv");
  cmd->add_option("SCENE", options->scene, "Scene file (TOML)")->required();
  auto* json = cmd->add_flag("--json", options->json, "Print JSON");
  cmd->add_flag("--csv", options->csv,
                "Print CSV: needle,depth_m,force_N,alpha_N,beta_N,friction_N")
      ->excludes(json);
  cmd->add_option("--step", options->step, "Depth step with a unit (default 10um)");
  cmd->add_option("--max-points", options->max_points,
                  "Largest number of depths a curve may have (default 1000000)")
      ->check(CLI::Range(1L, 1'000'000'000L));
  cmd->add_option("--max-needles", options->max_needles, "Most needles the scene may hold")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, std::size_t{1'000'000}));
  cmd->add_option("--plugin-dir", options->plugin_dirs, "Extra folder to search for plugins");
  cmd->add_option("--plot", options->plot, "Write force against depth as SVG");
  cmd->callback([options] {
    const ForceResult result = compute(*options);
    // Every format prints the same numbers: one check of the tree covers the CSV and table too.
    const nlohmann::json tree = to_json(result);
    require_finite_json(tree, "force");
    if (!options->plot.empty()) {
      plot::Figure f;
      f.title = "force: " + std::filesystem::path(options->scene).filename().string() +
                " (post-puncture loads)";
      f.x.name = "depth below the surface";
      for (const NeedleCurve& c : result.curves) {
        plot::Series s;
        s.label = c.name;
        for (const LoadSample& p : c.curve) {
          s.x.push_back(p.depth_m);
          s.y.push_back(p.force_N);
        }
        f.series.push_back(std::move(s));
      }
      plot::write_svg(options->plot, f);
    }
    if (options->json) {
      std::cout << with_provenance(tree).dump(2) << "\n";
    } else if (options->csv) {
      print_csv(result);
    } else {
      print_table(result);
    }
  });
}

}  // namespace mneedle::cli
