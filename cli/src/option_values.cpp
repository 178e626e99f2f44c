#include "option_values.h"

#include "mneedle/base/error.h"

namespace mneedle::cli {

double option_quantity(const std::string& option, std::string_view text, Dimension d) {
  try {
    return parse_quantity(text, d);
  } catch (const InputError& e) {
    throw InputError(option + ": " + e.what());
  }
}

double positive_option_quantity(const std::string& option, std::string_view text, Dimension d) {
  const double v = option_quantity(option, text, d);
  if (!(v > 0.0)) throw InputError(option + " " + std::string(text) + ": must be positive");
  return v;
}

double option_length_unit(std::string_view text) {
  try {
    return length_unit_scale(text);
  } catch (const InputError& e) {
    throw InputError(std::string("--unit: ") + e.what());
  }
}

}  // namespace mneedle::cli
