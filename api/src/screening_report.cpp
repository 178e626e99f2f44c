#include "mneedle/api/screening_report.h"

#include "mneedle/api/finite_json.h"
#include "mneedle/api/simulation.h"

namespace mneedle {

nlohmann::json screening_json(const std::vector<ScreeningRow>& ranked,
                              const std::string& scene_name, const ScreeningOptions& options,
                              const std::vector<std::string>& warnings) {
  const bool sampled = !options.vary.empty();
  nlohmann::json out = {
      {"scene", scene_name},
      {"fidelity", options.fidelity},
      {"model", options.model},
      {"ranking",
       sampled ? nlohmann::json{"uncertainty.pass_probability", "uncertainty.puncture_depth_m.p50",
                                "puncture_depth_m", "puncture_force_N"}
               : nlohmann::json{"puncture_depth_m", "puncture_force_N"}},
      {"designs", nlohmann::json::array()},
      {"warnings", warnings}};
  for (const auto& r : ranked) {
    auto j = nlohmann::json::parse(r.json);
    j["resumed"] = r.resumed;
    out["designs"].push_back(j);
  }
  require_finite_json(out, "screen");
  return out;
}

std::vector<std::string> screening_warnings(const std::vector<ScreeningRow>& ranked,
                                            const Scene& scene) {
  double deepest = 0.0;
  std::string design;
  for (const ScreeningRow& r : ranked) {
    if (!r.ok || !r.puncture_depth_m || r.puncture_at_first_contact) continue;
    const nlohmann::json j = nlohmann::json::parse(r.json, nullptr, false);
    bool analytic = false;
    if (j.is_object() && j.contains("models_run") && j["models_run"].is_array())
      for (const auto& m : j["models_run"]) analytic = analytic || m == "analytic";
    if (!analytic && *r.puncture_depth_m > deepest)
      deepest = *r.puncture_depth_m, design = r.design;
  }
  if (design.empty()) return {};
  const auto w =
      small_strain_warning(scene, deepest, "design '" + design + "' before it punctures");
  if (!w) return {};
  return {*w};
}

}  // namespace mneedle
