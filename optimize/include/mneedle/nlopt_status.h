#pragma once
#include <string>

namespace mneedle {

/// A human-readable meaning of an NLopt result code (nlopt_result), for reports and errors.
std::string describe_nlopt_result(int code);

/// True when NLopt stopped because a convergence criterion was met, not because it gave up.
bool nlopt_result_converged(int code);

}  // namespace mneedle
