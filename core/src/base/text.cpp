#include "mneedle/base/text.h"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace mneedle {

std::string_view trim(std::string_view s) {
  constexpr std::string_view blank = " \t\r\n";
  const auto first = s.find_first_not_of(blank);
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(blank);
  return s.substr(first, last - first + 1);
}

std::string count_text(double count) {
  std::ostringstream out;
  if (count >= 0.0 && count < 1e7)
    out << std::fixed << std::setprecision(0) << std::ceil(count);
  else
    out << std::setprecision(3) << count;
  return out.str();
}

}  // namespace mneedle
