#include "mneedle/insertion/insertion_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>

#include "fe/needle_shape.h"
#include "insertion/insertion_planner.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/memory.h"
#include "mneedle/base/units.h"
#include "mneedle/fe/indentation3d.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/geometry/cross_section.h"
#include "mneedle/insertion/analytic_indentation.h"
#include "mneedle/insertion/penetration_force.h"
#include "mneedle/insertion/plate_contact.h"
#include "mneedle/insertion/puncture.h"
#include "mneedle/insertion/surface_loads.h"

namespace mneedle {
namespace {

using detail::PreKind;
using detail::RunPlan;

// The area inside a needle's outer outline at the undeformed surface when its tip is `depth`
// below it: the pressure criterion's area (docs/model.md, "Criteria"). The slicer is shared so
// that bisection closures can keep it.
constexpr double kFlatProbeDepth = 1e-9;  // m

class SectionArea {
 public:
  explicit SectionArea(const TriangleMesh& mesh)
      : slicer_(std::make_shared<const CrossSectionSlicer>(mesh)) {}
  double at(double depth) const {
    return depth > 0.0 ? slicer_->slice(depth).outline_area_m2 : 0.0;
  }
  /// The penetration criterion's tissue: F_p is then available at every depth.
  void set_penetration_tissue(const TissueMaterial& material, double toughness) {
    penetration_ = PenetrationTissue{material.youngs_modulus, material.poisson_ratio, toughness};
  }
  /// F_p of the section at the surface, as a needle of equal area: the wedge that opens the
  /// crack at this depth (docs/model.md, "Penetration criterion"); 0 without the criterion.
  double penetration_force(double depth) const {
    if (!penetration_) return 0.0;
    const double radius = std::sqrt(at(depth) / std::numbers::pi);
    return sharp_penetration_force(penetration_->modulus, penetration_->poisson,
                                   penetration_->toughness, radius)
        .force_N;
  }
  /// The outline 1 nm above the tip is wider than a 0.5 um circle: a flat end, not a point (a
  /// cone gives 0 there, a 5 um spherical cap 0.1 um, a 50 um flat 25 um).
  bool ends_flat() const { return std::sqrt(at(kFlatProbeDepth) / std::numbers::pi) > 0.5e-6; }
  double penetration_ratio(double force, double depth) const {
    const double fp = penetration_force(depth);
    return fp > 0.0 ? force / fp : 0.0;
  }

 private:
  struct PenetrationTissue {
    double modulus = 0.0;
    double poisson = 0.0;
    double toughness = 0.0;
  };
  std::shared_ptr<const CrossSectionSlicer> slicer_;
  std::optional<PenetrationTissue> penetration_;
};

double pressure_over(double force, double area) {
  return area > 0.0 ? force / area : 0.0;
}

// Pre-puncture history of one needle: the curve points and what the criteria read.
struct PreSeries {
  std::vector<RunPoint> points;
  std::vector<CriterionSample> samples;
  std::function<double(double)> resolve;  ///< criterion at any depth, when cheap (analytic)
};

// Adds the wall time of its scope to a RunSeconds field (also when the model throws: a failed
// proxy's time was spent too).
class StageTimer {
 public:
  StageTimer(RunSeconds* seconds, double RunSeconds::*field)
      : seconds_(seconds), field_(field), start_(std::chrono::steady_clock::now()) {
    if (seconds_ != nullptr) ++seconds_->fe_runs;
  }
  ~StageTimer() {
    if (seconds_ != nullptr)
      seconds_->*field_ +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  RunSeconds* seconds_;
  double RunSeconds::*field_;
  std::chrono::steady_clock::time_point start_;
};

struct PreResult {
  std::vector<PreSeries> needles;
  int nodes = 0;
  int elements = 0;
  int order = 0;
  bool axisymmetric = false;
  double min_dihedral_deg = 0.0;
  double max_aspect_ratio = 0.0;
  double contact_zone_m = 0.0;
  int unresolved_flats = 0;
  std::string model;
  std::optional<fe::InpExport> exported;
  std::optional<RunStop> stopped;  ///< run_3d / run_axisymmetric with keep_reached
};

// True when the main pre-puncture run that stopped with `e` after `reached` steps keeps them
// (the caller asked, there is at least one, and it is not memory); the caller rethrows otherwise.
template <typename Step>
bool keeps_reached(const SolverError& e, bool keep_reached, const std::vector<Step>& reached) {
  return keep_reached && !reached.empty() && dynamic_cast<const OutOfMemoryError*>(&e) == nullptr;
}

fe::ContactMode to_fe(Contact c) {
  return c == Contact::Frictionless ? fe::ContactMode::Frictionless : fe::ContactMode::Sticking;
}

// Tracks the criterion during a pre-puncture run: it stops once every needle has crossed, or
// at the first step at or beyond the requested depth (the model itself is built for the
// horizon, so where it stops changes nothing before that step).
//
// The cohesive criterion fires on the step after the force's peak (force_peak): its run goes one
// step beyond the requested depth, so that a peak in the last step before it is confirmed.
class CrossingWatch {
 public:
  CrossingWatch(std::size_t needles, const RunPlan& plan)
      : crossed_(needles, false),
        past_depth_(needles, false),
        last_force_(needles, 0.0),
        threshold_(plan.stop_at_crossing ? plan.threshold : std::nullopt),
        depth_m_(plan.depth_m),
        through_(plan.cohesive_through_layer) {}
  // False once every needle's criterion has reached the threshold.
  bool keep_going(std::size_t needle, const CriterionSample& s) {
    const bool peak = threshold_ && threshold_->criterion == PunctureCriterion::Cohesive;
    if (peak) {
      if (force_drop_step({last_force_[needle], s.force_N}) ||
          (through_ && s.cohesive_failed_fraction >= kCutThrough))
        crossed_[needle] = true;
      last_force_[needle] = s.force_N;
      if (past_depth_[needle]) return false;
      if (s.depth_m >= depth_m_ * (1.0 - 1e-12)) past_depth_[needle] = true;
    } else {
      if (threshold_ && criterion_value(threshold_->criterion, s) >= threshold_->threshold)
        crossed_[needle] = true;
      if (s.depth_m >= depth_m_ * (1.0 - 1e-12)) return false;
    }
    if (!threshold_) return true;
    return !std::all_of(crossed_.begin(), crossed_.end(), [](bool c) { return c; });
  }

