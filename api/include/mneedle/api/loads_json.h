#pragma once
// The post-puncture model's constants as resolved for a scene: each layer's pressure scale q,
// its wall-pressure cap and where q comes from (docs/model.md, "Pressure scale"). Printed by
// `scene check`, `force` and `simulate` so a number can always be traced to its source.

#include <nlohmann/json.hpp>
#include <string>

#include "mneedle/scene/scene.h"

namespace mneedle {

/// {"mode": ..., "beta_length_m": l or null (= each needle's R_ref), "layers": [{"name",
/// "pressure_scale_Pa", "wall_pressure_cap_Pa" (null: none), "source"}]}.
nlohmann::json resolved_loads_json(const Scene& scene);

/// One line per layer: "  q stratum_corneum 2.0e8 Pa (wall cap 21.6 MPa): derived ...".
std::string resolved_loads_text(const Scene& scene);

}  // namespace mneedle
