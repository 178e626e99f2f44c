#include "mneedle/nlopt_status.h"

#include <gtest/gtest.h>
#include <nlopt.h>

TEST(NloptStatus, ToleranceStopsCountAsConvergedAndBudgetStopsDoNot) {
  EXPECT_TRUE(mneedle::nlopt_result_converged(NLOPT_XTOL_REACHED));
  EXPECT_TRUE(mneedle::nlopt_result_converged(NLOPT_FTOL_REACHED));
  EXPECT_FALSE(mneedle::nlopt_result_converged(NLOPT_MAXEVAL_REACHED));
  EXPECT_FALSE(mneedle::nlopt_result_converged(NLOPT_FORCED_STOP));
}

TEST(NloptStatus, EveryCodeHasADescription) {
  for (int code = -5; code <= 6; ++code) EXPECT_FALSE(mneedle::describe_nlopt_result(code).empty());
}
