#pragma once
// Needle capacity: buckling (Euler/Johnson on the varying section) and material failure of the
// sections the insertion force passes through (docs/model.md, "Needle strength").

#include <functional>
#include <string>

#include "mneedle/strength/column_buckling.h"
#include "mneedle/strength/needle_material.h"

namespace mneedle {

/// Section properties at height h above the tip, perpendicular to the axis (bores subtracted).
struct SectionProperties {
  double area_m2 = 0.0;
  double i_min_m4 = 0.0;         // smallest principal second moment of area
  double extreme_fibre_m = 0.0;  // largest distance of the section from its centroid
};

using SectionProfile = std::function<SectionProperties(double height_m)>;

struct StrengthOptions {
  double length_m = 0.0;       // needle length, tip to clamped base
  double load_height_m = 0.0;  // height of the tissue surface above the tip (insertion depth)
  EndCondition end = EndCondition::FixedPinned;
  double lateral_ratio = 0.0;  // |lateral force| / axial force on the tip (bevels), adds bending
  int samples = 200;           // sections checked between load height and base
};

struct StrengthReport {
  double elastic_buckling_n = 0.0;  // eigenvalue of the varying-section column
  double buckling_n = 0.0;          // after Johnson's correction for short columns
  bool johnson = false;             // true when Johnson's parabola governed the buckling load
  double strength_n = 0.0;          // material failure of the weakest loaded section
  double capacity_n = 0.0;          // min(buckling, strength)
  std::string governing;            // "buckling" | "strength"
  double i_min_m4 = 0.0;            // over the loaded part [load height, base]
  double a_min_m2 = 0.0;            // over the loaded part
  double critical_height_m = 0.0;   // where material failure is decided
};

/// Capacity of a needle of the given section profile and material. The buckling column is the
/// part between the tissue surface (load height, pinned or free) and the base (clamped). InputError
/// for non-physical options (zero length, load height outside [0, L), an empty loaded section).
StrengthReport needle_strength(const SectionProfile& profile, const NeedleMaterial& material,
                               const StrengthOptions& options);

/// Profile of a solid or hollow circular rod (diameter D, bore d), the classical reference.
SectionProfile circular_rod_profile(double diameter_m, double bore_m);

/// Margin = capacity / peak force; infinite when no force acts.
double strength_margin(double capacity_n, double peak_force_n);

}  // namespace mneedle
