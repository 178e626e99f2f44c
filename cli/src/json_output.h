#pragma once
// The last gate before any number leaves mneedle: no NaN or Inf may reach an output file or the
// terminal (nlohmann::json would print NaN as null, a CSV as "nan"). Every command builds its
// result, passes it through these checks, and only then prints it in the requested format.

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace mneedle::cli {

/// Throws SolverError "<context>: non-finite value <v> at <path>" for the first NaN or infinite
/// number in the tree; `path` is written like needles[0].curve[3].force_N.
void require_finite_json(const nlohmann::json& tree, std::string_view context);
void require_finite_json(const nlohmann::ordered_json& tree, std::string_view context);

/// One number; `key` names it in the message (e.g. "force_N").
double require_finite(double value, std::string_view key, std::string_view context);

/// One CSV row: values[i] belongs to columns[i]; `row` names the row (e.g. "needle A, row 3").
void require_finite_row(const std::vector<double>& values, const std::vector<std::string>& columns,
                        std::string_view row, std::string_view context);

/// Checks, then writes tree.dump(2) and a newline; an object gets the run's "provenance"
/// (run_provenance.h) as a top-level key unless it has one.
void print_checked_json(std::ostream& out, const nlohmann::json& tree, std::string_view context);
void print_checked_json(std::ostream& out, const nlohmann::ordered_json& tree,
                        std::string_view context);

}  // namespace mneedle::cli
