// `mneedle scene check FILE [--json]`: validate a scene file and print it in SI units.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/loads_json.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

using Json = nlohmann::ordered_json;

// JSON key suffix of a value in SI, e.g. "_m", "_Pa", "_J_per_m2"; "" for plain numbers.
std::string si_suffix(Dimension d) {
  switch (d) {
    case Dimension::Dimensionless:
      return "";
    case Dimension::Length:
      return "_m";
    case Dimension::Angle:
      return "_rad";
    case Dimension::Pressure:
      return "_Pa";
    case Dimension::Force:
      return "_N";
    case Dimension::Speed:
      return "_m_per_s";
    case Dimension::Time:
      return "_s";
    case Dimension::Toughness:
      return "_J_per_m2";
    case Dimension::Density:
      return "_kg_per_m3";
    case Dimension::Viscosity:
      return "_Pa_s";
    case Dimension::Stiffness:
      return "_N_per_m";
    case Dimension::Energy:
      return "_J";
  }
  return "";
}

template <class T>
Json optional_json(const std::optional<T>& v) {
  return v ? Json(*v) : Json(nullptr);
}

Json material_json(const TissueMaterial& m) {
  Json j{{"model", to_string(m.model)}, {"E_Pa", m.youngs_modulus}, {"nu", m.poisson_ratio}};
  if (m.model == MaterialModel::MooneyRivlin) {
    j["C10_Pa"] = m.c10;
    j["C01_Pa"] = m.c01;
  }
  j["shear_modulus_Pa"] = m.shear_modulus();
  j["bulk_modulus_Pa"] = m.bulk_modulus();
  return j;
}

Json fracture_json(const std::optional<Fracture>& f) {
  if (!f) return nullptr;
  Json j{{"toughness_J_per_m2", f->toughness}, {"critical_pressure_Pa", f->critical_pressure}};
  if (f->cohesive_strength) {
    j["cohesive_strength_Pa"] = *f->cohesive_strength;
    j["cohesive_peak_ratio"] = f->cohesive_peak_ratio;
  }
  return j;
}

Json layer_json(const TissueLayer& layer) {
  Json j{{"name", layer.name},
         {"top_m", layer.top},
         {"thickness_m", layer.thickness},
         {"material", material_json(layer.material)},
         {"fracture", fracture_json(layer.fracture)}};
  if (layer.fracture) j["fracture"]["from"] = layer.fracture_is_own ? "layer" : "tissue";
  j["strength"] = layer.strength ? Json{{"strength_Pa", layer.strength->strength},
                                        {"length_m", layer.strength->length}}
                                 : Json(nullptr);
  return j;
}

Json tissue_json(const Tissue& t) {
  Json layers = Json::array();
  for (const auto& layer : t.layers) layers.push_back(layer_json(layer));
  return Json{{"size_m", t.size},
              {"boundary", to_string(t.boundary)},
              {"fracture", fracture_json(t.fracture)},
              {"layers", layers}};
}

Json geometry_json(const std::variant<PluginGeometry, StlGeometry>& g) {
  if (const auto* p = std::get_if<PluginGeometry>(&g)) {
    Json params = Json::object();
    for (const auto& [name, q] : p->parameters) params[name + si_suffix(q.dimension)] = q.value_si;
    return Json{{"plugin", p->plugin}, {"parameters", params}};
  }
  const auto& s = std::get<StlGeometry>(g);
  return Json{{"stl", s.path.string()}, {"unit", s.unit}, {"unit_scale_m", s.unit_scale}};
}

Json needle_json(const NeedleSpec& n) {
  return Json{{"name", n.name},
              {"geometry", geometry_json(n.geometry)},
              {"at_m", n.at},
              {"material", optional_json(n.material)}};
}

Json loads_json(const Scene& s) {
  const Loads& l = s.loads;
  Json j{{"scale", l.scale},
         {"stiffness_Pa", optional_json(l.stiffness)},
         {"friction", to_string(l.friction)}};
  if (l.mode == LoadMode::PaperAFig17) {
    j["specimen_diameter_m"] = *l.specimen_diameter;
    j["specimen_height_m"] = *l.specimen_height;
  }
  j["resolved"] = resolved_loads_json(s);
  if (l.friction == FrictionLaw::Coulomb) j["friction_coefficient"] = l.friction_coefficient;
  if (l.friction == FrictionLaw::LinearGrowth) {
    j["friction_max_force_N"] = l.friction_max_force;
    j["friction_saturation_depth_m"] = l.friction_saturation_depth;
  }
  return j;
}