 private:
  std::vector<bool> crossed_, past_depth_;
  std::vector<double> last_force_;
  std::optional<PunctureThreshold> threshold_;
  double depth_m_ = 0.0;
  bool through_ = false;  // the cohesive ring ends at the top layer's bottom
};

// The criterion's view of one needle at one depth: a 3-D NeedleStep3d or an axisymmetric
// InsertionStep, which carry the same fields. The pressure is over the section's outline.
template <class NeedleState>
CriterionSample sample_of(double depth, const NeedleState& n, const SectionArea& area) {
  CriterionSample s;
  s.depth_m = depth;
  s.contact_pressure_Pa = pressure_over(n.force_N, area.at(depth));
  s.tip_stress_Pa = n.tip_stress_Pa;
  s.energy_release_rate_J_per_m2 = n.energy_release_rate_J_per_m2;
  s.penetration_ratio = area.penetration_ratio(n.force_N, depth);
  s.force_N = n.force_N;
  if constexpr (requires { n.cohesive_failed_fraction; })
    s.cohesive_failed_fraction = n.cohesive_failed_fraction;
  return s;
}

void set_section(RunPoint& p, const SectionArea& area) {
  p.section_area_m2 = area.at(p.depth_m);
  p.section_pressure_Pa = pressure_over(p.force_N, p.section_area_m2);
  p.penetration_force_N = area.penetration_force(p.depth_m);
}

double tip_size_3d(const RunPlan& plan, const InsertionRunOptions& options) {
  if (options.overrides.tip_size_m) return *options.overrides.tip_size_m;
  return fe::mesh_sizing(options.fidelity, options.overrides.order.value_or(2),
                         plan.needle_radius_m, std::max(plan.block_x_m, plan.block_y_m), {},
                         plan.threshold ? plan.threshold->average_length_m : 0.0)
      .fine_size;
}

// keep_reached: a stop after the first step returns what was reached (InsertionRunOptions).
PreResult run_3d(const RunPlan& plan, const std::vector<PreparedNeedle>& needles,
                 const std::vector<SectionArea>& areas, const InsertionRunOptions& options,
                 double crack_depth, bool keep_reached = false) {
  fe::TissueBlockSpec block;
  block.size_x = plan.block_x_m;
  block.size_y = plan.block_y_m;
  block.layers = plan.layers;
  std::vector<fe::Needle3d> fe_needles;
  for (const PreparedNeedle& n : needles) fe_needles.push_back({n.name, n.mesh, n.x, n.y});
  fe::Simulation3dOptions o;
  o.fidelity = options.fidelity;
  o.order = options.overrides.order.value_or(2);
  o.depth = plan.horizon_m;
  o.steps = plan.steps;
  o.vtu_directory = plan.vtu_directory;
  o.vtu_comment = plan.vtu_comment;
  o.vtu_depth_m = plan.shown_depth_m;
  o.inp_path = plan.inp_path;
  o.inp_depth_m = plan.inp_depth_m;
  o.inp_comment = plan.inp_comment;
  o.contact = to_fe(options.contact);
  o.overrides = options.overrides;
  o.half_model = plan.half_model;
  o.mirror_x = plan.mirror_x;
  if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Stress)
    o.stress_average_length_m = plan.threshold->average_length_m;
  if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Energy)
    o.crack_depth_m = crack_depth;
  o.crack_face_contact = options.crack_face_contact;
  CrossingWatch watch(needles.size(), plan);
  int step_index = 0;
  bool past_shown = false;
  std::vector<fe::Step3d> reached;  // kept for a run that stops (keep_reached), with its mesh
  fe::Simulation3dResult built;
  o.on_mesh = [&](const fe::Simulation3dResult& summary) { built = summary; };
  o.on_stop_timing = [&](const fe::Timing3d& timing) { built.timing = timing; };
  o.on_step = [&](const fe::Step3d& step) {
    if (keep_reached) reached.push_back(step);
    bool more = true;
    double force = 0.0;
    for (std::size_t i = 0; i < step.needles.size(); ++i) {
      more = watch.keep_going(i, sample_of(step.depth_m, step.needles[i], areas[i])) && more;
      force += step.needles[i].force_N;
    }
    // Through the first step at or beyond the shown depth, where a run asked for that depth
    // stops.
    const bool shown = plan.shown_depth_m <= 0.0 || !past_shown;
    if (step.depth_m >= plan.shown_depth_m * (1.0 - 1e-12)) past_shown = true;
    if (options.on_progress && shown)
      options.on_progress("fe_3d", ++step_index, o.overrides.steps.value_or(o.steps), step.depth_m,
                          force);
    return more;
  };
  fe::Simulation3dResult r;
  std::optional<RunStop> stopped;
  {
    const StageTimer timer(plan.seconds, &RunSeconds::fe_3d_s);
    try {
      r = fe::simulate_3d(block, fe_needles, o);
    } catch (const SolverError& e) {
      if (!keeps_reached(e, keep_reached, reached)) throw;
      stopped = RunStop{reached.back().depth_m, e.what()};
      r = std::move(built);
      r.steps = std::move(reached);
    }
  }
  if (plan.seconds != nullptr) {
    plan.seconds->meshing_s += r.timing.meshing_s;
    plan.seconds->assembly_s += r.timing.assembly_s;
    plan.seconds->factorization_s += r.timing.factorization_s;
    plan.seconds->contact_s += r.timing.contact_s;
    plan.seconds->stress_s += r.timing.stress_s;
    plan.seconds->factorizations += r.timing.factorizations;
    plan.seconds->shifted_factorizations += r.timing.shifted_factorizations;
  }
  PreResult out;
  out.needles.resize(needles.size());
  for (const fe::Step3d& step : r.steps)
    for (std::size_t i = 0; i < step.needles.size() && i < needles.size(); ++i) {
      const fe::NeedleStep3d& n = step.needles[i];
      RunPoint p;
      p.depth_m = step.depth_m;
      p.force_N = n.force_N;
      p.lateral_force_N[0] = n.lateral_force_N[0];
      p.lateral_force_N[1] = n.lateral_force_N[1];
      p.contact_area_m2 = n.contact_area_m2;
      p.contact_pressure_Pa = n.contact_pressure_Pa;
      p.strain_energy_J = step.strain_energy_J;
      p.tip_stress_Pa = n.tip_stress_Pa;
      p.energy_release_rate_J_per_m2 = n.energy_release_rate_J_per_m2;
      p.crack_face_overlap_m = step.crack_face_overlap_m;
      set_section(p, areas[i]);
      out.needles[i].points.push_back(p);
      out.needles[i].samples.push_back(sample_of(step.depth_m, n, areas[i]));
    }
  out.nodes = r.nodes;
  out.elements = r.elements;
  out.order = r.order;
  out.min_dihedral_deg = r.quality.min_dihedral_deg;
  out.max_aspect_ratio = r.quality.max_aspect_ratio;
  out.contact_zone_m = r.contact_zone_m;
  out.unresolved_flats = r.unresolved_flats;
  out.model = "fe_3d";
  out.exported = r.exported;
  out.stopped = std::move(stopped);
  return out;
}

Reduction mirror_reduction(const RunPlan& plan) {
  const bool quarter = plan.half_model && plan.mirror_x;
  const std::string planes = quarter ? "x = 0 and y = 0" : plan.half_model ? "y = 0" : "x = 0";
  const std::string part = quarter           ? "x, y >= 0 quarter"
                           : plan.half_model ? "y >= 0 half"
                                             : "x >= 0 half";
  return {quarter ? "quarter_model" : "half_model",
          "the needles are symmetric about " + planes +
              " (each needle about its own axis, the array as a whole): the 3-D model solves the " +
              part +
              " (results reported for every needle; tested against the full model in "
              "tests/core/insertion/test_insertion_run.cpp)",
          std::nullopt};
}

// Cells of the cohesive ring per characteristic length E G_c / sigma_c^2 of its law, by fidelity
// (docs/model.md, "The cohesive criterion"): the process zone then spanned 3 / 9 / 13 cells at
// the force's peak under the validation's punch; kMinProcessZoneCells is checked there.
double cohesive_cells_per_length(fe::Fidelity f) {
  return f == fe::Fidelity::Fast ? 4.0 : f == fe::Fidelity::Fine ? 16.0 : 8.0;
}
constexpr int kMinProcessZoneCells = 3;
// Work limit: cells along the cohesive ring's line. The condensed surface holds every node of
// the line, and its damage rounds solve it again and again; a law whose length needs more cells
// than this is refused before any mesh is built.
constexpr double kMaxCohesiveCells = 150.0;

// The law's characteristic length E G_c / sigma_c^2 (m), E the top layer's modulus.
double cohesive_length(const PunctureThreshold& t, double E) {
  return E * t.threshold / (t.cohesive_strength_Pa * t.cohesive_strength_Pa);
}

// The ring's cells: the softening part of the law's length (1 - delta_y / delta_0 of it: the
// process zone shortens as the peak moves towards failure), or of a line shorter than it (a
// thin top layer), over the fidelity's cells per length.
double cohesive_ring_cell(const PunctureThreshold& t, double E, double line, fe::Fidelity f) {
  return std::min(cohesive_length(t, E) * (1.0 - t.cohesive_peak_ratio), line) /
         cohesive_cells_per_length(f);
}

// The cohesive criterion's ring: the top layer's law, the line `depth` long, its cells sized from
// the law (or the caller's cohesive_cell_m) where finer than the mesh's own.
void set_cohesive_ring(const RunPlan& plan, const InsertionRunOptions& options, double depth,
                       fe::AxisymmetricProblem& p) {
  const PunctureThreshold& t = *plan.threshold;
  p.cohesive_depth_m = depth;
  p.cohesive.toughness_J_per_m2 = t.threshold;
  p.cohesive.failure_opening_m = 2.0 * t.threshold / t.cohesive_strength_Pa;
  p.cohesive.peak_opening_m = t.cohesive_peak_ratio * p.cohesive.failure_opening_m;
  const double cell = options.cohesive_cell_m.value_or(
      cohesive_ring_cell(t, plan.full_layers.front().material.E, depth, options.fidelity));
  if (cell < fe::mesh_options_for(p).h_m) p.cohesive_cell_m = cell;
}

// keep_reached: a stop after the first step returns what was reached (InsertionRunOptions).
PreResult run_axisymmetric(const RunPlan& plan, const PreparedNeedle& needle,
                           const SectionArea& area, const InsertionRunOptions& options,
                           double crack_depth, bool keep_reached = false) {
  fe::AxisymmetricProblem p;
  for (const fe::TissueLayer& l : plan.layers) p.layers.push_back({l.thickness, l.material});
  p.radius_m = plan.axisymmetric_radius_m;
  p.needle = *needle.axisymmetric;
  p.depth_m = plan.horizon_m;
  p.fidelity = options.fidelity;
  p.contact = to_fe(options.contact);
  p.output_steps = plan.steps;
  p.overrides = options.overrides;
  p.vtu_directory = plan.vtu_directory;
  p.vtu_comment = plan.vtu_comment;
  if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Stress)
    p.stress_average_length_m = plan.threshold->average_length_m;
  if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Energy)
    p.crack_depth_m = crack_depth;
  p.crack_face_contact = options.crack_face_contact;
  if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive &&
      crack_depth > 0.0)
    set_cohesive_ring(plan, options, crack_depth, p);
  CrossingWatch watch(1, plan);
  int step_index = 0;
  std::vector<fe::InsertionStep> reached;  // kept for a run that stops (keep_reached)
  fe::InsertionResult built;               // and the mesh it ran on
  p.on_mesh = [&](const fe::InsertionResult& summary) { built = summary; };
  p.on_step = [&](const fe::InsertionStep& step) {
    if (keep_reached) reached.push_back(step);
    if (options.on_progress)
      options.on_progress("fe_axisymmetric", ++step_index,
                          p.overrides.steps.value_or(p.output_steps), step.depth_m, step.force_N);
    return watch.keep_going(0, sample_of(step.depth_m, step, area));
  };
  fe::InsertionResult r;
  std::optional<RunStop> stopped;
  {
    const StageTimer timer(plan.seconds, &RunSeconds::axisymmetric_fe_s);
    try {
      try {
        r = fe::simulate_axisymmetric(p);
      } catch (const fe::CrackedTwinError& e) {
        // On nonlinear layers the held crack faces can stop Newton first (docs/model.md, "Crack
        // faces in contact"): say how to run without them.
        const bool nonlinear = std::any_of(p.layers.begin(), p.layers.end(), [](const auto& l) {
          return l.material.model != MaterialModel::Linear;
        });
        if (p.crack_face_contact && nonlinear)
          throw SolverError(
              std::string(e.what()) +
              " ([model] crack_faces = \"free\" lets the crack's faces pass through each "
              "other instead, G then too high)");
        throw;
      }
    } catch (const SolverError& e) {
      if (!keeps_reached(e, keep_reached, reached)) throw;
      stopped = RunStop{reached.back().depth_m, e.what()};
      r = std::move(built);
      r.steps = std::move(reached);
    }
  }
  PreResult out;
  out.needles.resize(1);
  for (const fe::InsertionStep& st : r.steps) {
    RunPoint pt;
    pt.depth_m = st.depth_m;
    pt.force_N = st.force_N;
    pt.contact_area_m2 = st.contact_area_m2;
    pt.contact_pressure_Pa = st.contact_pressure_Pa;
    pt.strain_energy_J = st.strain_energy_J;
    pt.tip_stress_Pa = st.tip_stress_Pa;
    pt.energy_release_rate_J_per_m2 = st.energy_release_rate_J_per_m2;
    pt.crack_face_overlap_m = st.crack_face_overlap_m;
    pt.cohesive_crack_m = st.cohesive_crack_m;
    pt.cohesive_zone_m = st.cohesive_zone_m;
    pt.process_zone_cells = st.process_zone_cells;
    pt.fracture_energy_J = st.fracture_energy_J;
    pt.cohesive_failed_fraction = st.cohesive_failed_fraction;
    set_section(pt, area);
    out.needles[0].points.push_back(pt);
    out.needles[0].samples.push_back(sample_of(st.depth_m, st, area));
  }
  out.nodes = static_cast<int>(r.nodes);
  out.elements = static_cast<int>(r.elements);
  out.order = 2;
  out.axisymmetric = true;
  out.model = "axisymmetric_fe";
  out.stopped = std::move(stopped);
  return out;
}

