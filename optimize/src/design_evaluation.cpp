#include "mneedle/design_evaluation.h"

#include <algorithm>
#include <cmath>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/geometry/cross_section.h"
#include "mneedle/geometry/surface_groups.h"
#include "mneedle/strength/section_table.h"

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

std::string fidelity_name(fe::Fidelity f) {
  switch (f) {
    case fe::Fidelity::Fast:
      return "fast";
    case fe::Fidelity::Standard:
      return "standard";
    case fe::Fidelity::Fine:
      return "fine";
  }
  return "standard";
}

// The scene as run_insertion sees it for one design: one needle where the scene's first one is,
// inserted to the target depth, asking for the puncture and the force curve (no field output).
Scene design_scene(const Scene& scene, double depth_m) {
  Scene s = scene;
  NeedleSpec spec;
  if (!scene.needles.empty()) spec = scene.needles.front();
  if (spec.name.empty()) spec.name = "design";
  s.needles = {spec};
  s.insertion.depth = depth_m;
  s.model.outputs = {Output::Puncture, Output::ForceCurve};
  return s;
}

// Pressure criterion only: how close the run came to puncturing, max F / A_sec over the
// threshold. The other criteria's values are not on the curve; 0 then.
double criterion_ratio(const InsertionRun& run, const NeedleRun& needle) {
  if (!run.criterion || !run.threshold || *run.criterion != PunctureCriterion::Pressure ||
      !(*run.threshold > 0.0))
    return 0.0;
  double peak = 0.0;
  for (const RunPoint& p : needle.curve)
    if (p.stage == Stage::Pre) peak = std::max(peak, p.section_pressure_Pa);
  return std::clamp(peak / *run.threshold, 0.0, 1.0);
}

void add_insertion(DesignEvaluation& e, const TriangleMesh& mesh, const Scene& scene,
                   const EvaluationOptions& options) {
  PreparedNeedle needle;
  needle.mesh = mesh;
  apply_symmetry(options.symmetry, needle);
  const Scene s = design_scene(scene, e.depth_m);
  needle.name = s.needles.front().name;
  needle.x = s.needles.front().at[0];
  needle.y = s.needles.front().at[1];
  InsertionRunOptions ro;
  ro.fidelity = options.fidelity;
  ro.overrides = options.overrides;
  ro.contact = scene.model.contact;
  ro.criterion = scene.model.criterion;
  ro.model = options.model;
  const InsertionRun run = run_insertion(s, {needle}, ro);
  const NeedleRun& n = run.needles.front();
  e.models_run = run.models_run;
  for (const auto& r : run.reductions) e.reductions.push_back(r.name);
  e.insertion_seconds = run.seconds;
  for (const RunPoint& p : n.curve)
    if (p.depth_m <= e.depth_m * (1.0 + 1e-9)) {
      e.peak_force_n = std::max(e.peak_force_n, p.force_N);
      e.curve.push_back({p.depth_m, p.force_N, p.stage});
    }
  if (!n.curve.empty()) e.force_at_depth_n = n.curve.back().force_N;
  if (n.puncture && n.puncture->depth_m <= e.depth_m * (1.0 + 1e-9)) {
    e.puncture =
        PunctureSummary{n.puncture->depth_m,          n.puncture->force_N,
                        n.puncture->post_force_N,     std::string(to_string(n.puncture->criterion)),
                        n.puncture->at_first_contact, n.puncture->flat_tip};
    e.reaches_target = true;
    if (n.puncture->at_first_contact) {
      // No depth to optimise: the objective is the flat "no information" value, 2 x the depth.
      e.puncture_objective_m = 2.0 * e.depth_m;
      e.notes.push_back("the " + std::string(to_string(n.puncture->criterion)) +
                        " criterion fires at the first depth step (" +
                        format_quantity(n.puncture->depth_m, Dimension::Length) +
                        "): the puncture depth is not resolved for this tip and tissue");
    } else {
      e.puncture_objective_m = n.puncture->depth_m;
    }
    if (n.puncture->flat_tip)
      e.notes.push_back(
          "the needle ends in a flat: the penetration criterion's force is a sharp tip's, so "
          "this puncture depth is a lower bound (docs/model.md, \"Penetration criterion\")");
  } else {
    e.puncture_objective_m = e.depth_m * (2.0 - criterion_ratio(run, n));
    e.notes.push_back(run.criterion ? "no puncture up to the target depth " +
                                          format_quantity(e.depth_m, Dimension::Length)
                                    : "the scene's top layer has no puncture data (fracture or "
                                      "strength): the puncture is not modelled");
  }
}

}  // namespace

