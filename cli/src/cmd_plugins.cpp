// `mneedle plugins list|describe`: the tip shapes the plugin loader finds.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/units.h"
#include "mneedle/plugin_host.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

using Json = nlohmann::ordered_json;

struct PluginsOptions {
  std::string name;
  std::vector<std::filesystem::path> plugin_dirs;
  bool json = false;
};

Dimension parameter_dimension(const std::string& unit) {
  if (unit == "m") return Dimension::Length;
  if (unit == "rad") return Dimension::Angle;
  return Dimension::Dimensionless;
}

std::string readable(double value, const std::string& unit) {
  if (unit == "1") {
    std::ostringstream out;
    out << value;
    return out.str();
  }
  return format_quantity(value, parameter_dimension(unit));
}

Json parameter_json(const PluginParameter& p) {
  return Json{{"name", p.name},  {"unit", p.unit},  {"default_si", p.default_value},
              {"min_si", p.min}, {"max_si", p.max}, {"help", p.help}};
}

Json shape_json(const PluginShapeInfo& s) {
  Json parameters = Json::array();
  for (const auto& p : s.parameters) parameters.push_back(parameter_json(p));
  return Json{{"name", s.name},
              {"plugin_id", s.plugin_id},
              {"help", s.help},
              {"library", s.library.string()},
              {"thread_safe", s.thread_safe},
              {"section_area", s.has_section_area},
              {"section_properties", s.has_section_properties},
              {"parameters", parameters}};
}

void print_warnings(const PluginRegistry& registry) {
  for (const auto& w : registry.warnings()) std::cerr << "mneedle: warning: " << w << "\n";
}

void run_list(const PluginsOptions& options) {
  const PluginRegistry registry = PluginRegistry::discover(options.plugin_dirs);
  Json shapes = Json::array();
  for (const auto& s : registry.shapes()) shapes.push_back(shape_json(s));
  const Json tree{{"shapes", shapes}, {"warnings", registry.warnings()}};
  require_finite_json(tree, "plugins list");
  if (options.json) {
    std::cout << with_provenance(tree).dump(2) << "\n";
    return;
  }
  print_warnings(registry);
  for (const auto& s : registry.shapes()) {
    std::string names;
    for (const auto& p : s.parameters) names += (names.empty() ? "" : ", ") + p.name;
    std::cout << std::left << std::setw(14) << s.name << " " << s.help << "\n"
              << std::setw(14) << ""
              << " parameters: " << names << "\n"
              << std::setw(14) << ""
              << " from " << s.library.string() << "\n";
  }
}

void run_describe(const PluginsOptions& options) {
  const PluginRegistry registry = PluginRegistry::discover(options.plugin_dirs);
  const PluginShapeInfo& s = registry.shape(options.name);
  const Json tree = shape_json(s);
  require_finite_json(tree, "plugins describe " + s.name);
  if (options.json) {
    std::cout << with_provenance(tree).dump(2) << "\n";
    return;
  }
  std::cout << s.name << ": " << s.help << "\n"
            << "  plugin:   " << s.plugin_id << " (" << s.library.string() << ")\n"
            << "  threads:  " << (s.thread_safe ? "thread safe" : "calls serialised") << "\n"
            << "  sections: " << (s.has_section_area ? "analytic area" : "area from the mesh")
            << ", "
            << (s.has_section_properties ? "analytic second moment" : "second moment from the mesh")
            << "\n  parameters (value [min, max]):\n";
  for (const auto& p : s.parameters) {
    std::cout << "    " << std::left << std::setw(12) << p.name << " "
              << readable(p.default_value, p.unit) << " [" << readable(p.min, p.unit) << ", "
              << readable(p.max, p.unit) << "]  " << p.help << "\n";
  }
}

void add_plugin_dir_option(CLI::App* command, PluginsOptions& options) {
  command
      ->add_option("--plugin-dir", options.plugin_dirs,
                   "Extra folder to search for plugin libraries (repeatable)")
      ->allow_extra_args(false);
}

}  // namespace

void add_plugins_command(CLI::App& app) {
  auto options = std::make_shared<PluginsOptions>();
  CLI::App* plugins = app.add_subcommand("plugins", "List and describe tip-shape plugins");
  plugins->require_subcommand(1);
  plugins->footer("Example: mneedle plugins list");

  CLI::App* list = plugins->add_subcommand("list", "List every tip shape the loader finds");
  list->add_flag("--json", options->json, "Print one JSON object on stdout");
  add_plugin_dir_option(list, *options);
  list->footer(
      "Searches the built-in plugin folder, then MNEEDLE_PLUGIN_PATH (':'-separated), then\n"
      "--plugin-dir; never the current directory. Broken plugin files are warnings.\n"
      "Example: mneedle plugins list --json --plugin-dir ./my_plugins");
  list->callback([options] { run_list(*options); });

  CLI::App* describe = plugins->add_subcommand("describe", "Show a shape's parameters and bounds");
  describe->add_option("NAME", options->name, "Shape name, e.g. sharp_bevel")->required();
  describe->add_flag("--json", options->json, "Print one JSON object (values in SI, see unit)");
  add_plugin_dir_option(describe, *options);
  describe->footer("Example: mneedle plugins describe blunt_bevel");
  describe->callback([options] { run_describe(*options); });
}

}  // namespace mneedle::cli
