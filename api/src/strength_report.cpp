#include "mneedle/api/strength_report.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mneedle/api/finite_json.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/geometry/cross_section.h"
#include "mneedle/strength/needle_strength.h"
#include "mneedle/strength/section_table.h"

namespace mneedle {
namespace {

// --depth (the CLI's name; Python's `depth`) with its name in a unit error.
double depth_quantity(const std::string& text) {
  try {
    return parse_quantity(text, Dimension::Length);
  } catch (const InputError& e) {
    throw InputError(std::string("--depth: ") + e.what());
  }
}

// An area for a message: four significant digits (a needle's section is ~1e-8 m^2).
std::string area_text(double m2) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g m^2", m2);
  return text;
}

// How far a plugin's section hook may differ from a slice of its mesh (relative to the larger).
constexpr double kHookMeshTolerance = 0.2;

// The plugin's analytic hook when it has one (exact, cheap); the sliced mesh otherwise.
SectionTable section_table(const PluginRegistry& registry, const NeedleSource& needle) {
  const int samples = 200;
  if (!needle.plugin || !registry.shape(*needle.plugin).has_section_properties)
    return SectionTable::from_mesh(needle.mesh, samples);
  const double length = bounding_box(needle.mesh).max[2];
  // The table lives within strength_report(), inside the registry's lifetime.
  SectionProfile exact = [&registry, plugin = *needle.plugin,
                          params = needle.params](double height_m) {
    const auto s = registry.section_properties(plugin, params, height_m);
    // The hook gives no fibre distance: 2√(I/A) is exact for a solid circle, an upper bound
    // for a tube (conservative for the bending check).
    const double fibre = s->area_m2 > 0 ? 2.0 * std::sqrt(s->i_min_m4 / s->area_m2) : 0.0;
    return SectionProperties{s->area_m2, s->i_min_m4, fibre};
  };
  // The hook is the plugin's word for its own mesh: checked against slices of it at a few
  // heights, so that a hook that is wrong (a unit slip, another shape's formula) is named rather
  // than trusted (it gave a capacity 1000 times too large). kHookMeshTolerance: the coarsest
  // mesh a plugin may make (8 segments) holds 10 % less than its circle.
  const CrossSectionSlicer slicer(needle.mesh);
  for (const double share : {0.25, 0.5, 0.75, 0.999}) {
    const double h = share * length;
    const double hook = exact(h).area_m2, mesh = slicer.slice(h).area_m2;
    if (std::abs(hook - mesh) > kHookMeshTolerance * std::max(hook, mesh))
      throw InputError(needle.name + ": the plugin's section hook gives " + area_text(hook) +
                       " at " + format_quantity(h, Dimension::Length) +
                       " above the tip, its mesh " + area_text(mesh) +
                       ": the hook does not describe the shape");
  }
  return SectionTable::from_profile(std::move(exact), length, samples);
}

}  // namespace

nlohmann::json strength_report(const PluginRegistry& registry, const NeedleSource& needle,
                               const StrengthSettings& settings) {
  if (settings.material.empty()) throw InputError("strength: no needle material given");
  const NeedleMaterial material = find_needle_material(settings.material);
  const SectionTable table = section_table(registry, needle);

  StrengthOptions options;
  options.length_m = table.length_m();
  options.end = parse_end_condition(settings.end);
  options.lateral_ratio = settings.lateral_ratio;
  options.load_height_m =
      settings.depth.empty() ? table.tip_length_m() : depth_quantity(settings.depth);
  const StrengthReport r = needle_strength(table.profile(), material, options);

  const nlohmann::json out = {{"needle", needle.name},
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
  require_finite_json(out, "strength");
  return out;
}

}  // namespace mneedle