// Closed-form path: each needle alone on the layered half-space through its equivalent body of
// revolution (arrays: no interaction between the needles). Pressure is its only criterion.
PreResult run_analytic(const RunPlan& plan, const Scene& scene,
                       const std::vector<PreparedNeedle>& needles,
                       const std::vector<SectionArea>& areas) {
  const bool has_criterion = plan.threshold.has_value();
  const PunctureCriterion criterion =
      has_criterion ? plan.threshold->criterion : PunctureCriterion::Pressure;
  if (has_criterion && criterion == PunctureCriterion::Energy)
    throw InputError(
        "simulate: the analytic model gives no energy release rate; the energy criterion needs "
        "--model axisymmetric or 3d");
  if (has_criterion && criterion == PunctureCriterion::Cohesive)
    throw InputError(scene.source_name +
                     ": model.criterion: \"cohesive\": the analytic model has no crack; the "
                     "cohesive criterion needs --model axisymmetric (or auto)");
  // The stress criterion in closed form: the top layer as a plate on the layer beneath, pressed
  // at one point by a pointed tip (docs/model.md, "The stress criterion on the analytic path").
  // Its force replaces the indentation law's: the stress is the plate's.
  const bool plate = has_criterion && criterion == PunctureCriterion::Stress;
  std::vector<double> depths;
  for (int k = 1; k <= plan.steps; ++k) depths.push_back(plan.horizon_m * k / plan.steps);
  PreResult out;
  for (std::size_t i = 0; i < needles.size(); ++i) {
    const PreparedNeedle& n = needles[i];
    auto profile = std::make_shared<const fe::AxisymmetricNeedle>(
        n.axisymmetric ? *n.axisymmetric
                       : equivalent_axisymmetric_needle(n.mesh, 1.05 * plan.horizon_m));
    PreSeries series;
    CrossingWatch watch(1, plan);
    std::vector<AnalyticStep> steps;
    PlateContact contact;
    if (plate) {
      try {
        contact = plate_contact(scene.tissue, profile->radii_m.front());
      } catch (const InputError& e) {
        // One line naming the scene (the message names the layer and the value).
        throw InputError(scene.source_name + ": " + e.what());
      }
      // The closed form holds while the tip alone touches the bent layer, as far as this rung of
      // the pre-puncture model goes (the puncture, or the rung's horizon before it).
      const double breaks =
          plate_depth_at_force(contact, scene.tissue, *profile,
                               plan.threshold->threshold / contact.stress_per_force_Pa_per_N);
      const double touches = point_contact_depth_limit(contact, *profile);
      if (touches < std::min(breaks, plan.horizon_m))
        throw InputError(
            scene.source_name +
            ": stress criterion on the analytic path: the needle meets the bent layer '" +
            scene.tissue.layers[0].name + "' with its flank at " +
            format_quantity(touches, Dimension::Length) +
            ", before the layer breaks under its tip at " +
            format_quantity(breaks, Dimension::Length) +
            ": no longer a point contact; use --model axisymmetric or 3d");
      for (double d : depths)
        steps.push_back({d, plate_force_at_depth(contact, scene.tissue, *profile, d), 0.0, 0.0});
    } else {
      steps = analytic_indentation(scene.tissue, *profile, depths);
    }
    for (const AnalyticStep& st : steps) {
      RunPoint p;
      p.depth_m = st.depth_m;
      p.force_N = st.force_N;
      p.contact_area_m2 = st.contact_area_m2;
      p.contact_pressure_Pa = st.contact_pressure_Pa;
      set_section(p, areas[i]);
      CriterionSample c;
      c.depth_m = st.depth_m;
      c.contact_pressure_Pa = p.section_pressure_Pa;
      c.penetration_ratio = areas[i].penetration_ratio(p.force_N, p.depth_m);
      c.force_N = p.force_N;
      if (plate) p.tip_stress_Pa = c.tip_stress_Pa = contact.stress_per_force_Pa_per_N * p.force_N;
      series.points.push_back(p);
      series.samples.push_back(c);
      if (!watch.keep_going(0, c)) break;
    }
    const Tissue tissue = scene.tissue;
    const SectionArea area = areas[i];
    const bool penetration = has_criterion && criterion == PunctureCriterion::Penetration;
    if (plate) {
      series.resolve = [contact, tissue, profile](double depth) {
        return contact.stress_per_force_Pa_per_N *
               plate_force_at_depth(contact, tissue, *profile, depth);
      };
    } else {
      series.resolve = [tissue, profile, area, penetration](double depth) {
        const double force = analytic_indentation(tissue, *profile, {depth}).front().force_N;
        return penetration ? area.penetration_ratio(force, depth)
                           : pressure_over(force, area.at(depth));
      };
    }
    out.needles.push_back(std::move(series));
  }
  out.model = "analytic";
  return out;
}

// Records a reduction's measured effect (relative force change); above the fidelity's
// tolerance renames it "<name>_rejected", says what was used instead and returns false.
bool keep_reduction(Reduction& reduction, double f_reduced, double f_full,
                    const InsertionRunOptions& options, const std::string& instead) {
  if (!(f_full > 0.0)) return true;
  reduction.measured_effect = std::abs(f_reduced - f_full) / f_full;
  const double tolerance =
      options.reduction_tolerance.value_or(detail::reduction_tolerance(options.fidelity));
  if (*reduction.measured_effect <= tolerance) return true;
  reduction.name += "_rejected";
  reduction.detail += "; measured effect above the " +
                      std::to_string(tolerance * 100.0).substr(0, 4) + " % tolerance: " + instead;
  return false;
}

// The axisymmetric model is cheap: where layers were merged, run it once more on the scene's own
// layers and measure the relative change of the force at the last common step. A merge that
// changes it by more than the fidelity's tolerance is undone (the full-layer run is used).
void check_layer_merge(const RunPlan& plan, const PreparedNeedle& needle, const SectionArea& area,
                       const InsertionRunOptions& options, double crack_depth, PreResult& reduced,
                       std::vector<Reduction>& reductions) {
  auto merge = std::find_if(reductions.begin(), reductions.end(),
                            [](const Reduction& r) { return r.name == "layer_merge"; });
  if (merge == reductions.end() || reduced.needles[0].points.empty()) return;
  RunPlan full = plan;
  full.layers = plan.full_layers;
  full.stop_at_crossing = false;  // same steps and mesh, no early stop: the reduced run's end
  full.vtu_directory.clear();
  full.depth_m = reduced.needles[0].points.back().depth_m;
  // The cohesive criterion's force is the cracked tissue's: its reference has the same ring (the
  // energy criterion's force is the intact model's, its crack a twin beside it).
  const bool cohesive = plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive;
  const PreResult reference =
      run_axisymmetric(full, needle, area, options, cohesive ? crack_depth : 0.0);
  if (keep_reduction(*merge, reduced.needles[0].points.back().force_N,
                     reference.needles[0].points.back().force_N, options,
                     "the scene's own layers were used"))
    return;
  RunPlan unmerged = plan;
  unmerged.layers = plan.full_layers;
  reduced = run_axisymmetric(unmerged, needle, area, options, crack_depth, options.keep_reached);
}

