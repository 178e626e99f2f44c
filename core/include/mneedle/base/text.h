#pragma once
// Small text helpers every reader of user input shares (units, CSV, scene values).

#include <cstddef>
#include <string>
#include <string_view>

namespace mneedle {

/// `s` without leading and trailing spaces, tabs, carriage returns and line feeds.
std::string_view trim(std::string_view s);

/// Levenshtein distance, letters compared without case: how far a misspelt name is from a known
/// one, for "did you mean" in messages.
std::size_t edit_distance(std::string_view a, std::string_view b);

/// A count of work items (points, samples) for a message: whole numbers below 10^7 in full,
/// larger ones to three significant digits ("2e+27"), so a huge request reads as what it is.
std::string count_text(double count);

}  // namespace mneedle
