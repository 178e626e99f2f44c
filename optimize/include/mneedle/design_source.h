#pragma once
// Where a needle comes from: a mesh file, a plugin with --set values, or a scene's [[needles]]
// entry. Every path ends in a validated mesh in the needle frame.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/mesh.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene.h"

namespace mneedle {

struct NeedleSource {
  std::string name;
  TriangleMesh mesh;                     // metres, needle frame
  std::optional<std::string> plugin;     // the shape, when made by a plugin
  std::map<std::string, double> params;  // SI, the shape's parameters (defaults filled in)
};

/// "key=value" settings (values with units, e.g. diameter=230um) → SI values checked against the
/// shape's parameter units. InputError names the setting and the problem.
std::map<std::string, double> parse_parameter_settings(const PluginShapeInfo& shape,
                                                       const std::vector<std::string>& settings);

/// Parsed quantities (a scene's or a design list's) → SI values for the shape; `where` prefixes
/// the key in messages.
std::map<std::string, double> scene_parameters(const PluginShapeInfo& shape,
                                               const std::map<std::string, Quantity>& given,
                                               const std::string& where);

/// Loads, validates and places a mesh file in the needle frame (its axis along z, tip at lowest z).
NeedleSource needle_from_file(const std::filesystem::path& file, double metres_per_unit);

NeedleSource needle_from_plugin(const PluginRegistry& registry, const std::string& shape,
                                const std::map<std::string, double>& params_si);

NeedleSource needle_from_scene(const PluginRegistry& registry, const NeedleSpec& spec);

}  // namespace mneedle