// The domain cut's truncation error, measured with the axisymmetric model (the needle itself, or
// for the 3-D model the first needle's body of revolution): the force at `depth` on the cut and on
// the full domain. Above the fidelity's tolerance the cut is undone (plan's block set back to the
// scene's) and false is returned. For the 3-D model this runs before the 3-D model, at the rung's
// horizon: the rung's mesh is then a function of the needle, the tissue and the rung alone (not of
// where the criterion fired or of the requested depth), and a rejected cut costs no 3-D solve.
bool measure_domain_cut(RunPlan& plan, const std::vector<PreparedNeedle>& needles,
                        const std::vector<SectionArea>& areas, const InsertionRunOptions& options,
                        double depth, std::optional<double> f_cut,
                        std::vector<Reduction>& reductions) {
  auto cut = std::find_if(reductions.begin(), reductions.end(),
                          [](const Reduction& r) { return r.name == "domain_cut"; });
  if (cut == reductions.end() || !(depth > 0.0)) return true;
  PreparedNeedle proxy = needles[0];
  if (!proxy.axisymmetric)
    proxy.axisymmetric = equivalent_axisymmetric_needle(proxy.mesh, 1.05 * plan.horizon_m);
  // The proxy measures the truncation only, in the axisymmetric model's own (6-node) triangles:
  // an element order asked of the 3-D model is not the proxy's to honour.
  InsertionRunOptions proxy_options = options;
  proxy_options.overrides.order.reset();
  auto reference_on = [&](double size_x, double size_y) {
    RunPlan probe = plan;
    probe.axisymmetric_radius_m = fe::equal_area_radius(std::sqrt(size_x * size_y));
    probe.stop_at_crossing = false;  // same depth steps and mesh rule, no early stop
    probe.vtu_directory.clear();
    probe.depth_m = depth;
    return run_axisymmetric(probe, proxy, areas[0], proxy_options, 0.0)
        .needles[0]
        .points.back()
        .force_N;
  };
  // For the 3-D model a proxy that cannot be solved (e.g. Newton stalling on a bevel's body of
  // revolution in a neo-Hookean tissue) leaves the cut unmeasured: the safe choice is the full
  // block, not an error that ends a run whose own model solves (docs/model.md, "Scene
  // planner", domain_cut). For the axisymmetric model the proxy is the run's own model on the full
  // block, so its failure is the run's.
  std::optional<std::string> unmeasured;
  double f_full = 0.0, f_reduced = 0.0;
  if (f_cut) {
    f_full = reference_on(plan.full_block_x_m, plan.full_block_y_m);
    f_reduced = *f_cut;
  } else {
    try {
      f_full = reference_on(plan.full_block_x_m, plan.full_block_y_m);
      f_reduced = reference_on(plan.block_x_m, plan.block_y_m);
    } catch (const OutOfMemoryError&) {
      throw;  // the whole block would need more still
    } catch (const SolverError& e) {
      unmeasured = e.what();
    }
  }
  if (unmeasured) {
    cut->name += "_rejected";
    cut->detail += "; its effect could not be measured (the axisymmetric proxy: " + *unmeasured +
                   "): the full block was used";
  } else if (keep_reduction(*cut, f_reduced, f_full, options, "the full block was used")) {
    return true;
  }
  plan.block_x_m = plan.full_block_x_m;
  plan.block_y_m = plan.full_block_y_m;
  plan.axisymmetric_radius_m = fe::equal_area_radius(std::sqrt(plan.block_x_m * plan.block_y_m));
  return false;
}

// The axisymmetric model measures its own cut after its run, at the run's last step (the run is
// the cut model's force; a rejected cut re-runs it on the full block, which is cheap).
void check_axisymmetric_domain_cut(RunPlan& plan, const PreparedNeedle& needle,
                                   const SectionArea& area, const InsertionRunOptions& options,
                                   double crack_depth, PreResult& reduced,
                                   std::vector<Reduction>& reductions) {
  if (reduced.needles[0].points.empty()) return;
  const RunPoint& last = reduced.needles[0].points.back();
  // The cut truncates the far field: under the cohesive criterion it is measured on the intact
  // tissue, both blocks run again (the run's own force is the cracked tissue's).
  const bool cohesive = plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive;
  if (measure_domain_cut(plan, {needle}, {area}, options, last.depth_m,
                         cohesive ? std::nullopt : std::optional<double>(last.force_N), reductions))
    return;
  reduced = run_axisymmetric(plan, needle, area, options, crack_depth, options.keep_reached);
}

// A run that stopped is not checked against its references (they would stop too, or cost a run
// to a depth the answer never reached): the reductions measured after the run say so.
void note_unmeasured(std::vector<Reduction>& reductions, const RunStop& stop) {
  for (Reduction& r : reductions)
    if (r.name == "layer_merge" || r.name == "domain_cut")
      r.detail +=
          "; not measured: the run stopped at " + format_quantity(stop.depth_m, Dimension::Length);
}

double axisymmetric_tip_size(const RunPlan& plan, const PreparedNeedle& needle,
                             const InsertionRunOptions& options) {
  if (options.overrides.tip_size_m) return *options.overrides.tip_size_m;
  fe::AxisymmetricProblem p;
  for (const fe::TissueLayer& l : plan.layers) p.layers.push_back({l.thickness, l.material});
  p.radius_m = plan.axisymmetric_radius_m;
  p.needle = *needle.axisymmetric;
  p.depth_m = plan.horizon_m;
  p.fidelity = options.fidelity;
  return fe::mesh_options_for(p).h_m;
}

std::vector<double> post_depths(const RunPlan& plan) {
  const int n = std::max(plan.steps, 20);
  std::vector<double> d;
  for (int k = 1; k <= n; ++k) d.push_back(plan.depth_m * k / n);
  return d;
}

RunPoint post_point(const SurfaceLoadModel& model, double depth) {
  const LoadSample s = model.at(depth);
  RunPoint p;
  p.depth_m = depth;
  p.stage = Stage::Post;
  p.force_N = s.force_N;
  p.alpha_N = s.alpha_N;
  p.beta_N = s.beta_N;
  p.friction_N = s.friction_N;
  return p;
}

// Pre-puncture point at a depth between two steps (0 before the first): each quantity linear.
RunPoint interpolated_point(const std::vector<RunPoint>& points, double depth) {
  RunPoint before;
  for (const RunPoint& p : points) {
    if (p.depth_m >= depth) {
      const double span = p.depth_m - before.depth_m;
      const double t = span > 0.0 ? (depth - before.depth_m) / span : 1.0;
      auto mix = [t](double a, double b) { return a + t * (b - a); };
      RunPoint r;
      r.depth_m = depth;
      r.force_N = mix(before.force_N, p.force_N);
      r.lateral_force_N[0] = mix(before.lateral_force_N[0], p.lateral_force_N[0]);
      r.lateral_force_N[1] = mix(before.lateral_force_N[1], p.lateral_force_N[1]);
      r.contact_area_m2 = mix(before.contact_area_m2, p.contact_area_m2);
      r.contact_pressure_Pa = r.contact_area_m2 > 0.0 ? r.force_N / r.contact_area_m2 : 0.0;
      r.strain_energy_J = mix(before.strain_energy_J, p.strain_energy_J);
      r.tip_stress_Pa = mix(before.tip_stress_Pa, p.tip_stress_Pa);
      r.energy_release_rate_J_per_m2 =
          mix(before.energy_release_rate_J_per_m2, p.energy_release_rate_J_per_m2);
      r.crack_face_overlap_m = mix(before.crack_face_overlap_m, p.crack_face_overlap_m);
      r.cohesive_crack_m = mix(before.cohesive_crack_m, p.cohesive_crack_m);
      r.cohesive_zone_m = mix(before.cohesive_zone_m, p.cohesive_zone_m);
      r.process_zone_cells = p.process_zone_cells;
      r.fracture_energy_J = mix(before.fracture_energy_J, p.fracture_energy_J);
      r.cohesive_failed_fraction = mix(before.cohesive_failed_fraction, p.cohesive_failed_fraction);
      return r;
    }
    before = p;
  }
  return points.empty() ? RunPoint{} : points.back();
}

// The post-puncture point at `depth` when the stress criterion broke a stiff top layer over
// softer ones (docs/model.md, "The broken top layer"): the layer stays gripped to the shaft and is
// dragged down, so the tissue keeps the deformation it had before the puncture, the force rising
// at the pre-puncture stiffness from the puncture force, until that needs more than the layer's
// grip, its own distributed loads (wedge and friction, capped at its strength); then it slides
// and carries its grip. The layers below carry their distributed loads throughout.
RunPoint gripped_point(const SurfaceLoadModel& model, double depth, double puncture_depth,
                       double puncture_force, double stiffness, bool& slid) {
  std::vector<LoadSample> layers;
  const LoadSample total = model.at(depth, &layers);
  const LoadSample& top = layers.front();
  RunPoint p;
  p.depth_m = depth;
  p.stage = Stage::Post;
  const double held = puncture_force + stiffness * (depth - puncture_depth);
  const double below = total.force_N - top.force_N;
  // Once it slides it does not grip again (evaluated at increasing depths).
  const double share = slid ? top.force_N : std::clamp(held - below, 0.0, top.force_N);
  slid = share >= top.force_N;
  if (slid) {  // sliding: every layer's distributed loads
    p.alpha_N = total.alpha_N;
    p.beta_N = total.beta_N;
    p.friction_N = total.friction_N;
  } else {
    p.alpha_N = total.alpha_N - top.alpha_N;
    p.beta_N = total.beta_N - top.beta_N;
    p.friction_N = total.friction_N - top.friction_N;
    p.collar_N = share;
  }
  p.force_N = p.alpha_N + p.beta_N + p.friction_N + p.collar_N;
  return p;
}

