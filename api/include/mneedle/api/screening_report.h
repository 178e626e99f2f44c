#pragma once
// `screen --json` as a library call: ranked rows (rank_rows) as the JSON tree the CLI prints
// and Python returns (docs/cli.md, "screen").

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mneedle/screening.h"

namespace mneedle {

/// {scene, fidelity, model, ranking (the keys the order follows), designs: each row's JSON with
/// "resumed"}, checked finite. `scene_name` is the scene as the user named it.
nlohmann::json screening_json(const std::vector<ScreeningRow>& ranked,
                              const std::string& scene_name, const ScreeningOptions& options);

}  // namespace mneedle
