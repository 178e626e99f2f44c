#include "mneedle/design_evaluation.h"

#include <algorithm>
#include <cmath>

#include "mneedle/error.h"
#include "mneedle/section_table.h"
#include "mneedle/surface_groups.h"
#include "mneedle/units.h"

namespace mneedle {
namespace {

DesignGeometry describe(const TriangleMesh& mesh, const SectionTable& sections) {
  DesignGeometry g;
  g.triangles = mesh.triangles.size();
  g.volume_m3 = signed_volume(mesh);
  g.area_m2 = surface_area(mesh);
  g.length_m = sections.length_m();
  g.tip_length_m = sections.tip_length_m();
  const SurfaceGroups groups = classify_surface(mesh);
  g.alpha_area_m2 = groups.of(SurfaceGroup::alpha).area_m2;
  g.beta_area_m2 = groups.of(SurfaceGroup::beta).area_m2;
  return g;
}

double evaluation_depth(const Scene& scene) {
  return scene.requirements.target_depth.value_or(scene.insertion.depth);
}

}  // namespace

std::vector<NeedleMaterial> scene_needle_materials(const Scene& scene) {
  std::vector<NeedleMaterial> out;
  for (const auto& m : scene.materials)
    out.push_back({m.name, m.youngs_modulus, m.poisson_ratio, m.strength, FailureMode::Fracture,
                   scene.source_name + ":" + std::to_string(m.line)});
  return out;
}

DesignEvaluation evaluate_design(const TriangleMesh& mesh, const Scene& scene,
                                 const std::string& needle_material,
                                 const EvaluationOptions& options) {
  DesignEvaluation e;
  const SectionTable sections = SectionTable::from_mesh(mesh);
  e.geometry = describe(mesh, sections);
  e.depth_m = evaluation_depth(scene);
  if (e.depth_m >= e.geometry.length_m)
    throw InputError("needle of length " + format_quantity(e.geometry.length_m, Dimension::Length) +
                     " cannot reach the depth " + format_quantity(e.depth_m, Dimension::Length));

  const SurfaceLoadModel loads(mesh, load_constants(scene));
  for (int i = 1; i <= options.depth_steps; ++i) {
    const LoadSample s = loads.at(e.depth_m * i / options.depth_steps);
    e.peak_force_n = std::max(e.peak_force_n, s.force_N);
    e.force_at_depth_n = s.force_N;
  }

  const NeedleMaterial material =
      find_needle_material(needle_material, scene_needle_materials(scene));
  e.material = material.name;
  StrengthOptions so;
  so.length_m = e.geometry.length_m;
  // The weakest loaded section is the one at the tissue surface when the tip has just gone in;
  // the tip itself is carried by the tissue around it.
  so.load_height_m = std::min(e.geometry.tip_length_m, 0.999 * e.geometry.length_m);
  e.strength = needle_strength(options.section_hook.value_or(sections.profile()), material, so);
  e.margin = strength_margin(e.strength.capacity_n, e.peak_force_n);
  e.safety_factor = scene.requirements.safety_factor;
  e.passes = e.margin >= e.safety_factor;
  if (!e.passes)
    e.notes.push_back("strength margin " + std::to_string(e.margin) + " below the safety factor " +
                      std::to_string(e.safety_factor));
  return e;
}

}  // namespace mneedle