// The cohesive criterion's peak is a puncture only where the model resolves it (docs/model.md,
// "The cohesive criterion"): the process zone spans kMinProcessZoneCells cells or more at the
// highest step, and the damaged cells stop short of the crack line's end unless that end is the
// top layer's bottom (then the layer has broken through: a puncture).
void check_cohesive_peak(const RunPlan& plan, const RunPoint& at, double depth) {
  const std::string where = "cohesive criterion: at the force's peak (" +
                            format_quantity(depth, Dimension::Length) + ") ";
  if (at.process_zone_cells < kMinProcessZoneCells)
    throw SolverError(where + "the process zone spans " + std::to_string(at.process_zone_cells) +
                      " cell(s) of the ring crack, fewer than " +
                      std::to_string(kMinProcessZoneCells) +
                      ": the peak is not mesh-converged (raise [model] fidelity; at fine, a "
                      "lower cohesive_strength lengthens the process zone)");
  const double line = plan.cohesive_depth_m;
  const double layer = plan.full_layers.front().thickness;
  if (line < layer * (1.0 - 1e-9) && at.cohesive_zone_m >= line * (1.0 - 1e-9))
    throw SolverError(where + "the damage has reached the end of the " +
                      format_quantity(line, Dimension::Length) +
                      " ring crack: the peak is the line's, not the tissue's");
}

// Without a peak the damage must not have reached the end of a line that stops inside the top
// layer: the force would then be the line's, not the tissue's.
void check_cohesive_line(const RunPlan& plan, const std::vector<RunPoint>& points) {
  if (plan.cohesive_through_layer || points.empty()) return;
  const double line = plan.cohesive_depth_m;
  for (const RunPoint& p : points)
    if (p.depth_m <= plan.depth_m * (1.0 + 1e-12) && p.cohesive_zone_m >= line * (1.0 - 1e-9))
      throw SolverError("cohesive criterion: the damage reached the end of the " +
                        format_quantity(line, Dimension::Length) + " ring crack at " +
                        format_quantity(p.depth_m, Dimension::Length) +
                        " with no force peak before it: the run cannot say where the tissue "
                        "punctures");
}

NeedleRun assemble_needle(const std::string& name, const PreSeries& pre, const RunPlan& plan,
                          const SectionArea& area, const SurfaceLoadModel* post) {
  NeedleRun run;
  run.name = name;
  std::optional<Crossing> crossing;
  std::optional<double> peak_force;  // the cohesive criterion's force at its peak
  if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive) {
    std::vector<double> depths, forces;
    for (const RunPoint& p : pre.points) {
      depths.push_back(p.depth_m);
      forces.push_back(p.force_N);
    }
    double force = 0.0;
    crossing = force_peak(depths, forces, &force);
    // The ring cut through the top layer (where it ends there): the failed share reaches 1,
    // located linearly between the steps as the energy criterion's G.
    std::optional<Crossing> through;
    if (plan.cohesive_through_layer) {
      std::vector<double> failed;
      for (const RunPoint& p : pre.points) failed.push_back(p.cohesive_failed_fraction);
      through = first_crossing(depths, failed, kCutThrough);
    }
    if (through && (!crossing || through->depth_m < crossing->depth_m)) {
      crossing = through;
      peak_force.reset();
    } else if (crossing) {
      peak_force = force;
    }
    // Beyond the requested depth nothing is reported, so nothing there is checked: the step the
    // run took past it only confirms a peak before it.
    if (crossing && crossing->depth_m > plan.depth_m * (1.0 + 1e-12)) {
      crossing.reset();
      peak_force.reset();
    }
    if (crossing && peak_force)  // the highest step is the one before the drop
      check_cohesive_peak(plan, pre.points[*force_drop_step(forces) - 1], crossing->depth_m);
    if (!crossing) check_cohesive_line(plan, pre.points);
  } else if (plan.threshold) {
    std::vector<double> depths, values;
    for (const CriterionSample& s : pre.samples) {
      depths.push_back(s.depth_m);
      values.push_back(criterion_value(plan.threshold->criterion, s));
    }
    // The pressure is F(d) / A_sec(d) with A_sec exact at any depth: bisect on it with F linear
    // between the steps, so the depth moves continuously with the design (analytic runs bring
    // their own exact resolve).
    std::function<double(double)> resolve = pre.resolve;
    if (!resolve && plan.threshold->criterion == PunctureCriterion::Pressure) {
      const std::vector<RunPoint>& points = pre.points;
      resolve = [&points, &area](double depth) {
        return pressure_over(interpolated_point(points, depth).force_N, area.at(depth));
      };
    }
    if (!resolve && plan.threshold->criterion == PunctureCriterion::Penetration) {
      const std::vector<RunPoint>& points = pre.points;
      resolve = [&points, &area](double depth) {
        return area.penetration_ratio(interpolated_point(points, depth).force_N, depth);
      };
    }
    const double tolerance = plan.horizon_m / std::max(plan.steps, 1) * 1e-6;
    crossing = first_crossing(depths, values, plan.threshold->threshold, resolve, tolerance);
    if (crossing && crossing->depth_m > plan.depth_m * (1.0 + 1e-12)) crossing.reset();
    // Above the threshold at the first step: nothing before it was computed, so the crossing
    // cannot be placed inside the step. It is reported at the step, flagged at_first_contact.
    if (crossing && crossing->step == 0) {
      crossing->depth_m = depths.front();
      crossing->fraction = 1.0;
    }
  }
  if (!crossing) {
    // Up to the requested depth; a last step beyond it is cut there (linear in between).
    for (const RunPoint& p : pre.points)
      if (p.depth_m < plan.depth_m * (1.0 - 1e-12)) run.curve.push_back(p);
    // A run that stopped before the depth (keep_reached) ends at its last step, listed above.
    if (!pre.points.empty() && pre.points.back().depth_m >= plan.depth_m * (1.0 - 1e-12)) {
      RunPoint end = pre.points.back().depth_m > plan.depth_m
                         ? interpolated_point(pre.points, plan.depth_m)
                         : pre.points.back();
      set_section(end, area);
      run.curve.push_back(end);
    }
  } else {
    for (const RunPoint& p : pre.points)
      if (p.depth_m < crossing->depth_m) run.curve.push_back(p);
    RunPoint at = interpolated_point(pre.points, crossing->depth_m);
    if (peak_force) {
      at.force_N = *peak_force;
      at.contact_pressure_Pa = at.contact_area_m2 > 0.0 ? at.force_N / at.contact_area_m2 : 0.0;
    }
    set_section(at, area);
    run.curve.push_back(at);
    Puncture puncture;
    puncture.depth_m = crossing->depth_m;
    puncture.force_N = at.force_N;
    puncture.criterion = plan.threshold->criterion;
    puncture.at_first_contact = crossing->step == 0;
    puncture.flat_tip =
        plan.threshold->criterion == PunctureCriterion::Penetration && area.ends_flat();
    if (post != nullptr) {
      // A stiff top layer broken by the stress criterion over softer layers keeps its grip
      // (gripped_point); the pre-puncture stiffness at the puncture is the slope of the step it
      // lies in (from the origin in the first step).
      std::vector<double> moduli;
      for (const fe::TissueLayer& layer : plan.full_layers) moduli.push_back(layer.material.E);
      const bool gripped =
          post->layers().size() >= 2 && top_layer_grips(plan.threshold->criterion, moduli);
      const RunPoint* below = nullptr;
      const RunPoint* above = nullptr;
      for (const RunPoint& p : pre.points) {
        if (p.depth_m < crossing->depth_m) below = &p;
        if (p.depth_m >= crossing->depth_m && above == nullptr) above = &p;
      }
      const double from_d = below ? below->depth_m : 0.0, from_f = below ? below->force_N : 0.0;
      const double to_d = above ? above->depth_m : crossing->depth_m;
      const double to_f = above ? above->force_N : at.force_N;
      const double stiffness = to_d > from_d ? (to_f - from_f) / (to_d - from_d) : 0.0;
      bool slid = false;
      auto post_at = [&](double d) {
        return gripped ? gripped_point(*post, d, crossing->depth_m, at.force_N, stiffness, slid)
                       : post_point(*post, d);
      };
      puncture.post_force_N = post_at(crossing->depth_m).force_N;
      if (plan.post_stage) {
        run.curve.push_back(post_at(crossing->depth_m));
        for (double d : post_depths(plan))
          if (d > crossing->depth_m) run.curve.push_back(post_at(d));
      }
    }
    run.puncture = puncture;
  }
  for (const RunPoint& p : run.curve) run.max_force_N = std::max(run.max_force_N, p.force_N);
  return run;
}

