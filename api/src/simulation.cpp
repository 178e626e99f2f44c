#include "mneedle/api/simulation.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iomanip>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <variant>

#include "mneedle/api/finite_json.h"
#include "mneedle/api/loads_json.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/fe/blas_kernels.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/insertion/energy_check.h"
#include "mneedle/insertion/penetration_force.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/needle_frame.h"

namespace mneedle {
namespace {

// A setting outside its list is a one-line error naming it (the CLI's own check says the same
// before this; a Python caller meets this one).
void check_choice(const std::string& name, const std::string& value,
                  std::initializer_list<const char*> allowed, bool empty_ok) {
  if (empty_ok && value.empty()) return;
  std::string list;
  for (const char* a : allowed) {
    if (value == a) return;
    list += (list.empty() ? "" : ", ") + std::string(a);
  }
  throw InputError("simulate: " + name + " '" + value + "' is not one of " + list);
}

nlohmann::json point_json(const RunPoint& p, std::optional<PunctureCriterion> criterion) {
  nlohmann::json j = {
      {"depth_m", p.depth_m}, {"force_N", p.force_N}, {"stage", std::string(to_string(p.stage))}};
  if (p.stage == Stage::Pre) {
    j["lateral_force_N"] = {p.lateral_force_N[0], p.lateral_force_N[1]};
    j["contact_area_m2"] = p.contact_area_m2;
    j["contact_pressure_Pa"] = p.contact_pressure_Pa;
    j["section_area_m2"] = p.section_area_m2;
    j["section_pressure_Pa"] = p.section_pressure_Pa;
    j["strain_energy_J"] = p.strain_energy_J;
    if (criterion == PunctureCriterion::Stress) j["tip_stress_Pa"] = p.tip_stress_Pa;
    if (criterion == PunctureCriterion::Energy) {
      j["energy_release_rate_J_per_m2"] = p.energy_release_rate_J_per_m2;
      j["crack_face_overlap_m"] = p.crack_face_overlap_m;
    }
    if (criterion == PunctureCriterion::Penetration)
      j["penetration_force_N"] = p.penetration_force_N;
    if (criterion == PunctureCriterion::Cohesive) {
      j["cohesive_crack_m"] = p.cohesive_crack_m;
      j["cohesive_zone_m"] = p.cohesive_zone_m;
      j["process_zone_cells"] = p.process_zone_cells;
      j["fracture_energy_J"] = p.fracture_energy_J;
      j["cohesive_failed_fraction"] = p.cohesive_failed_fraction;
    }
  } else {
    j["alpha_N"] = p.alpha_N;
    j["beta_N"] = p.beta_N;
    j["friction_N"] = p.friction_N;
    j["collar_N"] = p.collar_N;
  }
  return j;
}

nlohmann::json curve_json(const std::vector<RunPoint>& curve,
                          std::optional<PunctureCriterion> criterion) {
  nlohmann::json c = nlohmann::json::array();
  for (const RunPoint& p : curve) c.push_back(point_json(p, criterion));
  return c;
}

nlohmann::json seconds_by_stage_json(const RunSeconds& t) {
  return {{"fe_3d_s", t.fe_3d_s},
          {"axisymmetric_fe_s", t.axisymmetric_fe_s},
          {"meshing_s", t.meshing_s},
          {"assembly_s", t.assembly_s},
          {"factorization_s", t.factorization_s},
          {"contact_s", t.contact_s},
          {"stress_s", t.stress_s},
          {"factorizations", t.factorizations},
          {"shifted_factorizations", t.shifted_factorizations},
          {"fe_runs", t.fe_runs}};
}

// The BLAS kernels the factorisations ran on (fe/blas_kernels.h): a fact about the machine, as
// the time and the memory are; null where the BLAS is not OpenBLAS.
nlohmann::json blas_kernels_json() {
  const fe::BlasKernels kernels = fe::select_blas_kernels();
  if (kernels.detected.empty()) return nullptr;
  return {{"detected", kernels.detected}, {"used", kernels.used}};
}

nlohmann::json energy_check_json(const std::optional<EnergyCheck>& check) {
  if (!check) return nullptr;
  return {{"depth_m", check->depth_m},
          {"work_J", check->work_J},
          {"strain_energy_J", check->strain_energy_J},
          {"relative_difference", check->relative_difference},
          {"tolerance", kEnergyCheckTolerance},
          {"passes", check->passes}};
}

nlohmann::json run_json(const InsertionRun& run, const Scene& scene) {
  nlohmann::json needles = nlohmann::json::array();
  for (const NeedleRun& n : run.needles) {
    nlohmann::json puncture = nullptr;
    if (n.puncture) {
      puncture = {{"depth_m", n.puncture->depth_m},
                  {"force_N", n.puncture->force_N},
                  {"criterion", to_string(n.puncture->criterion)},
                  {"post_force_N", n.puncture->post_force_N},
                  {"at_first_contact", n.puncture->at_first_contact}};
      if (n.puncture->criterion == PunctureCriterion::Penetration)
        puncture["flat_tip"] = n.puncture->flat_tip;
    }
    needles.push_back({{"name", n.name},
                       {"curve", curve_json(n.curve, run.criterion)},
                       {"puncture", puncture},
                       {"max_force_N", n.max_force_N}});
  }
  nlohmann::json mesh = {{"nodes", run.nodes},
                         {"elements", run.elements},
                         {"order", run.order},
                         {"axisymmetric", run.axisymmetric}};
  if (run.min_dihedral_deg > 0.0) {
    mesh["min_dihedral_deg"] = run.min_dihedral_deg;
    mesh["max_aspect_ratio"] = run.max_aspect_ratio;
    mesh["contact_zone_m"] = run.contact_zone_m;
  }
  nlohmann::json reductions = nlohmann::json::array();
  for (const Reduction& r : run.reductions) {
    nlohmann::json j = {{"name", r.name}, {"detail", r.detail}};
    j["measured_effect"] = r.measured_effect ? nlohmann::json(*r.measured_effect) : nullptr;
    reductions.push_back(j);
  }
  nlohmann::json criterion = nullptr;
  if (run.criterion) {
    criterion = {{"name", to_string(*run.criterion)}, {"threshold", *run.threshold}};
    if (*run.criterion == PunctureCriterion::Energy) criterion["crack_depth_m"] = run.crack_depth_m;
    if (*run.criterion == PunctureCriterion::Cohesive) {
      const Fracture& f = *scene.tissue.layers.front().fracture;
      criterion["crack_depth_m"] = run.crack_depth_m;
      criterion["cohesive_strength_Pa"] = *f.cohesive_strength;
      criterion["cohesive_peak_ratio"] = f.cohesive_peak_ratio;
    }
  }
  return {{"needles", needles},
          {"mesh", mesh},
          {"total_curve", curve_json(run.total_curve, std::nullopt)},
          {"models_run", run.models_run},
          {"reductions", reductions},
          {"fidelity", fe::to_string(run.fidelity)},
          {"criterion", criterion},
          {"loads", resolved_loads_json(scene)},
          {"pre_puncture_horizon_m", run.horizon_m},
          {"pre_puncture_step_m", run.first_step_m},
          {"pre_puncture_rungs_m", run.rungs_m},
          {"energy_check", energy_check_json(run.energy_check)},
          {"peak_memory_bytes", run.peak_memory_bytes},
          {"blas_kernels", blas_kernels_json()},
          {"seconds_by_stage", seconds_by_stage_json(run.seconds_by_stage)},
          {"seconds", run.seconds},
          {"stopped", run.stopped ? nlohmann::json{{"depth_m", run.stopped->depth_m},
                                                   {"reason", run.stopped->reason}}
                                  : nlohmann::json(nullptr)}};
}

}  // namespace

void apply_simulate_settings(Scene& scene, const SimulateSettings& s) {
  check_choice("fidelity", s.fidelity, {"fast", "standard", "fine"}, true);
  check_choice("contact", s.contact, {"sticking", "frictionless"}, true);
  check_choice("criterion", s.criterion,
               {"pressure", "energy", "stress", "penetration", "cohesive"}, true);
  check_choice("model", s.model, {"auto", "analytic", "axisymmetric", "3d"}, false);
  if (s.max_needles < 1 || s.max_needles > 100000)
    throw InputError("simulate: max_needles " + std::to_string(s.max_needles) +
                     " (from 1 to 100000)");
  if (s.axis.empty()) return;
  parse_axis_choice(s.axis);
  for (NeedleSpec& n : scene.needles) {
    if (auto* stl = std::get_if<StlGeometry>(&n.geometry)) stl->axis = s.axis;
  }
}

InsertionRunOptions simulate_run_options(const Scene& scene, const SimulateSettings& s) {
  InsertionRunOptions r = scene_run_options(scene);
  if (s.fidelity == "fast") r.fidelity = fe::Fidelity::Fast;
  if (s.fidelity == "standard") r.fidelity = fe::Fidelity::Standard;
  if (s.fidelity == "fine") r.fidelity = fe::Fidelity::Fine;
  if (s.contact == "sticking") r.contact = Contact::Sticking;
  if (s.contact == "frictionless") r.contact = Contact::Frictionless;
  if (s.criterion == "pressure") r.criterion = PunctureCriterion::Pressure;
  if (s.criterion == "energy") r.criterion = PunctureCriterion::Energy;
  if (s.criterion == "stress") r.criterion = PunctureCriterion::Stress;
  if (s.criterion == "penetration") r.criterion = PunctureCriterion::Penetration;
  if (s.criterion == "cohesive") r.criterion = PunctureCriterion::Cohesive;
  r.model = s.model == "analytic"       ? PreModel::Analytic
            : s.model == "axisymmetric" ? PreModel::Axisymmetric
            : s.model == "3d"           ? PreModel::Full3d
                                        : PreModel::Auto;
  r.max_fe_needles = s.max_needles;
  r.allow_reductions = !s.no_reductions;
  r.keep_reached = s.keep_reached;
  return r;
}

namespace {

// The energy criterion's crack faces pass through each other where their contact is not
// modelled (nonlinear tissue in 3-D, frictionless needle contact): G then counts an overlap that
// cannot happen and is too high.
std::vector<std::string> energy_warnings(const InsertionRun& run, const Scene& scene) {
  std::vector<std::string> out;
  if (run.criterion != PunctureCriterion::Energy) return out;
  for (const NeedleRun& n : run.needles) {
    double overlap = 0.0;
    for (const RunPoint& p : n.curve) overlap = std::max(overlap, p.crack_face_overlap_m);
    // 1 nm: far above what faces held in contact keep (round-off, ~1e-20 m, on the linear path;
    // at most 1e-8 x the depth, 1e-11 m at 1 mm, on the nonlinear one), far below any element.
    if (overlap > 1e-9)
      out.push_back(scene.source_name + ": needle '" + n.name + "': the crack's faces pass " +
                    "through each other by up to " + format_quantity(overlap, Dimension::Length) +
                    (scene.model.crack_faces == CrackFaces::Free
                         ? std::string(" ([model] crack_faces = \"free\" leaves them free), ")
                         : std::string(" (their contact is modelled with sticking needle contact "
                                       "only), ")) +
                    "so G is too high (docs/model.md, \"Crack faces in contact\")");
  }
  return out;
}

std::vector<std::string> penetration_warnings(const InsertionRun& run, const Scene& scene) {
  std::vector<std::string> out;
  if (run.criterion != PunctureCriterion::Penetration || scene.tissue.layers.empty()) return out;
  double widest_m2 = 0.0;
  for (const NeedleRun& n : run.needles)
    for (const RunPoint& p : n.curve) widest_m2 = std::max(widest_m2, p.section_area_m2);
  const double diameter = 2.0 * std::sqrt(widest_m2 / std::numbers::pi);
  const TissueLayer& top = scene.tissue.layers.front();
  const std::string layer = scene.source_name + ": tissue.layers[0] '" + top.name + "'";
  if (top.fracture && diameter > 0.0 &&
      sharp_penetration_force(top.material.youngs_modulus, top.material.poisson_ratio,
                              top.fracture->toughness, diameter / 2.0)
          .at_widest_crack)
    out.push_back(layer +
                  " is brittle against the needle (toughness / (E r) below about 0.013): its "
                  "crack would run wider than 12 needle radii, so F_p is an upper bound "
                  "(docs/model.md, \"Penetration criterion\")");
  if (scene.tissue.layers.size() > 1 && top.thickness < diameter)
    out.push_back(layer + " is " + format_quantity(top.thickness, Dimension::Length) +
                  " thick, less than the needle's diameter (" +
                  format_quantity(diameter, Dimension::Length) +
                  "): the penetration criterion takes it for a half-space, so its F_p does not "
                  "hold (docs/model.md, \"Penetration criterion\")");
  return out;
}

// The stress probe averages over balls of radius L centred at the top layer's nodes; where L is
// far below the elements no sub-point falls in any ball and the measure reads 0 at every step,
// so the criterion can never fire (docs/model.md, "Criteria", stress).
std::vector<std::string> stress_warnings(const InsertionRun& run, const Scene& scene) {
  std::vector<std::string> out;
  if (run.criterion != PunctureCriterion::Stress || scene.tissue.layers.empty()) return out;
  const TissueLayer& top = scene.tissue.layers.front();
  for (const NeedleRun& n : run.needles) {
    bool loaded = false, read = false;
    for (const RunPoint& p : n.curve) {
      if (p.stage != Stage::Pre) continue;
      loaded = loaded || p.force_N > 0.0;
      read = read || p.tip_stress_Pa != 0.0;
    }
    if (loaded && !read)
      out.push_back(scene.source_name + ": tissue.layers[0] '" + top.name +
                    "': the averaged stress read 0 at every step under needle '" + n.name +
                    "': its strength_length (" +
                    format_quantity(top.strength ? top.strength->length : 0.0, Dimension::Length) +
                    ") is far below the mesh's elements, so the stress criterion cannot fire "
                    "(docs/model.md, \"Criteria\", stress)");
  }
  if (run.unresolved_flats > 0) {
    const double widest =
        fe::kMostFlatRadiusPerLength * (top.strength ? top.strength->length : 0.0);
    out.push_back(scene.source_name + ": tissue.layers[0] '" + top.name +
                  "': " + std::to_string(run.unresolved_flats) +
                  " flat needle end(s) got no contact zone (wider than " +
                  format_quantity(widest, Dimension::Length) +
                  " in radius, or a mesh without refinement), so the stress at the flat's rim is "
                  "read on coarse cells and the depth may be a fifth too deep; set "
                  "model.contact_zone (docs/model.md, \"Tissue block and mesh\")");
  }
  return out;
}

// A stiff top layer pushed deeper than its own thickness carries the needle by membrane tension
// as well as by bending; a small-strain (linear) layer has no membrane tension, so its force and
// puncture depth are off by far more than the mesh's error (docs/validation.md, "Finite strain in
// a stiff top layer"): 1.6x the depth, 0.65x the force for paper A's skin cylinder.
std::vector<std::string> small_strain_warnings(const InsertionRun& run, const Scene& scene) {
  // The closed-form path is small strain whatever the layer's model: the advice would not hold.
  if (std::find(run.models_run.begin(), run.models_run.end(), "analytic") != run.models_run.end())
    return {};
  const NeedleRun* deepest = nullptr;
  double pushed = 0.0;
  for (const NeedleRun& n : run.needles) {
    double d = 0.0;
    if (n.puncture) {
      d = n.puncture->depth_m;
    } else {
      for (const RunPoint& p : n.curve)
        if (p.stage == Stage::Pre) d = std::max(d, p.depth_m);
    }
    if (d > pushed) pushed = d, deepest = &n;
  }
  if (deepest == nullptr) return {};
  std::optional<std::string> w = small_strain_warning(
      scene, pushed,
      "needle '" + deepest->name + "'" + (deepest->puncture ? " before it punctures" : ""));
  if (!w) return {};
  return {*w};
}

}  // namespace

std::optional<std::string> small_strain_warning(const Scene& scene, double pushed_m,
                                                const std::string& under) {
  const auto& layers = scene.tissue.layers;
  if (layers.size() < 2 || layers[0].material.model != MaterialModel::Linear) return std::nullopt;
  const TissueLayer& top = layers[0];
  const double contrast = top.material.youngs_modulus / layers[1].material.youngs_modulus;
  if (!(contrast >= kStiffTopLayerContrast) || !(top.thickness > 0.0) ||
      !(pushed_m > top.thickness) || !std::isfinite(pushed_m))
    return std::nullopt;
  std::ostringstream ratio;
  ratio << std::fixed << std::setprecision(1) << pushed_m / top.thickness;
  const std::string softer = std::to_string(std::lround(contrast));
  return scene.source_name + ": tissue.layers[0] '" + top.name +
         "' is linear (small strain) and is pushed " +
         format_quantity(pushed_m, Dimension::Length) + " deep under " + under + ", " +
         ratio.str() + " times its " + format_quantity(top.thickness, Dimension::Length) +
         " thickness, over a layer " + softer +
         " times softer: past its thickness a stiff layer also carries the needle by membrane "
         "tension, which small strain leaves out (material model \"svk\" or \"neo_hookean\" "
         "keeps E and nu with finite strain; docs/validation.md, \"Finite strain in a stiff top "
         "layer\")";
}

std::vector<std::string> criterion_warnings(const InsertionRun& run, const Scene& scene) {
  std::vector<std::string> out = penetration_warnings(run, scene);
  for (std::string& w : energy_warnings(run, scene)) out.push_back(std::move(w));
  for (std::string& w : stress_warnings(run, scene)) out.push_back(std::move(w));
  for (std::string& w : small_strain_warnings(run, scene)) out.push_back(std::move(w));
  return out;
}

nlohmann::json simulation_json(const InsertionRun& run, const Scene& scene,
                               const std::vector<PreparedNeedle>& needles,
                               const SimulateSettings& settings) {
  nlohmann::json tree = run_json(run, scene);
  // What lets a report rebuild and check each needle: its mesh's hash and the axis override.
  for (std::size_t i = 0; i < needles.size() && i < tree["needles"].size(); ++i)
    tree["needles"][i]["mesh_sha256"] = mesh_sha256(needles[i].mesh);
  if (!settings.axis.empty()) tree["axis"] = settings.axis;
  tree["warnings"] = criterion_warnings(run, scene);
  require_finite_json(tree, scene.source_name);
  return tree;
}

}  // namespace mneedle
