#include "mneedle/api/finite_json.h"

#include <cmath>
#include <optional>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

std::string describe(double value) {
  if (std::isnan(value)) return "NaN";
  return value > 0 ? "+Inf" : "-Inf";
}

[[noreturn]] void fail(std::string_view context, double value, const std::string& path) {
  throw SolverError(std::string(context) + ": non-finite value " + describe(value) + " at " +
                    (path.empty() ? std::string("the top level") : path));
}

// Depth-first search; returns the path of the first non-finite number and its value.
template <class Json>
std::optional<std::pair<std::string, double>> first_non_finite(const Json& node,
                                                               const std::string& path) {
  if (node.is_number_float()) {
    const double v = node.template get<double>();
    if (!std::isfinite(v)) return std::make_pair(path, v);
    return std::nullopt;
  }
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string child = path.empty() ? it.key() : path + "." + it.key();
      if (auto hit = first_non_finite(it.value(), child)) return hit;
    }
  } else if (node.is_array()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (auto hit = first_non_finite(node[i], path + "[" + std::to_string(i) + "]")) return hit;
    }
  }
  return std::nullopt;
}

template <class Json>
void check(const Json& tree, std::string_view context) {
  if (auto hit = first_non_finite(tree, "")) fail(context, hit->second, hit->first);
}

}  // namespace

void require_finite_json(const nlohmann::json& tree, std::string_view context) {
  check(tree, context);
}

void require_finite_json(const nlohmann::ordered_json& tree, std::string_view context) {
  check(tree, context);
}

double require_finite(double value, std::string_view key, std::string_view context) {
  if (!std::isfinite(value)) fail(context, value, std::string(key));
  return value;
}

void require_finite_row(const std::vector<double>& values, const std::vector<std::string>& columns,
                        std::string_view row, std::string_view context) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (std::isfinite(values[i])) continue;
    const std::string column = i < columns.size() ? columns[i] : "column " + std::to_string(i + 1);
    fail(context, values[i], std::string(row) + ", " + column);
  }
}

}  // namespace mneedle
