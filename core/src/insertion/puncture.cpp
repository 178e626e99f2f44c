#include "mneedle/insertion/puncture.h"

#include <algorithm>
#include <cmath>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

std::string layer_where(const Scene& scene, std::size_t index) {
  const TissueLayer& layer = scene.tissue.layers[index];
  return scene.source_name + ":" + std::to_string(layer.line) + ": tissue.layers[" +
         std::to_string(index) + "] '" + layer.name + "'";
}

[[noreturn]] void missing(const Scene& scene, const std::string& key, PunctureCriterion c) {
  throw InputError(layer_where(scene, 0) + ": " + key + ": missing (the " +
                   std::string(to_string(c)) + " criterion needs it)");
}

void check_sequence(const std::vector<double>& depths, const std::vector<double>& values,
                    double threshold) {
  if (depths.size() != values.size())
    throw InputError("puncture: " + std::to_string(depths.size()) + " depths but " +
                     std::to_string(values.size()) + " criterion values");
  if (!(threshold > 0.0) || !std::isfinite(threshold))
    throw InputError("puncture: the criterion threshold must be positive and finite");
  for (std::size_t i = 0; i < depths.size(); ++i) {
    if (!std::isfinite(depths[i]) || !std::isfinite(values[i]))
      throw InputError("puncture: step " + std::to_string(i) + " is not finite");
    if (depths[i] < 0.0 || (i > 0 && !(depths[i] > depths[i - 1])))
      throw InputError("puncture: depths must be ascending and non-negative (step " +
                       std::to_string(i) + ")");
  }
}

// A force that falls by less than this fraction of itself between two steps has not fallen: the
// solver's round-off (the condensed solve's 1e-14, the cohesive rounds' 1e-12) is far below it,
// and a crack's run drops the force by percents.
constexpr double kDropTolerance = 1e-9;

