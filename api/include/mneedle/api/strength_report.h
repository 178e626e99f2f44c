#pragma once
// `strength` as a library call: buckling and material capacity of one needle as the JSON tree
// the CLI prints and Python returns (docs/model.md, "Needle strength").

#include <nlohmann/json.hpp>
#include <string>

#include "mneedle/design_source.h"
#include "mneedle/plugin_host.h"

namespace mneedle {

struct StrengthSettings {
  std::string material;              // a needle material (docs/materials.md); required
  std::string end = "fixed-pinned";  // fixed-pinned | fixed-free | pinned-pinned
  std::string depth;                 // "300um": sections above it carry the force; "" = tip length
  double lateral_ratio = 0.0;        // lateral over axial tip force (bevels)
};

/// {needle, material, E_Pa, strength_Pa, failure_mode, end, effective_length_factor, length_m,
/// load_height_m, I_min_m4, A_min_m2, elastic_buckling_N, johnson, buckling_N, strength_N,
/// critical_height_m, capacity_N, governing}, checked finite. The plugin's analytic section hook
/// when it has one; the sliced mesh otherwise. InputError for a bad setting.
nlohmann::json strength_report(const PluginRegistry& registry, const NeedleSource& needle,
                               const StrengthSettings& settings);

}  // namespace mneedle
