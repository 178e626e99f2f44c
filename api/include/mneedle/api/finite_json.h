#pragma once
// The last gate before any number leaves mneedle: no NaN or Inf may reach an output file, the
// terminal or a Python caller (nlohmann::json would print NaN as null, a CSV as "nan"). Every
// command and every binding builds its result, passes it through these checks, and only then
// hands it on in the requested format.

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace mneedle {

/// Throws SolverError "<context>: non-finite value <v> at <path>" for the first NaN or infinite
/// number in the tree; `path` is written like needles[0].curve[3].force_N.
void require_finite_json(const nlohmann::json& tree, std::string_view context);
void require_finite_json(const nlohmann::ordered_json& tree, std::string_view context);

/// One number; `key` names it in the message (e.g. "force_N").
double require_finite(double value, std::string_view key, std::string_view context);

/// One CSV row: values[i] belongs to columns[i]; `row` names the row (e.g. "needle A, row 3").
void require_finite_row(const std::vector<double>& values, const std::vector<std::string>& columns,
                        std::string_view row, std::string_view context);

}  // namespace mneedle