std::vector<NeedleMaterial> scene_needle_materials(const Scene& scene) {
  std::vector<NeedleMaterial> out;
  for (const auto& m : scene.materials)
    out.push_back({m.name, m.youngs_modulus, m.poisson_ratio, m.strength, FailureMode::Fracture,
                   scene.source_name + ":" + std::to_string(m.line)});
  return out;
}

double max_radius_up_to(const TriangleMesh& mesh, double height_m) {
  double r = 0.0;
  for (const auto& v : mesh.vertices)
    if (v[2] <= height_m) r = std::max(r, std::hypot(v[0], v[1]));
  // The section at the height too: a cone's faces run from its point to a ring far above, so no
  // vertex but the point lies below a shallow height.
  const BoundingBox box = bounding_box(mesh);
  if (height_m > box.min[2] && height_m < box.max[2])
    for (const auto& loop : cross_section(mesh, height_m - box.min[2]).polygons)
      for (const Point2& p : loop) r = std::max(r, std::hypot(p[0], p[1]));
  return r;
}

fe::Fidelity parse_fidelity(const std::string& text) {
  if (text == "fast") return fe::Fidelity::Fast;
  if (text == "standard") return fe::Fidelity::Standard;
  if (text == "fine") return fe::Fidelity::Fine;
  throw InputError("fidelity '" + text + "': expected fast, standard or fine");
}

PreModel parse_pre_model(const std::string& text) {
  if (text == "auto") return PreModel::Auto;
  if (text == "analytic") return PreModel::Analytic;
  if (text == "axisymmetric") return PreModel::Axisymmetric;
  if (text == "3d") return PreModel::Full3d;
  throw InputError("model '" + text + "': expected auto, analytic, axisymmetric or 3d");
}

std::string to_string(PreModel model) {
  switch (model) {
    case PreModel::Auto:
      return "auto";
    case PreModel::Analytic:
      return "analytic";
    case PreModel::Axisymmetric:
      return "axisymmetric";
    case PreModel::Full3d:
      return "3d";
  }
  return "auto";
}

std::string design_material(const Scene& scene, const std::optional<std::string>& chosen) {
  if (chosen) return *chosen;
  for (const auto& n : scene.needles)
    if (n.material) return *n.material;
  return "silicon";
}

DesignEvaluation evaluate_design(const TriangleMesh& mesh, const Scene& scene,
                                 const std::string& needle_material,
                                 const EvaluationOptions& options) {
  DesignEvaluation e;
  const SectionTable sections = SectionTable::from_mesh(mesh);
  e.geometry = describe(mesh, sections);
  e.depth_m = evaluation_depth(scene);
  e.fidelity = fidelity_name(options.fidelity);
  if (e.depth_m >= e.geometry.length_m)
    throw InputError("needle of length " + format_quantity(e.geometry.length_m, Dimension::Length) +
                     " cannot reach the depth " + format_quantity(e.depth_m, Dimension::Length));
  add_insertion(e, mesh, scene, options);

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
  const bool strong = e.margin >= e.safety_factor;
  e.passes = strong && e.reaches_target;
  if (!strong)
    e.notes.push_back("strength margin " + std::to_string(e.margin) + " below the safety factor " +
                      std::to_string(e.safety_factor));
  return e;
}

}  // namespace mneedle
