#pragma once
// Printing a command's JSON: the finite gate (mneedle/api/finite_json.h, which every command
// also uses for its other formats) and then the run's provenance.

#include <nlohmann/json.hpp>
#include <ostream>
#include <string_view>

#include "mneedle/api/finite_json.h"

namespace mneedle::cli {

/// Checks, then writes tree.dump(2) and a newline; an object gets the run's "provenance"
/// (run_provenance.h) as a top-level key unless it has one.
void print_checked_json(std::ostream& out, const nlohmann::json& tree, std::string_view context);
void print_checked_json(std::ostream& out, const nlohmann::ordered_json& tree,
                        std::string_view context);

}  // namespace mneedle::cli
