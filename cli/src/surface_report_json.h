#pragma once
// JSON of the surface analysis for `mneedle inspect --json`: "groups" and "tip_area".

#include <nlohmann/json.hpp>
#include <vector>

#include "mneedle/needle/mesh.h"

namespace mneedle::cli {

/// {"groups": {"alpha": {"count": n, "area_m2": a}, "beta": ..., "side": ..., "back": ...},
///  "tip_area": [{"height_m": h, "area_m2": A}, ...]} for a mesh in the needle frame; the
/// default heights (default_tip_area_heights) when `heights_m` is empty.
nlohmann::json surface_report_json(const TriangleMesh& mesh,
                                   const std::vector<double>& heights_m = {});

}  // namespace mneedle::cli
