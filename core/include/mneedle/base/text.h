#pragma once
// Small text helpers every reader of user input shares (units, CSV, scene values).

#include <string>
#include <string_view>

namespace mneedle {

/// `s` without leading and trailing spaces, tabs, carriage returns and line feeds.
std::string_view trim(std::string_view s);

/// A count of work items (points, samples) for a message: whole numbers below 10^7 in full,
/// larger ones to three significant digits ("2e+27"), so a huge request reads as what it is.
std::string count_text(double count);

}  // namespace mneedle
