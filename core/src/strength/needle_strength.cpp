#include "mneedle/strength/needle_strength.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

void check_options(const StrengthOptions& o) {
  if (!(o.length_m > 0.0) || !std::isfinite(o.length_m))
    throw InputError("strength: needle length must be positive");
  if (!(o.load_height_m >= 0.0) || o.load_height_m >= o.length_m)
    throw InputError("strength: insertion depth must lie in [0, needle length)");
  if (!(o.lateral_ratio >= 0.0) || !std::isfinite(o.lateral_ratio))
    throw InputError("strength: lateral force ratio must be non-negative");
  if (o.samples < 2) throw InputError("strength: at least two sections must be checked");
}

// Stress per newton of axial force at height h: direct stress plus bending from the lateral
// tip force acting over the lever arm (h − z) from the tissue surface.
double stress_per_newton(const SectionProperties& s, double lever_m, double lateral_ratio) {
  double sigma = 1.0 / s.area_m2;
  if (lateral_ratio > 0.0 && s.i_min_m4 > 0.0)
    sigma += lateral_ratio * lever_m * s.extreme_fibre_m / s.i_min_m4;
  return sigma;
}

}  // namespace

StrengthReport needle_strength(const SectionProfile& profile, const NeedleMaterial& material,
                               const StrengthOptions& options) {
  check_options(options);
  StrengthReport r;
  r.i_min_m4 = std::numeric_limits<double>::infinity();
  r.a_min_m2 = std::numeric_limits<double>::infinity();
  double worst_stress = 0.0;
  const double z = options.load_height_m;
  for (int i = 0; i <= options.samples; ++i) {
    const double h = z + (options.length_m - z) * i / options.samples;
    const SectionProperties s = profile(h);
    if (!(s.area_m2 > 0.0))
      throw InputError("strength: the needle has no material at height " + std::to_string(h) +
                       " m, where it carries the insertion force");
    r.i_min_m4 = std::min(r.i_min_m4, s.i_min_m4);
    r.a_min_m2 = std::min(r.a_min_m2, s.area_m2);
    const double stress = stress_per_newton(s, h - z, options.lateral_ratio);
    if (stress > worst_stress) {
      worst_stress = stress;
      r.critical_height_m = h;
    }
  }
  r.strength_n = material.strength_pa / worst_stress;

  const double e = material.youngs_modulus_pa;
  // The column is the loaded part: from the tissue surface, which holds the needle laterally,
  // to the base. Below the surface the tissue carries the tip; a sharp tip pinned at its point
  // would have I → 0 there and no buckling strength at all.
  r.elastic_buckling_n = critical_buckling_load(
      [&](double s) { return e * profile(z + s).i_min_m4; }, options.length_m - z, options.end);
  r.buckling_n = johnson_critical_load(r.elastic_buckling_n, r.a_min_m2, material.strength_pa);
  r.johnson = r.buckling_n < r.elastic_buckling_n;

  r.capacity_n = std::min(r.buckling_n, r.strength_n);
  r.governing = r.buckling_n <= r.strength_n ? "buckling" : "strength";
  return r;
}

SectionProfile circular_rod_profile(double diameter_m, double bore_m) {
  if (!(diameter_m > 0.0) || !(bore_m >= 0.0) || bore_m >= diameter_m)
    throw InputError("strength: rod needs diameter > bore >= 0");
  const double pi = std::numbers::pi;
  SectionProperties s;
  s.area_m2 = pi / 4.0 * (diameter_m * diameter_m - bore_m * bore_m);
  s.i_min_m4 = pi / 64.0 * (std::pow(diameter_m, 4) - std::pow(bore_m, 4));
  s.extreme_fibre_m = diameter_m / 2.0;
  return [s](double) { return s; };
}

double strength_margin(double capacity_n, double peak_force_n) {
  if (!(peak_force_n > 0.0)) return std::numeric_limits<double>::infinity();
  return capacity_n / peak_force_n;
}

}  // namespace mneedle
