#pragma once
// Helpers shared by the built-in shape tests: one registry per test program, mesh checks
// and integrals of the analytic section hooks.

#include <cmath>
#include <map>
#include <string>

#include "mneedle/needle/mesh.h"
#include "mneedle/needle/mesh_validation.h"
#include "mneedle/plugin_host.h"

namespace mneedle::test {

inline const PluginRegistry& builtin_registry() {
  static const PluginRegistry registry = PluginRegistry::discover();
  return registry;
}

using Parameters = std::map<std::string, double>;

inline double relative_error(double value, double reference) {
  return std::abs(value - reference) / std::abs(reference);
}

/// ∫ A(h) dh over [0, length] by composite Simpson; the section hooks are exact, so this
/// is the analytic volume up to quadrature error (tiny at 20000 intervals).
inline double integrated_section_volume(const std::string& shape, const Parameters& p,
                                        double length, int intervals = 4000) {
  const auto& registry = builtin_registry();
  const double step = length / intervals;
  double sum = 0;
  for (int i = 0; i <= intervals; ++i) {
    const double weight = (i == 0 || i == intervals) ? 1 : (i % 2 == 1 ? 4 : 2);
    sum += weight * registry.section_area(shape, p, i * step).value();
  }
  return sum * step / 3;
}

}  // namespace mneedle::test