NeedleRun post_only_needle(const std::string& name, const RunPlan& plan,
                           const SurfaceLoadModel& post) {
  NeedleRun run;
  run.name = name;
  for (double d : post_depths(plan)) run.curve.push_back(post_point(post, d));
  for (const RunPoint& p : run.curve) run.max_force_N = std::max(run.max_force_N, p.force_N);
  return run;
}

// Value of a needle's curve at `depth`: at a depth listed twice (the puncture) the first or the
// second point; between points linear; past its last point (a curve that stops at puncture) its
// last point.
RunPoint curve_at(const std::vector<RunPoint>& curve, double depth, bool after) {
  RunPoint before;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const RunPoint& p = curve[i];
    if (p.depth_m == depth) {
      if (after && i + 1 < curve.size() && curve[i + 1].depth_m == depth) return curve[i + 1];
      return p;
    }
    if (p.depth_m > depth) {
      const double span = p.depth_m - before.depth_m;
      const double t = span > 0.0 ? (depth - before.depth_m) / span : 1.0;
      RunPoint r = p;
      r.depth_m = depth;
      auto mix = [t](double a, double b) { return a + t * (b - a); };
      r.force_N = mix(before.force_N, p.force_N);
      r.lateral_force_N[0] = mix(before.lateral_force_N[0], p.lateral_force_N[0]);
      r.lateral_force_N[1] = mix(before.lateral_force_N[1], p.lateral_force_N[1]);
      r.contact_area_m2 = mix(before.contact_area_m2, p.contact_area_m2);
      r.strain_energy_J = mix(before.strain_energy_J, p.strain_energy_J);
      r.alpha_N = mix(before.alpha_N, p.alpha_N);
      r.beta_N = mix(before.beta_N, p.beta_N);
      r.friction_N = mix(before.friction_N, p.friction_N);
      r.collar_N = mix(before.collar_N, p.collar_N);
      // The section too (an array's total sums it): within one stage, between the points.
      if (i > 0 && before.stage == p.stage && p.stage == Stage::Pre) {
        r.section_area_m2 = mix(before.section_area_m2, p.section_area_m2);
        r.section_pressure_Pa = pressure_over(r.force_N, r.section_area_m2);
      }
      return r;
    }
    before = p;
  }
  return curve.empty() ? RunPoint{} : curve.back();
}

std::vector<RunPoint> total_curve(const std::vector<NeedleRun>& needles) {
  std::vector<double> depths;
  for (const NeedleRun& n : needles)
    for (const RunPoint& p : n.curve) depths.push_back(p.depth_m);
  std::sort(depths.begin(), depths.end());
  depths.erase(std::unique(depths.begin(), depths.end()), depths.end());
  std::vector<RunPoint> total;
  for (double d : depths) {
    bool split = false;  // some needle punctures exactly here: a point before and after
    for (const NeedleRun& n : needles) split = split || (n.puncture && n.puncture->depth_m == d);
    for (int side = 0; side < (split ? 2 : 1); ++side) {
      RunPoint sum;
      sum.depth_m = d;
      for (std::size_t i = 0; i < needles.size(); ++i) {
        const RunPoint p = curve_at(needles[i].curve, d, side == 1);
        if (i == 0) sum.stage = p.stage;
        sum.force_N += p.force_N;
        sum.lateral_force_N[0] += p.lateral_force_N[0];
        sum.lateral_force_N[1] += p.lateral_force_N[1];
        sum.contact_area_m2 += p.contact_area_m2;
        sum.section_area_m2 += p.section_area_m2;
        sum.alpha_N += p.alpha_N;
        sum.beta_N += p.beta_N;
        sum.friction_N += p.friction_N;
        sum.collar_N += p.collar_N;
        if (i == 0) {  // one tissue: the system's energy
          sum.strain_energy_J = p.strain_energy_J;
          sum.fracture_energy_J = p.fracture_energy_J;
        }
      }
      sum.contact_pressure_Pa = sum.contact_area_m2 > 0.0 ? sum.force_N / sum.contact_area_m2 : 0.0;
      // Before any puncture the sections carry the whole force (the post-puncture force is not
      // a section's pressure: 0 there, as on each needle's own curve).
      sum.section_pressure_Pa = sum.section_area_m2 > 0.0 && sum.alpha_N == 0.0 &&
                                        sum.beta_N == 0.0 && sum.friction_N == 0.0 &&
                                        sum.collar_N == 0.0
                                    ? sum.force_N / sum.section_area_m2
                                    : 0.0;
      total.push_back(sum);
    }
  }
  return total;
}

// The cohesive criterion's ring crack runs down the top layer from the surface at the needle's
// outer radius (docs/model.md, "The cohesive criterion"): the needle's diameter deep, as the
// energy criterion's crack, or to the top layer's bottom, where the layer beneath holds it. A
// property of the needle and the tissue: the same line on every rung.
double cohesive_line_depth(const RunPlan& plan, const fe::AxisymmetricNeedle& needle) {
  return std::min(plan.full_layers.front().thickness, 2.0 * needle.max_radius());
}

// One rung of the pre-puncture model: the FE (or analytic) run for plan.horizon_m, with the
// planner's reductions checked. Fills the run's mesh summary and crack depth.
PreResult run_pre(RunPlan& plan, const Scene& scene, const std::vector<PreparedNeedle>& needles,
                  const std::vector<SectionArea>& areas, const InsertionRunOptions& options,
                  InsertionRun& run) {
  PreResult pre;
  run.crack_depth_m = 0.0;
  switch (plan.pre) {
    case PreKind::Full3d:
      if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive)
        throw InputError(scene.source_name +
                         ": model.criterion: \"cohesive\" runs on the "
                         "axisymmetric model only (one needle of revolution on the block's axis); "
                         "this run is on the 3-D model (asked for with --model 3d, or needed by "
                         "these needles), which has no cohesive crack yet");
      if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Energy)
        run.crack_depth_m = crack_depth_for(plan.needle_radius_m, tip_size_3d(plan, options));
      measure_domain_cut(plan, needles, areas, options, plan.horizon_m, std::nullopt,
                         run.reductions);
      pre = run_3d(plan, needles, areas, options, run.crack_depth_m, options.keep_reached);
      if (plan.half_model || plan.mirror_x) run.reductions.push_back(mirror_reduction(plan));
      break;
    case PreKind::Axisymmetric:
      if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Energy)
        run.crack_depth_m =
            crack_depth_for(plan.needle_radius_m, axisymmetric_tip_size(plan, needles[0], options));
      if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive)
        run.crack_depth_m = cohesive_line_depth(plan, *needles[0].axisymmetric);
      plan.cohesive_depth_m =
          plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive
              ? run.crack_depth_m
              : 0.0;
      plan.cohesive_through_layer =
          plan.cohesive_depth_m > 0.0 &&
          plan.cohesive_depth_m >= plan.full_layers.front().thickness * (1.0 - 1e-9);
      pre = run_axisymmetric(plan, needles[0], areas[0], options, run.crack_depth_m,
                             options.keep_reached);
      if (pre.stopped) {
        note_unmeasured(run.reductions, *pre.stopped);
        break;
      }
      check_layer_merge(plan, needles[0], areas[0], options, run.crack_depth_m, pre,
                        run.reductions);
      if (pre.stopped) {  // the scene's own layers, run again, stopped
        note_unmeasured(run.reductions, *pre.stopped);
        break;
      }
      check_axisymmetric_domain_cut(plan, needles[0], areas[0], options, run.crack_depth_m, pre,
                                    run.reductions);
      break;
    case PreKind::Analytic:
      pre = run_analytic(plan, scene, needles, areas);
      break;
    case PreKind::None:
      break;
  }
  return pre;
}

// The step at which a needle's criterion fired: the first at or above its threshold, or for the
// cohesive criterion the step that confirms the force's peak (force_drop_step).
std::optional<std::size_t> fired_step(const RunPlan& plan, const PreSeries& s) {
  const PunctureThreshold& t = *plan.threshold;
  if (t.criterion == PunctureCriterion::Cohesive) {
    std::vector<double> forces;
    for (const CriterionSample& c : s.samples) forces.push_back(c.force_N);
    std::optional<std::size_t> at = force_drop_step(forces);
    // Or the ring cut through the top layer, whichever comes first.
    for (std::size_t i = 0; plan.cohesive_through_layer && i < s.samples.size(); ++i)
      if (s.samples[i].cohesive_failed_fraction >= kCutThrough) {
        if (!at || i < *at) at = i;
        break;
      }
    return at;
  }
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    if (criterion_value(t.criterion, s.samples[i]) >= t.threshold) return i;
  return std::nullopt;
}

// True when every needle's criterion reached its threshold within the requested depth (the
// cohesive criterion: a peak anywhere in the run, which went a step beyond the depth to confirm
// one; a deeper rung would find the same peak).
bool every_needle_crossed(const RunPlan& plan, const PreResult& pre) {
  if (!plan.threshold) return false;
  const bool peak = plan.threshold->criterion == PunctureCriterion::Cohesive;
  return std::all_of(pre.needles.begin(), pre.needles.end(), [&](const PreSeries& s) {
    const auto at = fired_step(plan, s);
    return at && (peak || s.samples[*at].depth_m <= plan.depth_m * (1.0 + 1e-12));
  });
}

