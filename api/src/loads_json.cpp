#include "mneedle/api/loads_json.h"

#include <cmath>
#include <sstream>

#include "mneedle/base/units.h"
#include "mneedle/insertion/surface_loads.h"

namespace mneedle {

nlohmann::json resolved_loads_json(const Scene& scene) {
  const LoadConstants constants = load_constants(scene);
  const std::vector<LayerPressure> pressures = layer_pressures(constants);
  nlohmann::json layers = nlohmann::json::array();
  for (std::size_t i = 0; i < pressures.size(); ++i) {
    const LayerPressure& p = pressures[i];
    layers.push_back(
        {{"name", i < scene.tissue.layers.size() ? scene.tissue.layers[i].name : "all"},
         {"pressure_scale_Pa", p.pressure_scale_Pa},
         {"wall_pressure_cap_Pa", std::isfinite(p.wall_pressure_cap_Pa)
                                      ? nlohmann::json(p.wall_pressure_cap_Pa)
                                      : nlohmann::json(nullptr)},
         {"cutting_pressure_cap_Pa", std::isfinite(p.cutting_pressure_cap_Pa)
                                         ? nlohmann::json(p.cutting_pressure_cap_Pa)
                                         : nlohmann::json(nullptr)},
         {"source", p.source}});
  }
  nlohmann::json beta_length = nullptr;
  if (constants.mode == LoadModelMode::paper_a_fig17) {
    beta_length = kPaperAFig17BetaLength_m;
  } else if (constants.beta_length_m) {
    beta_length = *constants.beta_length_m;
  }
  return {
      {"mode", constants.mode == LoadModelMode::paper_a_fig17 ? "paper_a_fig17" : "distributed"},
      {"beta_length_m", beta_length},
      {"layers", layers}};
}

std::string resolved_loads_text(const Scene& scene) {
  const std::vector<LayerPressure> pressures = layer_pressures(load_constants(scene));
  std::ostringstream out;
  for (std::size_t i = 0; i < pressures.size(); ++i) {
    const LayerPressure& p = pressures[i];
    out << "  q " << (i < scene.tissue.layers.size() ? scene.tissue.layers[i].name : "all") << " "
        << format_quantity(p.pressure_scale_Pa, Dimension::Pressure);
    if (std::isfinite(p.wall_pressure_cap_Pa)) {
      out << " (wall pressure capped at "
          << format_quantity(p.wall_pressure_cap_Pa, Dimension::Pressure) << ")";
    }
    if (std::isfinite(p.cutting_pressure_cap_Pa)) {
      out << " (alpha pressure capped at "
          << format_quantity(p.cutting_pressure_cap_Pa, Dimension::Pressure) << ")";
    }
    out << ": " << p.source << "\n";
  }
  return out.str();
}

}  // namespace mneedle
