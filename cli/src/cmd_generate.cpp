// `mneedle generate NAME --set key=value ... -o out.stl`: build a needle mesh with a tip-shape
// plugin and write it as binary STL.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>

#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/plugin_host.h"
#include "option_values.h"

namespace mneedle::cli {
namespace {

struct GenerateOptions {
  std::string name;
  std::vector<std::string> settings;
  std::string unit = "mm";
  std::vector<std::filesystem::path> plugin_dirs;
  std::filesystem::path output;
};

Dimension parameter_dimension(const std::string& unit) {
  if (unit == "m") return Dimension::Length;
  if (unit == "rad") return Dimension::Angle;
  return Dimension::Dimensionless;
}

// "--set key=value" with a unit in the value ("230um", "30 deg"); a plain number is SI.
std::map<std::string, double> parse_settings(const std::vector<std::string>& settings,
                                             const PluginShapeInfo& shape) {
  std::map<std::string, double> si;
  for (const auto& setting : settings) {
    const auto equals = setting.find('=');
    if (equals == std::string::npos || equals == 0) {
      throw InputError("--set '" + setting + "': expected key=value, e.g. diameter=230um");
    }
    const std::string key = setting.substr(0, equals);
    const PluginParameter* parameter = nullptr;
    for (const auto& p : shape.parameters) {
      if (p.name == key) parameter = &p;
    }
    if (parameter == nullptr) {
      std::string names;
      for (const auto& p : shape.parameters) names += (names.empty() ? "" : ", ") + p.name;
      throw InputError("--set " + key + ": shape '" + shape.name + "' has no parameter '" + key +
                       "' (parameters: " + names + ")");
    }
    if (si.count(key) != 0) throw InputError("--set " + key + ": given twice");
    Quantity q{};
    try {
      q = parse_quantity(setting.substr(equals + 1));
    } catch (const InputError& e) {
      throw InputError("--set " + key + ": " + e.what());  // which value it was
    }
    si[key] = quantity_in(q, parameter_dimension(parameter->unit), "--set " + key);
  }
  return si;
}

void run_generate(const GenerateOptions& options) {
  // The file is always binary STL: another extension would be read as its own format later.
  std::string extension = options.output.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension != ".stl")
    throw InputError("-o '" + options.output.string() +
                     "': generate writes binary STL; name the file *.stl");
  const double metres_per_unit = option_length_unit(options.unit);
  const PluginRegistry registry = PluginRegistry::discover(options.plugin_dirs);
  const PluginShapeInfo& shape = registry.shape(options.name);
  const auto si = parse_settings(options.settings, shape);
  const TriangleMesh mesh = registry.generate(options.name, si);
  // A plugin is foreign code: no non-finite coordinate may reach the STL file.
  const std::string context = "generate " + shape.name;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    require_finite_row({v[0], v[1], v[2]}, {"x_m", "y_m", "z_m"}, "vertex " + std::to_string(i),
                       context);
  }
  const double volume = require_finite(signed_volume(mesh), "volume_m3", context);
  write_stl_binary(mesh, options.output, metres_per_unit,
                   "mneedle generate " + shape.name + " unit=" + options.unit);
  std::cout << "wrote " << options.output.string() << " (" << shape.name << ", "
            << mesh.triangles.size() << " triangles, volume " << volume << " m^3, unit "
            << options.unit << ")\n";
}

}  // namespace

void add_generate_command(CLI::App& app) {
  auto options = std::make_shared<GenerateOptions>();
  CLI::App* command =
      app.add_subcommand("generate", "Generate a needle mesh from a tip-shape plugin (binary STL)");
  command->add_option("NAME", options->name, "Shape name (see: mneedle plugins list)")->required();
  command
      ->add_option("--set", options->settings,
                   "Parameter as key=value with a unit, e.g. diameter=230um (repeatable)")
      ->allow_extra_args(false);
  command->add_option("--unit", options->unit, "Length unit of the STL: um, mm or m")
      ->capture_default_str();
  command
      ->add_option("--plugin-dir", options->plugin_dirs,
                   "Extra folder to search for plugin libraries (repeatable)")
      ->allow_extra_args(false);
  command->add_option("-o,--output", options->output, "Output STL file")->required();
  command->footer(
      "Unset parameters take their defaults (mneedle plugins describe NAME).\n"
      "Example: mneedle generate sharp_bevel --set diameter=230um --set bevel_angle=30deg "
      "-o sharp.stl");
  command->callback([options] { run_generate(*options); });
}

}  // namespace mneedle::cli
