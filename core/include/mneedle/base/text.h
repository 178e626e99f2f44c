#pragma once
// Small text helpers every reader of user input shares (units, CSV, scene values).

#include <string_view>

namespace mneedle {

/// `s` without leading and trailing spaces, tabs, carriage returns and line feeds.
std::string_view trim(std::string_view s);

}  // namespace mneedle
