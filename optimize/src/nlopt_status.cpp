#include "mneedle/nlopt_status.h"

#include <nlopt.h>

namespace mneedle {

std::string describe_nlopt_result(int code) {
  switch (static_cast<nlopt_result>(code)) {
    case NLOPT_SUCCESS:
      return "success";
    case NLOPT_STOPVAL_REACHED:
      return "objective reached the stop value";
    case NLOPT_FTOL_REACHED:
      return "converged (relative/absolute objective tolerance)";
    case NLOPT_XTOL_REACHED:
      return "converged (parameter tolerance)";
    case NLOPT_MAXEVAL_REACHED:
      return "stopped: evaluation budget used up";
    case NLOPT_MAXTIME_REACHED:
      return "stopped: time budget used up";
    case NLOPT_FAILURE:
      return "failed";
    case NLOPT_INVALID_ARGS:
      return "invalid arguments (bounds or start point)";
    case NLOPT_OUT_OF_MEMORY:
      return "out of memory";
    case NLOPT_ROUNDOFF_LIMITED:
      return "stopped: round-off limited";
    case NLOPT_FORCED_STOP:
      return "stopped by the objective (an evaluation failed)";
    default:
      return "unknown NLopt result";
  }
}

bool nlopt_result_converged(int code) {
  return code == NLOPT_SUCCESS || code == NLOPT_STOPVAL_REACHED || code == NLOPT_FTOL_REACHED ||
         code == NLOPT_XTOL_REACHED;
}

}  // namespace mneedle
