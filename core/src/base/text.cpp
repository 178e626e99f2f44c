#include "mneedle/base/text.h"

namespace mneedle {

std::string_view trim(std::string_view s) {
  constexpr std::string_view blank = " \t\r\n";
  const auto first = s.find_first_not_of(blank);
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(blank);
  return s.substr(first, last - first + 1);
}

}  // namespace mneedle