// How far the closed form's crossing may over-estimate the 3-D model's before the start rung is
// too deep (docs/model.md, "Pre-puncture horizon"): on paper A's silicone needles it reads 17-20 %
// deeper; 1.5 leaves room for more, and a start that fires within the rung below climbs again
// from rung 0, so a larger miss costs rungs, not the answer.
constexpr double kClosedFormMargin = 1.5;

// The rung the 3-D model's ladder starts on (docs/model.md, "Pre-puncture horizon"): the rung
// that covers the closed-form model's crossing (the deepest needle's) over kClosedFormMargin, so
// the rungs a puncture cannot be on are not built. The closed form is asked on horizons fixed by
// the tissue's thickness, never by the requested depth, so the start is a property of the needle
// and the tissue too. Where the closed form has no answer the ladder starts at rung 0.
int first_rung(const Scene& scene, const std::vector<PreparedNeedle>& needles,
               const std::vector<SectionArea>& areas, const InsertionRunOptions& options) {
  const RunPlan rung0 =
      detail::plan_insertion(scene, needles, options, detail::pre_puncture_horizon(0));
  // The pressure and penetration criteria only: the closed form has no energy release rate,
  // and its stress criterion (a plate on the layer beneath) fires within the first rungs in skin
  // while costing a tenth of a second of Bessel integrals to ask.
  if (!options.start_from_closed_form || !rung0.threshold || rung0.pre != PreKind::Full3d ||
      (rung0.threshold->criterion != PunctureCriterion::Pressure &&
       rung0.threshold->criterion != PunctureCriterion::Penetration))
    return 0;
  // The deepest rung inside the block (the closed form holds above the block's bottom only).
  const int inside = detail::rung_covering(scene.tissue.size[2]) - 1;
  // An optional saving must never end a run: any failure of the closed form starts at rung 0.
  try {
    // The closed form climbs its own ladder, with the 3-D rungs' steps, to the first rung on
    // which every needle crosses: a shallow puncture costs one short closed-form run.
    for (int k = 0; k <= inside; ++k) {
      RunPlan probe =
          detail::plan_insertion(scene, needles, options, detail::pre_puncture_horizon(k));
      probe.pre = PreKind::Analytic;
      probe.depth_m = probe.horizon_m;
      const PreResult closed_form = run_analytic(probe, scene, needles, areas);
      double deepest = 0.0;
      bool every = true;
      for (const PreSeries& series : closed_form.needles) {
        std::vector<double> depths, values;
        for (const CriterionSample& c : series.samples) {
          depths.push_back(c.depth_m);
          values.push_back(criterion_value(probe.threshold->criterion, c));
        }
        // Interpolated between the steps, not bisected: the start needs the rung, not the depth.
        const auto crossing = first_crossing(depths, values, probe.threshold->threshold);
        every = every && crossing.has_value();
        if (crossing) deepest = std::max(deepest, crossing->depth_m);
      }
      if (every) return detail::rung_covering(deepest / kClosedFormMargin);
    }
    return 0;
  } catch (const std::exception&) {
    return 0;
  }
}

// The depth of the first step at or above the threshold, deepest over the needles (the
// crossing lies between that step and the one before it); 0 when a needle has none.
double deepest_first_crossing(const RunPlan& plan, const PreResult& pre) {
  double deepest = 0.0;
  for (const PreSeries& s : pre.needles) {
    const auto at = fired_step(plan, s);
    if (!at) return 0.0;
    deepest = std::max(deepest, s.samples[*at].depth_m);
  }
  return deepest;
}

}  // namespace

void check_needle_placement(const Scene& scene, const std::vector<PreparedNeedle>& needles) {
  if (needles.size() != scene.needles.size())
    throw InputError(scene.source_name + ": needles: " + std::to_string(scene.needles.size()) +
                     " in the scene but " + std::to_string(needles.size()) + " prepared");
  if (!(scene.insertion.depth > 0.0))
    throw InputError(scene.source_name + ": insertion.depth: must be positive");
  // What enters the tissue must fit in the block, and two needles cannot share tissue: a file
  // read in the wrong unit (mm as m) or a copied `at` otherwise runs and reports nonsense.
  // The same radius the planner sizes the model from: every face reaching below the depth counts
  // whole, so a coarse mesh whose next vertex ring lies above the depth is not read as radius 0.
  std::vector<double> radius(needles.size(), 0.0);
  for (std::size_t i = 0; i < needles.size(); ++i) {
    radius[i] = fe::NeedleShape(needles[i].mesh).max_radius_up_to(scene.insertion.depth);
    const NeedleSpec& spec = scene.needles[i];
    const std::string where =
        scene.source_name + ":" + std::to_string(spec.line) + ": needle '" + spec.name + "': ";
    const double half_x = 0.5 * scene.tissue.size[0], half_y = 0.5 * scene.tissue.size[1];
    if (std::abs(needles[i].x) + radius[i] > half_x || std::abs(needles[i].y) + radius[i] > half_y)
      throw InputError(where + format_quantity(2.0 * radius[i], Dimension::Length) + " wide at (" +
                       format_quantity(needles[i].x, Dimension::Length) + ", " +
                       format_quantity(needles[i].y, Dimension::Length) +
                       "), it does not fit in the " +
                       format_quantity(scene.tissue.size[0], Dimension::Length) + " x " +
                       format_quantity(scene.tissue.size[1], Dimension::Length) +
                       " block (is the mesh's unit right?)");
    for (std::size_t j = 0; j < i; ++j)
      if (std::hypot(needles[i].x - needles[j].x, needles[i].y - needles[j].y) <
          radius[i] + radius[j])
        throw InputError(
            where + "overlaps needle '" + scene.needles[j].name + "' (axes " +
            format_quantity(std::hypot(needles[i].x - needles[j].x, needles[i].y - needles[j].y),
                            Dimension::Length) +
            " apart, radii " + format_quantity(radius[i], Dimension::Length) + " and " +
            format_quantity(radius[j], Dimension::Length) + ")");
  }
}

bool top_layer_grips(PunctureCriterion criterion, const std::vector<double>& layer_moduli_Pa) {
  return criterion == PunctureCriterion::Stress && layer_moduli_Pa.size() >= 2 &&
         layer_moduli_Pa[0] > layer_moduli_Pa[1];
}

namespace {

// The cohesive ring crack is solved on the linear model's condensed surface (docs/model.md,
// "Cohesive ring crack"): linear layers and sticking contact only.
void check_cohesive_tissue(const Scene& scene, const std::vector<PreparedNeedle>& needles,
                           const PunctureThreshold& t, const InsertionRunOptions& options) {
  for (const TissueLayer& layer : scene.tissue.layers)
    if (layer.material.model != MaterialModel::Linear)
      throw InputError(scene.source_name + ":" + std::to_string(layer.line) + ": tissue.layers '" +
                       layer.name + "': material.model: \"" +
                       std::string(to_string(layer.material.model)) +
                       "\"; the cohesive criterion needs linear layers");
  if (options.contact != Contact::Sticking)
    throw InputError(scene.source_name +
                     ": model.contact: the cohesive criterion needs sticking contact");
  // Work limit, before any mesh: the ring's cells down its line (the line and its cells are the
  // needle's and the top layer's; a 3-D needle is refused by the run itself).
  if (needles.size() != 1 || !needles.front().axisymmetric) return;
  const TissueLayer& top = scene.tissue.layers.front();
  const double E = top.material.youngs_modulus;
  const double line = std::min(top.thickness, 2.0 * needles.front().axisymmetric->max_radius());
  const double cells =
      line / (options.cohesive_cell_m.value_or(cohesive_ring_cell(t, E, line, options.fidelity)));
  if (!(cells <= kMaxCohesiveCells)) {
    const std::string key = top.fracture_is_own ? "tissue.layers[0].fracture.cohesive_strength"
                                                : "tissue.fracture.cohesive_strength";
    throw InputError(scene.source_name + ":" + std::to_string(top.line) + ": " + key + ": " +
                     format_quantity(t.cohesive_strength_Pa, Dimension::Pressure) +
                     " makes the law's length E G_c / sigma_c^2 " +
                     format_quantity(cohesive_length(t, E), Dimension::Length) + ", which needs " +
                     (std::isfinite(cells)
                          ? std::to_string(static_cast<long long>(std::ceil(cells)))
                          : std::string("unboundedly many")) +
                     " cells down the " + format_quantity(line, Dimension::Length) +
                     " ring crack at " + fe::to_string(options.fidelity) + ", above the limit of " +
                     std::to_string(static_cast<int>(kMaxCohesiveCells)) +
                     " (a lower strength lengthens it; docs/model.md, \"The cohesive criterion\")");
  }
}

}  // namespace

InsertionRunOptions scene_run_options(const Scene& scene) {
  InsertionRunOptions r;
  r.fidelity = scene.model.fidelity == Fidelity::Fast   ? fe::Fidelity::Fast
               : scene.model.fidelity == Fidelity::Fine ? fe::Fidelity::Fine
                                                        : fe::Fidelity::Standard;
  r.contact = scene.model.contact;
  r.criterion = scene.model.criterion;
  return r;
}

static_assert(kMaxMeshRefinement == fe::kMaxRefinementLevels,
              "the scene's mesh_refinement bound is the mesh generator's");

