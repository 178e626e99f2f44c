#include "insertion/insertion_planner.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fe/needle_shape.h"
#include "mneedle/base/error.h"
#include "mneedle/fe/material.h"

namespace mneedle::detail {
namespace {

std::string um(double metres) {
  std::ostringstream out;
  out.precision(4);
  out << metres * 1e6 << " um";
  return out.str();
}

double max_radius_below(const TriangleMesh& mesh, double height) {
  return fe::NeedleShape(mesh).max_radius_up_to(height);
}

// A mirror plane x = 0 (y = 0) holds when every needle is symmetric about its own plane in that
// direction and has a twin of the same mesh at its mirror image (itself when on the plane).
bool mirror_holds(const std::vector<PreparedNeedle>& needles, bool across_x) {
  return std::all_of(needles.begin(), needles.end(), [&](const PreparedNeedle& n) {
    if (!(across_x ? n.mirror_symmetric_x0 : n.mirror_symmetric_y0)) return false;
    const double x = across_x ? -n.x : n.x, y = across_x ? n.y : -n.y;
    return std::any_of(needles.begin(), needles.end(), [&](const PreparedNeedle& m) {
      return m.x == x && m.y == y && m.mesh.vertices == n.mesh.vertices &&
             m.mesh.triangles == n.mesh.triangles;
    });
  });
}

// The energy criterion cracks each needle on the plane x = needle x: not on a mirror plane.
bool crack_on_x_mirror(const RunPlan& plan, const std::vector<PreparedNeedle>& needles) {
  return plan.threshold && plan.threshold->criterion == PunctureCriterion::Energy &&
         std::any_of(needles.begin(), needles.end(),
                     [](const PreparedNeedle& n) { return n.x == 0.0; });
}

void choose_mirror_planes(RunPlan& plan, const std::vector<PreparedNeedle>& needles) {
  plan.half_model = mirror_holds(needles, false);
  plan.mirror_x = mirror_holds(needles, true) && !crack_on_x_mirror(plan, needles);
}

bool on_axis(const PreparedNeedle& n) {
  return std::hypot(n.x, n.y) < 1e-12;
}

PreKind choose_model(const Scene& scene, const std::vector<PreparedNeedle>& needles,
                     const InsertionRunOptions& options, std::vector<Reduction>& reductions) {
  const bool axisymmetric_ok =
      needles.size() == 1 && needles.front().axisymmetric.has_value() && on_axis(needles.front());
  switch (options.model) {
    case PreModel::Analytic:
      return PreKind::Analytic;
    case PreModel::Full3d:
      return PreKind::Full3d;
    case PreModel::Axisymmetric:
      if (!axisymmetric_ok) {
        const NeedleSpec& spec = scene.needles.front();
        throw InputError(scene.source_name + ":" + std::to_string(spec.line) + ": needle '" +
                         spec.name + "': " +
                         (needles.size() != 1
                              ? std::to_string(needles.size()) +
                                    " needles need the 3-D model; the axisymmetric model takes one"
                          : !needles.front().axisymmetric
                              ? std::string("not a body of revolution; this needle needs "
                                            "the 3-D model")
                              : std::string("not on the block's axis (x = y = 0); it needs "
                                            "the 3-D model")));
      }
      return PreKind::Axisymmetric;
    case PreModel::Auto:
      break;
  }
  if (axisymmetric_ok) {
    reductions.push_back(
        {"axisymmetric",
         "one needle of revolution on the axis: axisymmetric model on a cylinder of the block's "
         "cross-section area instead of the 3-D block (tested against the 3-D model in "
         "tests/core/insertion/test_insertion_run.cpp)",
         std::nullopt});
    return PreKind::Axisymmetric;
  }
  return PreKind::Full3d;
}

// Layers whose top lies deeper than the needles' influence become one substrate layer with the
// material of the shallowest of them: the field there is too weak for their contrast to matter.
void merge_deep_layers(RunPlan& plan, double influence) {
  double top = 0.0;
  std::size_t first_deep = plan.layers.size();
  for (std::size_t i = 0; i < plan.layers.size(); ++i) {
    if (i > 0 && top >= influence) {
      first_deep = i;
      break;
    }
    top += plan.layers[i].thickness;
  }
  if (first_deep + 1 >= plan.layers.size()) return;
  double merged = 0.0;
  std::string names;
  for (std::size_t i = first_deep; i < plan.layers.size(); ++i) {
    merged += plan.layers[i].thickness;
    names += (names.empty() ? "" : ", ") + plan.layers[i].name;
  }
  const std::size_t count = plan.layers.size() - first_deep;
  plan.layers.resize(first_deep + 1);
  plan.layers.back().thickness = merged;
  plan.reductions.push_back({"layer_merge",
                             std::to_string(count) + " layers below " + um(top) + " (" + names +
                                 ") merged into one substrate with the material of '" +
                                 plan.layers.back().name + "': deeper than " +
                                 std::to_string(static_cast<int>(kInfluenceDepths)) +
                                 " x (needle radius + pre-puncture horizon) = " + um(influence),
                             std::nullopt});
}

// The block beyond the needles' reach carries almost no strain: keep kDomainReach (a + d) around
// them (the block stays centred on the scene's origin, so the needles keep their coordinates).
// run_insertion measures the truncation error and undoes the cut when it is above tolerance.
void cut_domain(RunPlan& plan, const std::vector<PreparedNeedle>& needles) {
  const double reach = domain_reach(plan.needle_radius_m, plan.horizon_m);
  double half_x = 0.0, half_y = 0.0;
  for (const PreparedNeedle& n : needles) {
    half_x = std::max(half_x, std::abs(n.x));
    half_y = std::max(half_y, std::abs(n.y));
  }
  const double cut_x = std::min(plan.block_x_m, 2.0 * (half_x + reach));
  const double cut_y = std::min(plan.block_y_m, 2.0 * (half_y + reach));
  if (cut_x >= plan.block_x_m && cut_y >= plan.block_y_m) return;
  plan.block_x_m = cut_x;
  plan.block_y_m = cut_y;
  plan.reductions.push_back(
      {"domain_cut",
       "block " + um(plan.full_block_x_m) + " x " + um(plan.full_block_y_m) + " cut to " +
           um(cut_x) + " x " + um(cut_y) + ": " + std::to_string(static_cast<int>(kDomainReach)) +
           " x (needle radius + pre-puncture horizon) = " + um(reach) + " around the needles",
       std::nullopt});
}

}  // namespace

double domain_reach(double needle_radius_m, double insertion_depth_m) {
  return kDomainReach * (needle_radius_m + insertion_depth_m);
}

double reduction_tolerance(fe::Fidelity fidelity) {
  switch (fidelity) {
    case fe::Fidelity::Fast:
      return 0.05;
    case fe::Fidelity::Standard:
      return 0.02;
    case fe::Fidelity::Fine:
      return 0.01;
  }
  return 0.02;
}

double pre_puncture_horizon(int rung) {
  return std::ldexp(kFirstHorizon, rung);
}

int rung_covering(double depth_m) {
  int rung = 0;
  // A depth equal to a rung (to round-off) is covered by that rung.
  while (pre_puncture_horizon(rung) < depth_m * (1.0 - 1e-12) && rung < 60) ++rung;
  return rung;
}

double influence_depth(double needle_radius_m, double insertion_depth_m) {
  return kInfluenceDepths * (needle_radius_m + insertion_depth_m);
}

std::vector<fe::TissueLayer> fe_layers(const Scene& scene) {
  std::vector<fe::TissueLayer> layers;
  for (std::size_t i = 0; i < scene.tissue.layers.size(); ++i) {
    const TissueLayer& l = scene.tissue.layers[i];
    fe::MaterialParameters p;
    p.model = l.material.model;
    p.E = l.material.youngs_modulus;
    p.nu = l.material.poisson_ratio;
    p.c10 = l.material.c10;
    p.c01 = l.material.c01;
    try {
      fe::Material check(p);
    } catch (const InputError& e) {
      throw InputError(scene.source_name + ":" + std::to_string(l.line) + ": tissue.layers[" +
                       std::to_string(i) + "] '" + l.name + "': " + e.what());
    }
    layers.push_back({l.name, l.thickness, p});
  }
  return layers;
}

RunPlan plan_insertion(const Scene& scene, const std::vector<PreparedNeedle>& needles,
                       const InsertionRunOptions& options, double horizon_m) {
  RunPlan plan;
  plan.depth_m = scene.insertion.depth;
  plan.horizon_m = horizon_m;
  plan.layers = fe_layers(scene);
  plan.full_layers = plan.layers;
  plan.block_x_m = scene.tissue.size[0];
  plan.block_y_m = scene.tissue.size[1];
  plan.full_block_x_m = plan.block_x_m;
  plan.full_block_y_m = plan.block_y_m;
  plan.vtu_directory = options.vtu_directory;
  plan.vtu_comment = options.vtu_comment;
  plan.inp_path = options.inp_path;
  plan.inp_depth_m = options.inp_depth_m;
  plan.inp_comment = options.inp_comment;
  for (const PreparedNeedle& n : needles)
    plan.needle_radius_m = std::max(plan.needle_radius_m, max_radius_below(n.mesh, plan.horizon_m));

  plan.steps = options.steps > 0                        ? options.steps
               : options.overrides.steps                ? *options.overrides.steps
               : options.fidelity == fe::Fidelity::Fast ? 10
               : options.fidelity == fe::Fidelity::Fine ? 40
                                                        : 20;
  const bool wants_puncture = scene.model.wants(Output::Puncture);
  const bool wants_curve = scene.model.wants(Output::ForceCurve);
  if (!wants_puncture && wants_curve && !scene.model.wants(Output::Fields)) {
    plan.pre = PreKind::None;
    plan.post_stage = true;
    plan.reductions.push_back({"no_fe",
                               "outputs ask for the post-puncture force curve only: no "
                               "pre-puncture model runs, every point is post-puncture",
                               std::nullopt});
    return plan;
  }
  if (has_puncture_data(scene) || options.criterion != scene.model.criterion)
    plan.threshold = puncture_threshold(scene, options.criterion);
  plan.post_stage = wants_curve && plan.threshold.has_value();
  if (plan.threshold && !wants_curve)
    plan.reductions.push_back({"stop_at_puncture",
                               "outputs ask for the puncture only: the pre-puncture model stops "
                               "at the step where the criterion fires, no post-puncture curve",
                               std::nullopt});
  plan.pre = choose_model(scene, needles, options, plan.reductions);
  if (plan.pre == PreKind::Analytic) return plan;

  if (options.allow_reductions) {
    merge_deep_layers(plan, influence_depth(plan.needle_radius_m, plan.horizon_m));
    cut_domain(plan, needles);
    if (plan.pre == PreKind::Full3d) choose_mirror_planes(plan, needles);
  }
  plan.axisymmetric_radius_m = fe::equal_area_radius(std::sqrt(plan.block_x_m * plan.block_y_m));
  return plan;
}

}  // namespace mneedle::detail
