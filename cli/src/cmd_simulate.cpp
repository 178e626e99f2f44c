// `mneedle simulate SCENE [--fidelity ...] [--contact ...] [--json|--csv]`: the pre-puncture
// finite element stage. An axisymmetric needle (cylinder or cone plugin) alone runs on the
// axisymmetric model; bevels, STL needles and arrays run on the 3-D tetrahedral model.
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "mneedle/design_source.h"
#include "mneedle/error.h"
#include "mneedle/fe/axisymmetric.h"
#include "mneedle/fe/indentation3d.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene.h"
#include "mneedle/units.h"

namespace mneedle::cli {
namespace {

struct SimulateOptions {
  std::filesystem::path scene;
  std::string fidelity;
  std::string contact;
  std::string model = "auto";
  std::string vtu;
  bool json = false;
  bool csv = false;
};

fe::MaterialModel to_fe(MaterialModel m) {
  switch (m) {
    case MaterialModel::Linear:
      return fe::MaterialModel::Linear;
    case MaterialModel::StVenantKirchhoff:
      return fe::MaterialModel::StVenantKirchhoff;
    case MaterialModel::NeoHookean:
      return fe::MaterialModel::NeoHookean;
    case MaterialModel::MooneyRivlin:
      return fe::MaterialModel::MooneyRivlin;
  }
  return fe::MaterialModel::Linear;
}

std::vector<fe::AxisymmetricLayer> layers_of(const Scene& scene) {
  std::vector<fe::AxisymmetricLayer> layers;
  for (const TissueLayer& l : scene.tissue.layers) {
    fe::MaterialParameters p;
    p.model = to_fe(l.material.model);
    p.E = l.material.youngs_modulus;
    p.nu = l.material.poisson_ratio;
    p.c10 = l.material.c10;
    p.c01 = l.material.c01;
    try {
      fe::Material check(p);
    } catch (const InputError& e) {
      throw InputError(scene.source_name + ":" + std::to_string(l.line) + ": layer '" + l.name +
                       "': " + e.what());
    }
    layers.push_back({l.thickness, p});
  }
  return layers;
}

// The needle's outer profile from the plugin's section area A(h) = pi (r_out^2 - r_bore^2).
fe::AxisymmetricNeedle axisymmetric_needle(const Scene& scene, const NeedleSpec& spec,
                                           const PluginRegistry& registry) {
  const std::string where =
      scene.source_name + ":" + std::to_string(spec.line) + ": needle '" + spec.name + "'";
  const auto* plugin = std::get_if<PluginGeometry>(&spec.geometry);
  if (plugin == nullptr || (plugin->plugin != "cylinder" && plugin->plugin != "cone"))
    throw InputError(where +
                     ": only the axisymmetric cylinder and cone plugins can be simulated yet; "
                     "this needle needs the 3-D model");
  std::map<std::string, double> si;
  for (const auto& [name, quantity] : plugin->parameters) si[name] = quantity.value_si;
  const PluginShapeInfo& shape = registry.shape(plugin->plugin);
  const std::vector<double> values = registry.resolve_parameters(plugin->plugin, si);
  std::map<std::string, double> resolved;
  for (std::size_t i = 0; i < shape.parameters.size(); ++i)
    resolved[shape.parameters[i].name] = values[i];
  const double radius = 0.5 * resolved.at("diameter");
  const double bore = resolved.count("bore") ? 0.5 * resolved["bore"] : 0.0;
  if (plugin->plugin == "cylinder") return fe::AxisymmetricNeedle::flat_punch(radius, bore);
  // Cone: sample the section so a rounded tip (tip_radius) is followed too.
  const double length = resolved.at("length");
  const double taper = (radius - bore) / std::tan(resolved.at("half_angle"));
  const double top = std::min(length, 1.05 * taper);
  fe::AxisymmetricNeedle needle;
  needle.bore_radius_m = bore;
  constexpr int kSamples = 200;
  for (int i = 0; i <= kSamples; ++i) {
    const double h = top * i / kSamples;
    const std::optional<double> area = registry.section_area(plugin->plugin, resolved, h);
    if (!area) throw InputError(where + ": the cone plugin gives no section area");
    const double r = std::sqrt(std::max(*area / M_PI + bore * bore, 0.0));
    const double previous = needle.radii_m.empty() ? 0.0 : needle.radii_m.back();
    needle.heights_m.push_back(h);
    needle.radii_m.push_back(std::max({r, previous, bore}));
  }
  return needle;
}

fe::Fidelity fidelity_of(const Scene& scene, const std::string& option) {
  const std::string name = option.empty() ? std::string(to_string(scene.model.fidelity)) : option;
  if (name == "fast") return fe::Fidelity::Fast;
  if (name == "fine") return fe::Fidelity::Fine;
  return fe::Fidelity::Standard;
}

fe::ContactMode contact_of(const Scene& scene, const std::string& option) {
  const std::string name = option.empty() ? std::string(to_string(scene.model.contact)) : option;
  return name == "frictionless" ? fe::ContactMode::Frictionless : fe::ContactMode::Sticking;
}

nlohmann::json to_json(const std::string& name, const fe::InsertionResult& r) {
  nlohmann::json curve = nlohmann::json::array();
  for (const fe::InsertionStep& s : r.steps)
    curve.push_back({{"depth_m", s.depth_m},
                     {"force_N", s.force_N},
                     {"lateral_force_N", {0.0, 0.0}},
                     {"contact_area_m2", s.contact_area_m2},
                     {"contact_pressure_Pa", s.contact_pressure_Pa},
                     {"strain_energy_J", s.strain_energy_J}});
  return {{"needles", {{{"name", name}, {"curve", curve}}}},
          {"mesh",
           {{"nodes", r.nodes}, {"elements", r.elements}, {"order", 2}, {"axisymmetric", true}}}};
}

void print_csv(const fe::InsertionResult& r) {
  std::cout << "depth_m,force_N,lateral_force_x_N,lateral_force_y_N,contact_area_m2,"
               "contact_pressure_Pa,strain_energy_J,newton_iterations\n";
  std::cout << std::setprecision(9);
  for (const fe::InsertionStep& s : r.steps)
    std::cout << s.depth_m << "," << s.force_N << ",0,0," << s.contact_area_m2 << ","
              << s.contact_pressure_Pa << "," << s.strain_energy_J << "," << s.newton_iterations
              << "\n";
}

void print_table(const std::string& name, const fe::InsertionResult& r) {
  std::cout << "needle " << name << " (axisymmetric, " << r.nodes << " nodes, " << r.elements
            << " 6-node triangles, " << std::setprecision(3) << r.solve_seconds << " s)\n";
  std::cout << "  depth [um]   force [mN]   area [um^2]   pressure [MPa]   energy [uJ]   iter\n";
  for (const fe::InsertionStep& s : r.steps)
    std::cout << std::fixed << std::setprecision(2) << std::setw(12) << s.depth_m * 1e6
              << std::setprecision(4) << std::setw(13) << s.force_N * 1e3 << std::setprecision(1)
              << std::setw(14) << s.contact_area_m2 * 1e12 << std::setprecision(4) << std::setw(17)
              << s.contact_pressure_Pa * 1e-6 << std::setprecision(4) << std::setw(14)
              << s.strain_energy_J * 1e6 << std::setw(7) << s.newton_iterations << "\n";
}

bool axisymmetric_scene(const Scene& scene) {
  if (scene.needles.size() != 1) return false;
  const auto* plugin = std::get_if<PluginGeometry>(&scene.needles.front().geometry);
  return plugin != nullptr && (plugin->plugin == "cylinder" || plugin->plugin == "cone");
}

fe::TissueBlockSpec block_of(const Scene& scene) {
  fe::TissueBlockSpec block;
  block.size_x = scene.tissue.size[0];
  block.size_y = scene.tissue.size[1];
  const auto layers = layers_of(scene);
  for (std::size_t i = 0; i < layers.size(); ++i)
    block.layers.push_back(
        {scene.tissue.layers[i].name, layers[i].thickness_m, layers[i].material});
  return block;
}

nlohmann::json to_json_3d(const fe::Simulation3dResult& r) {
  nlohmann::json needles = nlohmann::json::array();
  for (std::size_t n = 0; n < (r.steps.empty() ? 0 : r.steps.front().needles.size()); ++n) {
    nlohmann::json curve = nlohmann::json::array();
    for (const fe::Step3d& s : r.steps) {
      const fe::NeedleStep3d& ns = s.needles[n];
      curve.push_back({{"depth_m", s.depth_m},
                       {"force_N", ns.force_N},
                       {"lateral_force_N", {ns.lateral_force_N[0], ns.lateral_force_N[1]}},
                       {"contact_area_m2", ns.contact_area_m2},
                       {"contact_pressure_Pa", ns.contact_pressure_Pa},
                       {"strain_energy_J", s.strain_energy_J}});
    }
    needles.push_back({{"name", r.steps.front().needles[n].name}, {"curve", curve}});
  }
  return {{"needles", needles},
          {"mesh",
           {{"nodes", r.nodes},
            {"elements", r.elements},
            {"order", r.order},
            {"axisymmetric", false},
            {"min_dihedral_deg", r.quality.min_dihedral_deg},
            {"max_aspect_ratio", r.quality.max_aspect_ratio}}}};
}

void print_3d(const fe::Simulation3dResult& r, bool csv) {
  if (csv)
    std::cout << "needle,depth_m,force_N,lateral_force_x_N,lateral_force_y_N,contact_area_m2,"
                 "contact_pressure_Pa,strain_energy_J,newton_iterations\n";
  else
    std::cout << "3-D model: " << r.nodes << " nodes, " << r.elements << " TET"
              << (r.order == 2 ? 10 : 4) << ", " << std::setprecision(3) << r.timing.total_s
              << " s (" << r.solver_backend
              << ")\n  needle          depth [um]   force [mN]   lateral x, y [mN]\n";
  for (const fe::Step3d& s : r.steps)
    for (const fe::NeedleStep3d& n : s.needles) {
      if (csv) {
        std::cout << std::setprecision(9) << n.name << "," << s.depth_m << "," << n.force_N << ","
                  << n.lateral_force_N[0] << "," << n.lateral_force_N[1] << "," << n.contact_area_m2
                  << "," << n.contact_pressure_Pa << "," << s.strain_energy_J << ","
                  << s.newton_iterations << "\n";
      } else {
        std::cout << "  " << std::left << std::setw(14) << n.name << std::right << std::fixed
                  << std::setprecision(2) << std::setw(12) << s.depth_m * 1e6
                  << std::setprecision(4) << std::setw(13) << n.force_N * 1e3 << "   "
                  << n.lateral_force_N[0] * 1e3 << ", " << n.lateral_force_N[1] * 1e3 << "\n";
        std::cout.unsetf(std::ios::fixed);
      }
    }
}

void run_3d(const Scene& scene, const SimulateOptions& o) {
  if (contact_of(scene, o.contact) == fe::ContactMode::Frictionless)
    throw InputError(scene.source_name +
                     ": model.contact: frictionless contact is not available in the 3-D model yet "
                     "(use sticking, or an axisymmetric needle)");
  const PluginRegistry registry = PluginRegistry::discover();
  std::vector<fe::Needle3d> needles;
  for (const NeedleSpec& spec : scene.needles)
    needles.push_back({spec.name, needle_from_scene(registry, spec).mesh, spec.at[0], spec.at[1]});
  fe::Simulation3dOptions options;
  options.fidelity = fidelity_of(scene, o.fidelity);
  options.depth = scene.insertion.depth;
  options.vtu_directory = o.vtu;
  const fe::Simulation3dResult result = fe::simulate_3d(block_of(scene), needles, options);
  if (o.json)
    std::cout << to_json_3d(result).dump(2) << "\n";
  else
    print_3d(result, o.csv);
}

void run(const SimulateOptions& o) {
  const Scene scene = load_scene(o.scene);
  const bool axisymmetric =
      o.model == "axisymmetric" || (o.model == "auto" && axisymmetric_scene(scene));
  if (!axisymmetric || !o.vtu.empty()) {
    if (o.model == "axisymmetric")
      throw InputError("simulate: --vtu is written by the 3-D model only (use --model 3d)");
    run_3d(scene, o);
    return;
  }
  if (scene.needles.size() != 1)
    throw InputError(scene.source_name + ": needles: " + std::to_string(scene.needles.size()) +
                     " needles need the 3-D model; the axisymmetric solver takes exactly one");
  const PluginRegistry registry = PluginRegistry::discover();
  const NeedleSpec& spec = scene.needles.front();
  fe::AxisymmetricProblem problem;
  problem.layers = layers_of(scene);
  // A cylinder with the block's cross-section area (see docs: fe_model).
  problem.radius_m = std::sqrt(scene.tissue.size[0] * scene.tissue.size[1] / M_PI);
  problem.needle = axisymmetric_needle(scene, spec, registry);
  problem.depth_m = scene.insertion.depth;
  problem.fidelity = fidelity_of(scene, o.fidelity);
  problem.contact = contact_of(scene, o.contact);
  const fe::InsertionResult result = fe::simulate_axisymmetric(problem);
  if (o.json)
    std::cout << to_json(spec.name, result).dump(2) << "\n";
  else if (o.csv)
    print_csv(result);
  else
    print_table(spec.name, result);
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* cmd =
      app.add_subcommand("simulate", "Pre-puncture finite element insertion (axisymmetric or 3-D)");
  cmd->add_option("scene", options->scene, "scene file (TOML)")->required();
  cmd->add_option("--fidelity", options->fidelity, "mesh fidelity (default: the scene's)")
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_option("--contact", options->contact, "needle contact (default: the scene's)")
      ->check(CLI::IsMember({"sticking", "frictionless"}));
  cmd->add_option("--model", options->model,
                  "auto (axisymmetric when the scene allows it), axisymmetric or 3d")
      ->check(CLI::IsMember({"auto", "axisymmetric", "3d"}))
      ->capture_default_str();
  cmd->add_option("--vtu", options->vtu, "write step_<k>.vtu per depth step here (3-D model)");
  cmd->footer(
      "Examples:\n  mneedle simulate designs/scenes/human_skin.toml --fidelity fast --json\n"
      "  mneedle simulate tests/assets/scenes/axisymmetric_punch.toml --csv");
  auto* json = cmd->add_flag("--json", options->json, "print the curve as JSON");
  cmd->add_flag("--csv", options->csv, "print the curve as CSV")->excludes(json);
  cmd->callback([options]() { run(*options); });
}

}  // namespace mneedle::cli
