// The command line's exit statuses and error lines (docs/cli.md, "Exit status").
#include <gtest/gtest.h>

#include <string>

#include "run_mneedle.h"

namespace {

using mneedle::test::run_mneedle;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;

TEST(ExitStatus, SuccessAndHelpAreZero) {
  EXPECT_EQ(run_mneedle("--help").exit_code, 0);
  EXPECT_EQ(run_mneedle("simulate --help").exit_code, 0);
}

TEST(ExitStatus, BadInputIsOneWithTheErrorPrefix) {
  const auto run = run_mneedle("scene check '" + kRoot + "/no_such_scene.toml'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err.rfind("mneedle: error: ", 0), 0u) << run.err;
}

TEST(ExitStatus, BadCommandLineIsTwoWithTheErrorPrefix) {
  for (const char* args : {"simulate", "simulate x.toml --no-such-option", "no-such-command"}) {
    const auto run = run_mneedle(args);
    EXPECT_EQ(run.exit_code, 2) << args;
    EXPECT_EQ(run.err.rfind("mneedle: error: ", 0), 0u) << args << ": " << run.err;
    EXPECT_NE(run.err.find("(see mneedle --help)"), std::string::npos) << run.err;
  }
}

}  // namespace

namespace {

// docs/cli.md promises an example in every command's help.
TEST(Help, EveryCommandShowsAnExample) {
  for (const char* command : {"scene check", "plugins list", "plugins describe", "generate",
                              "inspect", "force", "strength", "screen", "optimize", "fit",
                              "predict", "stats", "simulate", "toughness", "calibrate"}) {
    const auto run = mneedle::test::run_mneedle(std::string(command) + " --help");
    EXPECT_EQ(run.exit_code, 0) << command << ": " << run.err;
    EXPECT_NE(run.out.find("Example"), std::string::npos) << command << " --help:\n" << run.out;
  }
}

}  // namespace