Json scene_to_json(const Scene& s) {
  Json needles = Json::array();
  for (const auto& n : s.needles) needles.push_back(needle_json(n));
  Json outputs = Json::array();
  for (const auto o : s.model.outputs) outputs.push_back(to_string(o));
  Json materials = Json::array();
  for (const auto& m : s.materials) {
    materials.push_back(Json{{"name", m.name},
                             {"E_Pa", m.youngs_modulus},
                             {"nu", m.poisson_ratio},
                             {"strength_Pa", m.strength},
                             {"density_kg_per_m3", optional_json(m.density)}});
  }
  return Json{{"file", s.source_name},
              {"valid", true},
              {"tissue", tissue_json(s.tissue)},
              {"needles", needles},
              {"insertion",
               {{"depth_m", s.insertion.depth},
                {"speed_m_per_s", s.insertion.speed},
                {"angle_rad", s.insertion.angle}}},
              {"model",
               {{"fidelity", to_string(s.model.fidelity)},
                {"outputs", outputs},
                {"criterion", to_string(s.model.criterion)},
                {"contact", to_string(s.model.contact)},
                {"crack_faces", to_string(s.model.crack_faces)},
                {"mesh_refinement", optional_json(s.model.mesh_refinement)},
                {"contact_zone_m", optional_json(s.model.contact_zone)},
                {"contact_zone_tip_m", optional_json(s.model.contact_zone_tip)}}},
              {"loads", loads_json(s)},
              {"requirements",
               {{"target_depth_m", optional_json(s.requirements.target_depth)},
                {"safety_factor", s.requirements.safety_factor}}},
              {"materials", materials}};
}

// ---- text summary ---------------------------------------------------------------------------

std::string q(double v, Dimension d) {
  return format_quantity(v, d);
}

// A layer's depth range; a zero top in the unit of its bottom ("0 um to 20 um", not "0 m").
std::string depth_range(double top, double bottom) {
  const std::string end = q(bottom, Dimension::Length);
  const auto space = end.find(' ');
  const std::string start = top == 0.0 && space != std::string::npos ? "0" + end.substr(space)
                                                                     : q(top, Dimension::Length);
  return start + " to " + end;
}

std::string layer_line(std::size_t i, const TissueLayer& l) {
  std::ostringstream s;
  s << "  [" << i << "] " << l.name << ": " << depth_range(l.top, l.top + l.thickness) << " ("
    << q(l.thickness, Dimension::Length) << "), " << to_string(l.material.model) << " E "
    << q(l.material.youngs_modulus, Dimension::Pressure) << ", nu " << l.material.poisson_ratio;
  if (l.material.model == MaterialModel::MooneyRivlin) {
    s << " (C10 " << q(l.material.c10, Dimension::Pressure) << ", C01 "
      << q(l.material.c01, Dimension::Pressure) << ")";
  }
  if (l.fracture) {
    s << "; fracture J " << q(l.fracture->toughness, Dimension::Toughness) << ", P_c "
      << q(l.fracture->critical_pressure, Dimension::Pressure);
    if (l.fracture->cohesive_strength)
      s << ", cohesive sigma_c " << q(*l.fracture->cohesive_strength, Dimension::Pressure)
        << " (delta_y/delta_0 " << l.fracture->cohesive_peak_ratio << ")";
    s << (l.fracture_is_own ? "" : " (from tissue)");
  } else {
    s << "; no fracture data";
  }
  if (l.strength) {
    s << "; strength " << q(l.strength->strength, Dimension::Pressure) << " over "
      << q(l.strength->length, Dimension::Length);
  }
  return s.str();
}

std::string needle_line(const NeedleSpec& n) {
  std::ostringstream s;
  s << "  " << n.name << ": ";
  if (const auto* p = std::get_if<PluginGeometry>(&n.geometry)) {
    s << "plugin " << p->plugin << " (";
    bool first = true;
    for (const auto& [name, value] : p->parameters) {
      s << (first ? "" : ", ") << name << " " << q(value.value_si, value.dimension);
      first = false;
    }
    s << ")";
  } else {
    const auto& stl = std::get<StlGeometry>(n.geometry);
    s << "STL " << stl.path.string() << " in " << stl.unit;
  }
  s << " at (" << q(n.at[0], Dimension::Length) << ", " << q(n.at[1], Dimension::Length) << ")";
  s << ", material " << n.material.value_or("(not given)");
  return s.str();
}

