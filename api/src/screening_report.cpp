#include "mneedle/api/screening_report.h"

#include "mneedle/api/finite_json.h"

namespace mneedle {

nlohmann::json screening_json(const std::vector<ScreeningRow>& ranked,
                              const std::string& scene_name, const ScreeningOptions& options) {
  const bool sampled = !options.vary.empty();
  nlohmann::json out = {
      {"scene", scene_name},
      {"fidelity", options.fidelity},
      {"model", options.model},
      {"ranking",
       sampled ? nlohmann::json{"uncertainty.pass_probability", "uncertainty.puncture_depth_m.p50",
                                "puncture_depth_m", "puncture_force_N"}
               : nlohmann::json{"puncture_depth_m", "puncture_force_N"}},
      {"designs", nlohmann::json::array()}};
  for (const auto& r : ranked) {
    auto j = nlohmann::json::parse(r.json);
    j["resumed"] = r.resumed;
    out["designs"].push_back(j);
  }
  require_finite_json(out, "screen");
  return out;
}

}  // namespace mneedle