// Bisection on [lo, hi], value(lo) < threshold <= value(hi): the criterion need not be linear
// between the steps, so the located depth is as exact as the tolerance asks.
double bisect(const std::function<double(double)>& resolve, double lo, double hi, double threshold,
              double tolerance) {
  const double tol = tolerance > 0.0 ? tolerance : 1e-6 * (hi - lo);
  for (int i = 0; i < 200 && hi - lo > tol; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double v = resolve(mid);
    if (!std::isfinite(v)) throw SolverError("puncture: the criterion is not finite at depth");
    (v >= threshold ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

bool has_puncture_data(const Scene& scene) {
  if (scene.tissue.layers.empty()) return false;
  const TissueLayer& top = scene.tissue.layers.front();
  return top.fracture.has_value() || top.strength.has_value();
}

PunctureThreshold puncture_threshold(const Scene& scene, PunctureCriterion criterion) {
  if (scene.tissue.layers.empty())
    throw InputError(scene.source_name + ": tissue.layers: no layer to puncture");
  const TissueLayer& top = scene.tissue.layers.front();
  const std::string fracture_key =
      top.fracture_is_own || !scene.tissue.fracture ? "fracture" : "tissue.fracture";
  PunctureThreshold t;
  t.criterion = criterion;
  t.layer = 0;
  switch (criterion) {
    case PunctureCriterion::Pressure:
      if (!top.fracture || !(top.fracture->critical_pressure > 0.0))
        missing(scene, fracture_key + ".critical_pressure", criterion);
      t.threshold = top.fracture->critical_pressure;
      break;
    case PunctureCriterion::Energy:
      if (!top.fracture || !(top.fracture->toughness > 0.0))
        missing(scene, fracture_key + ".toughness", criterion);
      t.threshold = top.fracture->toughness;
      break;
    case PunctureCriterion::Penetration:
      if (!top.fracture || !(top.fracture->toughness > 0.0))
        missing(scene, fracture_key + ".toughness", criterion);
      // The plane-strain crack model under F_p takes 0 <= nu < 0.5 (the scene allows nu < 0).
      if (top.material.poisson_ratio < 0.0)
        throw InputError(layer_where(scene, 0) +
                         ": material.nu: " + std::to_string(top.material.poisson_ratio) +
                         " is negative; the penetration criterion needs 0 <= nu < 0.5");
      t.threshold = 1.0;  // F reaches F_p
      break;
    case PunctureCriterion::Stress:
      if (!top.strength) missing(scene, "strength", criterion);
      t.threshold = top.strength->strength;
      t.average_length_m = top.strength->length;
      break;
    case PunctureCriterion::Cohesive:
      if (!top.fracture || !(top.fracture->toughness > 0.0))
        missing(scene, fracture_key + ".toughness", criterion);
      if (!top.fracture->cohesive_strength)
        missing(scene, fracture_key + ".cohesive_strength", criterion);
      t.threshold = top.fracture->toughness;
      t.cohesive_strength_Pa = *top.fracture->cohesive_strength;
      t.cohesive_peak_ratio = top.fracture->cohesive_peak_ratio;
      break;
  }
  return t;
}

double criterion_value(PunctureCriterion criterion, const CriterionSample& sample) {
  switch (criterion) {
    case PunctureCriterion::Pressure:
      return sample.contact_pressure_Pa;
    case PunctureCriterion::Energy:
      return sample.energy_release_rate_J_per_m2;
    case PunctureCriterion::Stress:
      return sample.tip_stress_Pa;
    case PunctureCriterion::Penetration:
      return sample.penetration_ratio;
    case PunctureCriterion::Cohesive:
      return 0.0;  // no threshold to reach: force_peak reads the force itself
  }
  return 0.0;
}

std::optional<Crossing> first_crossing(const std::vector<double>& depths_m,
                                       const std::vector<double>& values, double threshold,
                                       const std::function<double(double)>& resolve,
                                       double depth_tolerance_m) {
  check_sequence(depths_m, values, threshold);
  double previous_depth = 0.0;
  double previous_value = 0.0;
  for (std::size_t i = 0; i < depths_m.size(); ++i) {
    if (values[i] >= threshold) {
      Crossing c;
      c.step = i;
      if (resolve) {
        c.depth_m = bisect(resolve, previous_depth, depths_m[i], threshold, depth_tolerance_m);
      } else {
        // previous_value < threshold <= values[i], so the denominator is positive.
        const double f = (threshold - previous_value) / (values[i] - previous_value);
        c.depth_m = previous_depth + f * (depths_m[i] - previous_depth);
      }
      const double span = depths_m[i] - previous_depth;
      c.fraction = span > 0.0 ? std::clamp((c.depth_m - previous_depth) / span, 0.0, 1.0) : 1.0;
      return c;
    }
    previous_depth = depths_m[i];
    previous_value = values[i];
  }
  return std::nullopt;
}

std::optional<std::size_t> force_drop_step(const std::vector<double>& forces_N) {
  for (std::size_t i = 1; i < forces_N.size(); ++i)
    if (forces_N[i] < forces_N[i - 1] * (1.0 - kDropTolerance)) return i;
  return std::nullopt;
}

std::optional<Crossing> force_peak(const std::vector<double>& depths_m,
                                   const std::vector<double>& forces_N, double* peak_force_N) {
  // Any positive threshold passes the check: the sequence is what is checked here.
  check_sequence(depths_m, forces_N, 1.0);
  const auto drop = force_drop_step(forces_N);
  if (!drop) return std::nullopt;
  // The highest step is the one before the drop; its neighbours bracket the vertex (before the
  // first step, the origin: no contact, no force).
  const std::size_t top = *drop - 1;
  const double x0 = top > 0 ? depths_m[top - 1] : 0.0, y0 = top > 0 ? forces_N[top - 1] : 0.0;
  const double x1 = depths_m[top], y1 = forces_N[top];
  const double x2 = depths_m[*drop], y2 = forces_N[*drop];
  // Divided differences: y = y1 + b (x - x1) + c (x - x1)^2 with c < 0, since y1 >= y0 and
  // y1 > y2 make the parabola concave.
  if (!(x1 > x0)) {  // a first step at depth 0: no interval before it to place a vertex in
    Crossing at;
    at.depth_m = x1;
    at.step = top;
    at.fraction = 1.0;
    if (peak_force_N != nullptr) *peak_force_N = y1;
    return at;
  }
  const double s01 = (y1 - y0) / (x1 - x0), s12 = (y2 - y1) / (x2 - x1);
  const double c = (s12 - s01) / (x2 - x0);
  const double b = s01 + c * (x1 - x0);
  double vertex = c < 0.0 ? x1 - b / (2.0 * c) : x1;
  vertex = std::clamp(vertex, x0, x2);
  Crossing crossing;
  crossing.depth_m = vertex;
  crossing.step = vertex <= x1 ? top : *drop;
  const double from = vertex <= x1 ? x0 : x1, to = vertex <= x1 ? x1 : x2;
  crossing.fraction = to > from ? std::clamp((vertex - from) / (to - from), 0.0, 1.0) : 1.0;
  if (peak_force_N != nullptr)
    *peak_force_N = y1 + b * (vertex - x1) + c * (vertex - x1) * (vertex - x1);
  return crossing;
}

double interpolate_at(const std::vector<double>& depths_m, const std::vector<double>& values,
                      double depth_m) {
  if (depths_m.empty()) return 0.0;
  double d0 = 0.0, v0 = 0.0;
  for (std::size_t i = 0; i < depths_m.size(); ++i) {
    if (depth_m <= depths_m[i]) {
      const double span = depths_m[i] - d0;
      if (span <= 0.0) return values[i];
      return v0 + (values[i] - v0) * (depth_m - d0) / span;
    }
    d0 = depths_m[i];
    v0 = values[i];
  }
  return values.back();
}

double crack_depth_for(double needle_radius_m, double tip_element_size_m) {
  return std::max(2.0 * needle_radius_m, 2.0 * tip_element_size_m);
}

}  // namespace mneedle