void print_summary(std::ostream& out, const Scene& s) {
  const auto& t = s.tissue;
  out << s.source_name << ": valid scene\n";
  out << "tissue: " << q(t.size[0], Dimension::Length) << " x " << q(t.size[1], Dimension::Length)
      << " x " << q(t.size[2], Dimension::Length) << " deep, boundary " << to_string(t.boundary)
      << ", " << t.layers.size() << " layer(s)\n";
  for (std::size_t i = 0; i < t.layers.size(); ++i) out << layer_line(i, t.layers[i]) << "\n";
  out << "needles: " << s.needles.size() << "\n";
  for (const auto& n : s.needles) out << needle_line(n) << "\n";
  out << "insertion: depth " << q(s.insertion.depth, Dimension::Length) << ", speed "
      << q(s.insertion.speed, Dimension::Speed) << ", angle "
      << q(s.insertion.angle, Dimension::Angle) << "\n";
  out << "model: fidelity " << to_string(s.model.fidelity) << ", outputs";
  for (const auto o : s.model.outputs) out << " " << to_string(o);
  out << ", criterion " << to_string(s.model.criterion) << ", contact "
      << to_string(s.model.contact) << ", crack faces " << to_string(s.model.crack_faces) << "\n";
  out << "loads: S " << s.loads.scale << ", K "
      << (s.loads.stiffness ? q(*s.loads.stiffness, Dimension::Pressure)
                            : std::string("from the layer modulus"))
      << ", friction " << to_string(s.loads.friction);
  if (s.loads.friction == FrictionLaw::Coulomb)
    out << " (mu " << s.loads.friction_coefficient << ")";
  if (s.loads.friction == FrictionLaw::LinearGrowth) {
    out << " (F_max " << q(s.loads.friction_max_force, Dimension::Force) << " reached at "
        << q(s.loads.friction_saturation_depth, Dimension::Length) << ")";
  }
  out << "\n" << resolved_loads_text(s);
  out << "requirements: target depth "
      << (s.requirements.target_depth ? q(*s.requirements.target_depth, Dimension::Length)
                                      : std::string("none"))
      << ", safety factor " << s.requirements.safety_factor << "\n";
  for (const auto& m : s.materials) {
    out << "material " << m.name << ": E " << q(m.youngs_modulus, Dimension::Pressure) << ", nu "
        << m.poisson_ratio << ", strength " << q(m.strength, Dimension::Pressure) << "\n";
  }
}

}  // namespace

void add_scene_command(CLI::App& app) {
  auto* scene = app.add_subcommand("scene", "Validate and print scene files (docs/scene.md)");
  scene->require_subcommand(1);

  struct Options {
    std::string file;
    bool json = false;
    std::vector<std::filesystem::path> plugin_dirs;
  };
  auto opts = std::make_shared<Options>();
  auto* check = scene->add_subcommand(
      "check", "Validate a scene file and print it with every value in SI units");
  check->add_option("FILE", opts->file, "Scene file (TOML)")->required();
  check->add_flag("--json", opts->json, "Print one JSON object (keys carry their SI unit)");
  check->add_option("--plugin-dir", opts->plugin_dirs, "Extra folder to search for plugins");
  check->footer(
      "Example:\n  mneedle scene check designs/scenes/human_skin.toml\n"
      "  mneedle scene check designs/scenes/human_skin.toml --json\n"
      "An invalid scene prints one line naming file:line, the key and the problem; exit 1.\n");
  check->callback([opts] {
    const Scene s = load_scene(opts->file);
    // The needles are built and placed as every command that runs the scene does: a mesh that
    // is not a closed solid, a needle wider than the block or two on the same tissue fail here.
    const PluginRegistry registry =
        needs_plugins(s) ? PluginRegistry::discover(opts->plugin_dirs) : PluginRegistry();
    const std::vector<PreparedNeedle> needles = prepare_needles(registry, s);
    check_needle_placement(s, needles);
    record_scene(s, opts->file);
    record_plugin_meshes(s, needles);
    // The summary prints the same values as the JSON: one check covers both.
    const Json tree = scene_to_json(s);
    require_finite_json(tree, "scene " + opts->file);
    if (opts->json) {
      std::cout << with_provenance(tree).dump(2) << "\n";
    } else {
      print_summary(std::cout, s);
    }
  });
}

}  // namespace mneedle::cli
