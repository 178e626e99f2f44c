#pragma once
// Dimensional values given on the command line: every error names the option it came from
// (docs/cli.md: quantities on the command line carry their units).

#include <string>
#include <string_view>

#include "mneedle/base/units.h"

namespace mneedle::cli {

/// `text` as a quantity of dimension `d` in SI; InputError "OPTION: problem" (e.g. "--step: "10"
/// needs a unit: a length such as ...").
double option_quantity(const std::string& option, std::string_view text, Dimension d);

/// As option_quantity, and above zero: InputError "OPTION TEXT: must be positive" otherwise.
double positive_option_quantity(const std::string& option, std::string_view text, Dimension d);

/// A mesh file's length unit (`--unit um|mm|m`) in metres; InputError "--unit: problem".
double option_length_unit(std::string_view text);

}  // namespace mneedle::cli
