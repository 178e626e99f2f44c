// mneedle strength: buckling and material capacity of one needle (docs/model.md, "Needle
// strength").
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/strength/needle_strength.h"
#include "mneedle/strength/section_table.h"
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

// The plugin's analytic hook when it has one (exact, cheap); the sliced mesh otherwise.
SectionTable section_table(const PluginRegistry& registry, const NeedleSource& needle) {
  const int samples = 200;
  if (!needle.plugin || !registry.shape(*needle.plugin).has_section_properties)
    return SectionTable::from_mesh(needle.mesh, samples);
  const double length = bounding_box(needle.mesh).max[2];
  std::vector<double> heights;
  std::vector<SectionProperties> sections;
  for (int i = 0; i <= samples; ++i) {
    const double h = length * i / samples;
    const auto s = registry.section_properties(*needle.plugin, needle.params, h);
    // The hook gives no fibre distance: 2√(I/A) is exact for a solid circle, an upper bound
    // for a tube (conservative for the bending check).
    const double fibre = s->area_m2 > 0 ? 2.0 * std::sqrt(s->i_min_m4 / s->area_m2) : 0.0;
    heights.push_back(h);
    sections.push_back({s->area_m2, s->i_min_m4, fibre});
  }
  return SectionTable(std::move(heights), std::move(sections));
}

void run_strength(const StrengthArgs& args) {
  if (args.file.empty() == args.plugin.empty())
    throw InputError("strength: give either a mesh FILE or --plugin NAME");
  const auto registry =
      PluginRegistry::discover({args.plugin_dirs.begin(), args.plugin_dirs.end()});
  NeedleSource needle =
      args.file.empty()
          ? needle_from_plugin(registry, args.plugin,
                               parse_parameter_settings(registry.shape(args.plugin), args.settings))
          : needle_from_file(args.file, length_unit_scale(args.unit), parse_axis_choice(args.axis));
  if (!needle.frame_note.empty())
    std::cerr << "mneedle: " << args.file << ": " << needle.frame_note << "\n";
  if (args.file.empty())
    record_mesh(needle.name, needle.mesh);
  else
    record_input("needle", args.file);
  const NeedleMaterial material = find_needle_material(args.material);
  const SectionTable table = section_table(registry, needle);

  StrengthOptions options;
  options.length_m = table.length_m();
  options.end = parse_end_condition(args.end);
  options.lateral_ratio = args.lateral_ratio;
  options.load_height_m =
      args.depth.empty() ? table.tip_length_m() : parse_quantity(args.depth, Dimension::Length);
  const StrengthReport r = needle_strength(table.profile(), material, options);

  nlohmann::json out = {{"needle", needle.name},
                        {"material", material.name},
                        {"E_Pa", material.youngs_modulus_pa},
                        {"strength_Pa", material.strength_pa},
                        {"failure_mode", failure_mode_name(material.failure)},
                        {"end", end_condition_name(options.end)},
                        {"effective_length_factor", effective_length_factor(options.end)},
                        {"length_m", options.length_m},
                        {"load_height_m", options.load_height_m},
                        {"I_min_m4", r.i_min_m4},
                        {"A_min_m2", r.a_min_m2},
                        {"elastic_buckling_N", r.elastic_buckling_n},
                        {"johnson", r.johnson},
                        {"buckling_N", r.buckling_n},
                        {"strength_N", r.strength_n},
                        {"critical_height_m", r.critical_height_m},
                        {"capacity_N", r.capacity_n},
                        {"governing", r.governing}};
  // Text and JSON print the same numbers: check them once, before either.
  require_finite_json(out, "strength");
  if (args.json) {
    std::cout << with_provenance(out).dump(2) << "\n";
    return;
  }
  std::cout << needle.name << " in " << material.name << " (" << end_condition_name(options.end)
            << ", loaded from " << format_quantity(options.load_height_m, Dimension::Length)
            << " above the tip)\n"
            << "  buckling:  " << format_quantity(r.buckling_n, Dimension::Force)
            << (r.johnson ? "  (Johnson, inelastic)" : "  (Euler, elastic)") << "\n"
            << "  strength:  " << format_quantity(r.strength_n, Dimension::Force) << "  ("
            << failure_mode_name(material.failure) << " at "
            << format_quantity(r.critical_height_m, Dimension::Length) << " above the tip)\n"
            << "  capacity:  " << format_quantity(r.capacity_n, Dimension::Force)
            << "  governed by " << r.governing << "\n";
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
