#include "mneedle/design_source.h"

#include "mneedle/error.h"
#include "mneedle/mesh_io.h"
#include "mneedle/mesh_validation.h"
#include "mneedle/needle_frame.h"
#include "mneedle/units.h"

namespace mneedle {
namespace {

const PluginParameter& find_parameter(const PluginShapeInfo& shape, const std::string& name) {
  for (const auto& p : shape.parameters)
    if (p.name == name) return p;
  std::string known;
  for (const auto& p : shape.parameters) known += (known.empty() ? "" : ", ") + p.name;
  throw InputError("shape '" + shape.name + "' has no parameter '" + name + "' (known: " + known +
                   ")");
}

Dimension parameter_dimension(const PluginParameter& p) {
  if (p.unit == "m") return Dimension::Length;
  if (p.unit == "rad") return Dimension::Angle;
  return Dimension::Dimensionless;
}

}  // namespace

std::map<std::string, double> parse_parameter_settings(const PluginShapeInfo& shape,
                                                       const std::vector<std::string>& settings) {
  std::map<std::string, double> si;
  for (const auto& setting : settings) {
    const auto eq = setting.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--set '" + setting + "': expected key=value, e.g. diameter=230um");
    const std::string key = setting.substr(0, eq);
    const PluginParameter& p = find_parameter(shape, key);
    try {
      si[key] = parse_quantity(setting.substr(eq + 1), parameter_dimension(p));
    } catch (const InputError& e) {
      throw InputError("--set " + key + ": " + e.what());
    }
  }
  return si;
}

std::map<std::string, double> scene_parameters(const PluginShapeInfo& shape,
                                               const std::map<std::string, Quantity>& given,
                                               const std::string& where) {
  std::map<std::string, double> si;
  for (const auto& [key, quantity] : given) {
    const PluginParameter& p = find_parameter(shape, key);
    si[key] = quantity_in(quantity, parameter_dimension(p), where + "." + key);
  }
  return si;
}

NeedleSource needle_from_file(const std::filesystem::path& file, double metres_per_unit) {
  NeedleSource n;
  n.name = file.stem().string();
  n.mesh = load_mesh(file, metres_per_unit);
  require_valid_mesh(n.mesh, file.string());
  place_in_needle_frame(n.mesh, std::nullopt);
  return n;
}

NeedleSource needle_from_plugin(const PluginRegistry& registry, const std::string& shape,
                                const std::map<std::string, double>& params_si) {
  NeedleSource n;
  n.name = shape;
  n.plugin = shape;
  const auto& info = registry.shape(shape);
  const std::vector<double> values = registry.resolve_parameters(shape, params_si);
  for (std::size_t i = 0; i < info.parameters.size(); ++i)
    n.params[info.parameters[i].name] = values[i];
  n.mesh = registry.generate(shape, n.params);
  return n;
}

NeedleSource needle_from_scene(const PluginRegistry& registry, const NeedleSpec& spec) {
  if (const auto* stl = std::get_if<StlGeometry>(&spec.geometry)) {
    NeedleSource n = needle_from_file(stl->path, stl->unit_scale);
    n.name = spec.name;
    return n;
  }
  const auto& plugin = std::get<PluginGeometry>(spec.geometry);
  const auto& info = registry.shape(plugin.plugin);
  NeedleSource n = needle_from_plugin(
      registry, plugin.plugin, scene_parameters(info, plugin.parameters, "needles." + spec.name));
  n.name = spec.name;
  return n;
}

}  // namespace mneedle
