// mneedle strength: buckling and material capacity of one needle (docs/model.md, "Needle
// strength").
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "mneedle/api/strength_report.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/needle/needle_frame.h"
#include "option_values.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct StrengthArgs {
  std::string file;
  std::string plugin;
  std::vector<std::string> settings;
  std::string unit = "mm";
  std::string axis = "auto";
  std::string material;
  std::string end = "fixed-pinned";
  std::string depth;
  double lateral_ratio = 0.0;
  std::vector<std::string> plugin_dirs;
  bool json = false;
};

void run_strength(const StrengthArgs& args) {
  if (args.file.empty() == args.plugin.empty())
    throw InputError("strength: give either a mesh FILE or --plugin NAME");
  const auto registry =
      PluginRegistry::discover({args.plugin_dirs.begin(), args.plugin_dirs.end()});
  NeedleSource needle =
      args.file.empty()
          ? needle_from_plugin(registry, args.plugin,
                               parse_parameter_settings(registry.shape(args.plugin), args.settings))
          : needle_from_file(args.file, option_length_unit(args.unit),
                             parse_axis_choice(args.axis));
  if (!needle.frame_note.empty())
    std::cerr << "mneedle: " << args.file << ": " << needle.frame_note << "\n";
  if (args.file.empty())
    record_mesh(needle.name, needle.mesh);
  else
    record_input("needle", args.file);
  StrengthSettings settings;
  settings.material = args.material;
  settings.end = args.end;
  settings.depth = args.depth;
  settings.lateral_ratio = args.lateral_ratio;
  // Text and JSON print the same numbers, checked once by strength_report.
  const nlohmann::json out = strength_report(registry, needle, settings);
  if (args.json) {
    std::cout << with_provenance(out).dump(2) << "\n";
    return;
  }
  const auto q = [&](const char* key, Dimension d) {
    return format_quantity(out[key].get<double>(), d);
  };
  std::cout << needle.name << " in " << out["material"].get<std::string>() << " ("
            << out["end"].get<std::string>() << ", loaded from "
            << q("load_height_m", Dimension::Length) << " above the tip)\n"
            << "  buckling:  " << q("buckling_N", Dimension::Force)
            << (out["johnson"].get<bool>() ? "  (Johnson, inelastic)" : "  (Euler, elastic)")
            << "\n"
            << "  strength:  " << q("strength_N", Dimension::Force) << "  ("
            << out["failure_mode"].get<std::string>() << " at "
            << q("critical_height_m", Dimension::Length) << " above the tip)\n"
            << "  capacity:  " << q("capacity_N", Dimension::Force) << "  governed by "
            << out["governing"].get<std::string>() << "\n";
}

}  // namespace

void add_strength_command(CLI::App& app) {
  auto args = std::make_shared<StrengthArgs>();
  auto* cmd = app.add_subcommand("strength", "Buckling and material capacity of a needle");
  cmd->footer(
      "Examples:\n"
      "  mneedle strength --plugin cone --set diameter=200um --set length=600um --material pla\n"
      "  mneedle strength designs/sharp_bevel.stl --unit mm --material silicon --json");
  cmd->add_option("file", args->file, "Needle mesh (STL, OBJ, PLY, OFF)");
  cmd->add_option("--plugin", args->plugin, "Tip-shape plugin instead of a file");
  cmd->add_option("--set", args->settings, "Plugin parameter, key=value with unit (repeatable)");
  cmd->add_option("--axis", args->axis,
                  "Needle axis in the mesh file: auto, x, y, z or a tip direction a,b,c; a holder "
                  "the needle stands on is cut off")
      ->capture_default_str();
  cmd->add_option("--unit", args->unit, "Length unit of the mesh file: um, mm, m")
      ->capture_default_str();
  cmd->add_option("--material", args->material, "Needle material (see docs/materials.md)")
      ->required();
  cmd->add_option("--end", args->end, "End condition: fixed-pinned, fixed-free, pinned-pinned")
      ->capture_default_str();
  cmd->add_option("--depth", args->depth,
                  "Insertion depth: sections above it carry the force (default: the tip's length)");
  cmd->add_option("--lateral-ratio", args->lateral_ratio,
                  "Lateral over axial tip force, for the bending stress (bevels)");
  cmd->add_option("--plugin-dir", args->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->add_flag("--json", args->json, "Print one JSON object");
  cmd->callback([args] { run_strength(*args); });
}

}  // namespace mneedle::cli
