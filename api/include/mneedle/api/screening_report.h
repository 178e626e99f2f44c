#pragma once
// `screen --json` as a library call: ranked rows (rank_rows) as the JSON tree the CLI prints
// and Python returns (docs/cli.md, "screen").

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mneedle/screening.h"

namespace mneedle {

/// {scene, fidelity, model, ranking (the keys the order follows), designs: each row's JSON with
/// "resumed", warnings (screening_warnings)}, checked finite. `scene_name` is the scene as the
/// user named it.
nlohmann::json screening_json(const std::vector<ScreeningRow>& ranked,
                              const std::string& scene_name, const ScreeningOptions& options,
                              const std::vector<std::string>& warnings = {});

/// What holds for the whole run, one line each: the small-strain top layer's warning of
/// `simulate` (small_strain_warning), once, at the design that pushed the layer deepest before it
/// punctured (closed-form rows and first-contact depths left out). The CLI prints them on stderr,
/// Python raises them as RuntimeWarnings.
std::vector<std::string> screening_warnings(const std::vector<ScreeningRow>& ranked,
                                            const Scene& scene);

}  // namespace mneedle
