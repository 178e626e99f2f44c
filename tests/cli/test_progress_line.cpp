#include "progress_line.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "run_mneedle.h"

namespace {

using mneedle::cli::ProgressLine;
using mneedle::cli::ProgressState;

// A clock the test moves by hand.
struct FakeClock {
  double now = 100.0;
  ProgressLine::Clock clock() {
    return [this] { return now; };
  }
};

const ProgressState kStep{"fe_3d", 7, 20, 35e-6, 1.23e-3};

TEST(ProgressLine, SaysNothingDuringTheFirstSecond) {
  FakeClock t;
  std::ostringstream err;
  ProgressLine line(err, "simulate", false, false, t.clock());
  t.now += 0.9;
  line.update(kStep);
  line.finish();
  EXPECT_EQ(err.str(), "");
}

TEST(ProgressLine, PipedPrintsOneLinePerStepWithDepthForceAndTime) {
  FakeClock t;
  std::ostringstream err;
  ProgressLine line(err, "simulate", false, false, t.clock());
  t.now += 2.1;
  line.update(kStep);
  t.now += 0.5;
  line.update({"fe_3d", 8, 20, 40e-6, 1.5e-3});
  line.finish();
  EXPECT_EQ(err.str(),
            "simulate: fe_3d step 7/20, depth 35 um, force 1.23 mN, 2.1 s\n"
            "simulate: fe_3d step 8/20, depth 40 um, force 1.5 mN, 2.6 s\n");
  t.now += 1234.56;  // a long fine run: still seconds, one decimal
  line.update(kStep);
  EXPECT_NE(err.str().find(", 1237.2 s\n"), std::string::npos) << err.str();
}

TEST(ProgressLine, TerminalRedrawsOneLineAndEndsIt) {
  FakeClock t;
  std::ostringstream err;
  ProgressLine line(err, "simulate", true, false, t.clock());
  t.now += 1.5;
  line.update(kStep);
  line.update(kStep);
  line.finish();
  const std::string text = "simulate: fe_3d step 7/20, depth 35 um, force 1.23 mN, 1.5 s";
  EXPECT_EQ(err.str(), "\r\033[K" + text + "\r\033[K" + text + "\n");
}

// A run that throws leaves through the destructor: the error starts on its own line.
TEST(ProgressLine, LeavingTheScopeEndsTheRedrawnLine) {
  FakeClock t;
  std::ostringstream err;
  {
    ProgressLine line(err, "simulate", true, false, t.clock());
    t.now += 1.5;
    line.update(kStep);
  }
  ASSERT_FALSE(err.str().empty());
  EXPECT_EQ(err.str().back(), '\n');
}

TEST(ProgressLine, QuietPrintsNothing) {
  FakeClock t;
  std::ostringstream err;
  ProgressLine line(err, "simulate", true, true, t.clock());
  t.now += 10.0;
  line.update(kStep);
  line.finish();
  EXPECT_EQ(err.str(), "");
}

// End to end: a run under a second prints nothing on stderr, and --quiet is accepted.
TEST(ProgressLine, ShortSimulateLeavesStderrEmpty) {
  const auto run = mneedle::test::run_mneedle("simulate '" + std::string(MNEEDLE_TEST_ASSETS) +
                                              "/scenes/axisymmetric_punch.toml' --quiet");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
}

}  // namespace