InsertionRun run_insertion(const Scene& scene, const std::vector<PreparedNeedle>& needles,
                           const InsertionRunOptions& requested) {
  const auto start = std::chrono::steady_clock::now();
  // The scene's mesh refinement reaches every command the same way (an explicit override wins).
  InsertionRunOptions options = requested;
  if (!options.overrides.refinement_levels)
    options.overrides.refinement_levels = scene.model.mesh_refinement;
  // Each of the zone's two sizes on its own: an explicit override wins, the scene fills the rest.
  if (!options.overrides.contact_zone_size_m)
    options.overrides.contact_zone_size_m = scene.model.contact_zone;
  if (!options.overrides.contact_zone_tip_size_m)
    options.overrides.contact_zone_tip_size_m = scene.model.contact_zone_tip;
  // A scene's zone is bisected out of a refined grid: say so in the scene's words, before any
  // mesh is built (the mesh generator refuses it too, in its own).
  if (scene.model.contact_zone && *scene.model.contact_zone > 0.0 &&
      requested.overrides.contact_zone_size_m == std::nullopt) {
    const auto& top = scene.tissue.layers;
    const double length =
        scene.model.criterion == PunctureCriterion::Stress && !top.empty() && top.front().strength
            ? top.front().strength->length
            : 0.0;
    const int levels = options.overrides.refinement_levels.value_or(fe::default_refinement_levels(
        options.fidelity, options.overrides.order.value_or(2), length));
    if (levels == 0)
      throw InputError(scene.source_name +
                       ": model.contact_zone: needs a refined 3-D grid, and this run has none "
                       "(fast without the stress criterion, or TET4 elements); set "
                       "mesh_refinement = 2 or remove contact_zone");
  }
  options.crack_face_contact = scene.model.crack_faces == CrackFaces::Contact;
  check_needle_placement(scene, needles);
  // The pre-puncture model climbs the horizon ladder (docs/model.md, "Pre-puncture horizon"):
  // rung k is built for 100 um x 2^k whatever depth was asked, and the first rung on which every
  // criterion fires (or that covers the requested depth) gives the answer. The same needle and
  // tissue thus give the same puncture for any requested depth beyond it.
  int last_rung = detail::rung_covering(scene.insertion.depth);
  RunPlan plan =
      detail::plan_insertion(scene, needles, options, detail::pre_puncture_horizon(last_rung));
  // The cohesive criterion confirms a peak on the step after it: the last rung reaches a step
  // beyond the requested depth, where the block is deep enough for that rung (else a peak in the
  // last step before the requested depth stays unconfirmed: docs/model.md, "The cohesive
  // criterion").
  const bool cohesive = plan.threshold && plan.threshold->criterion == PunctureCriterion::Cohesive;
  if (cohesive) {
    check_cohesive_tissue(scene, needles, *plan.threshold, options);
    if (plan.horizon_m < scene.insertion.depth + plan.horizon_m / std::max(plan.steps, 1) &&
        detail::pre_puncture_horizon(last_rung + 1) < scene.tissue.depth()) {
      ++last_rung;
      plan =
          detail::plan_insertion(scene, needles, options, detail::pre_puncture_horizon(last_rung));
    }
  }
  InsertionRun run;
  run.fidelity = options.fidelity;
  if (plan.threshold) {
    run.criterion = plan.threshold->criterion;
    run.threshold = plan.threshold->threshold;
  }
  if (!plan.vtu_directory.empty()) create_output_folder(plan.vtu_directory, "--vtu");

  std::vector<std::optional<SurfaceLoadModel>> post(needles.size());
  const LoadConstants constants = load_constants(scene);
  const bool need_post = plan.pre == PreKind::None || plan.threshold.has_value();
  if (need_post)
    for (std::size_t i = 0; i < needles.size(); ++i) post[i].emplace(needles[i].mesh, constants);

  if ((plan.pre == PreKind::Full3d || plan.pre == PreKind::Axisymmetric) &&
      needles.size() > options.max_fe_needles)
    throw InputError(scene.source_name + ": needles: " + std::to_string(needles.size()) +
                     " needles in one finite element model, above the limit of " +
                     std::to_string(options.max_fe_needles) +
                     " (raise it with --max-needles; a symmetric array is solved on its quarter)");
  if (plan.pre == PreKind::None) {
    run.reductions = plan.reductions;
    for (std::size_t i = 0; i < needles.size(); ++i)
      run.needles.push_back(post_only_needle(needles[i].name, plan, *post[i]));
    run.models_run.push_back("surface_loads");
  } else {
    std::vector<SectionArea> areas;
    for (const PreparedNeedle& n : needles) areas.emplace_back(n.mesh);
    if (plan.threshold && plan.threshold->criterion == PunctureCriterion::Penetration) {
      const TissueLayer& top = scene.tissue.layers.front();
      for (SectionArea& a : areas) a.set_penetration_tissue(top.material, top.fracture->toughness);
    }
    PreResult pre;
    // Without a criterion nothing can fire early: the rung covering the depth is the answer.
    const int first = plan.threshold ? first_rung(scene, needles, areas, options) : last_rung;
    // Climbs from `from`; with `decide`, first asks whether the start rung fired where the rung
    // below it reaches (at first contact, say, on a mesh spike under the tip that no closed form
    // has): then the rungs skipped might have fired, and it returns true without climbing on.
    auto climb = [&](int from, bool decide) {
      // A start above the rung covering the depth still runs (its run stops at the depth): the
      // rung a run uses never depends on how deep it was asked to go.
      for (int rung = from; rung <= std::max(last_rung, from); ++rung) {
        plan = detail::plan_insertion(scene, needles, options, detail::pre_puncture_horizon(rung));
        plan.seconds = &run.seconds_by_stage;
        run.reductions = plan.reductions;
        const bool deciding = decide && rung == from && from > 0;
        const double below = deciding ? detail::pre_puncture_horizon(from - 1) : 0.0;
        // The decision sees the start rung as deep as the rung below reaches, whatever depth was
        // asked; the answer is then cut at that depth as always.
        if (deciding) {
          plan.shown_depth_m = plan.depth_m;  // what goes deeper only decides: not shown
          plan.depth_m = std::max(plan.depth_m, below);
        }
        pre = run_pre(plan, scene, needles, areas, options, run);
        run.rungs_m.push_back(plan.horizon_m);
        if (deciding) {
          plan.depth_m = scene.insertion.depth;
          plan.shown_depth_m = 0.0;
          // A deciding rung that stopped cannot decide (it may have stopped beyond the requested
          // depth, which only the decision looks at): climb from rung 0 as the decision would.
          if (pre.stopped) return true;
          const double crossed = deepest_first_crossing(plan, pre);
          if (crossed > 0.0 && crossed <= below * (1.0 + 1e-12)) return true;
        }
        // A rung that stopped ends the climb (keep_reached): what it reached is the answer; a
        // deeper rung, built for a longer horizon, may stop too or elsewhere.
        if (pre.stopped || every_needle_crossed(plan, pre)) break;
      }
      return false;
    };
    if (climb(first, true)) climb(0, false);  // docs/model.md, "Pre-puncture horizon"
    run.horizon_m = plan.horizon_m;
    run.first_step_m = plan.horizon_m / std::max(plan.steps, 1);
    run.models_run.push_back(pre.model);
    run.nodes = pre.nodes;
    run.exported = pre.exported;
    run.elements = pre.elements;
    run.order = pre.order;
    run.axisymmetric = pre.axisymmetric;
    run.min_dihedral_deg = pre.min_dihedral_deg;
    run.max_aspect_ratio = pre.max_aspect_ratio;
    run.contact_zone_m = pre.contact_zone_m;
    run.unresolved_flats = pre.unresolved_flats;
    run.stopped = pre.stopped;
    bool any_post = false;
    for (std::size_t i = 0; i < needles.size(); ++i) {
      run.needles.push_back(assemble_needle(needles[i].name, pre.needles[i], plan, areas[i],
                                            post[i] ? &*post[i] : nullptr));
      any_post = any_post || run.needles.back().puncture.has_value();
    }
    if (any_post) run.models_run.push_back("surface_loads");
  }
  run.total_curve = total_curve(run.needles);
  // Past a stop the needles that did not puncture have no force: the sum ends there too (a
  // needle that punctured before it keeps its own post-puncture curve, which needs no FE).
  if (run.stopped)
    std::erase_if(run.total_curve, [&](const RunPoint& p) {
      return p.depth_m > run.stopped->depth_m * (1.0 + 1e-12);
    });
  // The energy ledger of the pre-puncture stage, up to the first needle's puncture (after it
  // the tissue is cut and the ledger would need the fracture energy; docs/model.md).
  std::vector<double> depth, force, energy;
  for (const RunPoint& p : run.total_curve) {
    if (p.stage != Stage::Pre) break;
    depth.push_back(p.depth_m);
    force.push_back(p.force_N);
    energy.push_back(p.strain_energy_J + p.fracture_energy_J);  // W = U + W_d (cohesive)
  }
  run.energy_check = check_energy(depth, force, energy);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.peak_memory_bytes = peak_memory_bytes();
  return run;
}

std::string_view to_string(Stage s) {
  return s == Stage::Pre ? "pre" : "post";
}

}  // namespace mneedle
