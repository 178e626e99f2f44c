// `mneedle report` and `--report DIR` (docs/cli.md, "Reports"): what they write and what they
// refuse. The page in a browser is checked by tests/report/check_report.mjs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::file_text;
using mneedle::test::run_mneedle;

const std::string kPunch = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/axisymmetric_punch.toml";

fs::path work(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("mneedle_report_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t pos = 0; (pos = text.find(what, pos)) != std::string::npos; pos += what.size())
    ++n;
  return n;
}

TEST(ReportCommand, SimulateReportFolderHoldsTheJsonItPrintsAndThePage) {
  const fs::path dir = work("simulate");
  // Same time for both runs, so that the two JSON texts can be compared whole.
  const auto run =
      run_mneedle("simulate '" + kPunch + "' --json --quiet --report '" + dir.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  auto printed = nlohmann::json::parse(run.out);
  auto written = nlohmann::json::parse(file_text(dir / "result.json"));
  EXPECT_EQ(written["needles"], printed["needles"]);
  EXPECT_EQ(written["provenance"]["command"], printed["provenance"]["command"]);
  const std::string page = file_text(dir / "report.html");
  EXPECT_NE(page.find("<h2>Puncture</h2>"), std::string::npos);
  EXPECT_EQ(count(page, "<figure class=\"plot\">"), 1u);
  EXPECT_EQ(count(page, "<option value="), printed["needles"].size());
  EXPECT_NE(page.find("<td>tool</td><td><code>mneedle</code></td>"), std::string::npos);
  fs::remove_all(dir);
}

TEST(ReportCommand, ScreenResultGivesTheRankingCurvesAndEveryNeedle) {
  const fs::path dir = work("screen");
  const auto screen = run_mneedle("screen '" + std::string(MNEEDLE_SOURCE_ROOT) +
                                  "/designs' --scene '" + std::string(MNEEDLE_SOURCE_ROOT) +
                                  "/designs/scenes/silicone_phantom.toml' --model analytic --json");
  ASSERT_EQ(screen.exit_code, 0) << screen.err;
  std::ofstream(dir / "r.json") << screen.out;
  const auto run = run_mneedle("report '" + (dir / "r.json").string() + "' -o '" +
                               (dir / "r.html").string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");  // every needle rebuilt: nothing to say
  const std::string page = file_text(dir / "r.html");
  EXPECT_NE(page.find("<h2>Ranking</h2>"), std::string::npos);
  EXPECT_EQ(count(page, "<option value="), 4u);  // the four shipped designs
  EXPECT_EQ(count(page, "class=\"viewable\""), 4u);
  // The report names the command that wrote it and the one that ran the screen.
  EXPECT_NE(page.find("This page was written by <code>mneedle report"), std::string::npos);
  EXPECT_NE(page.find("<code>mneedle screen"), std::string::npos);
  fs::remove_all(dir);
}

TEST(ReportCommand, ANeedleFileChangedSinceTheRunIsSaidAndLeftOutOfThe3dView) {
  const fs::path dir = work("changed");
  fs::copy_file(std::string(MNEEDLE_SOURCE_ROOT) + "/designs/cone.stl", dir / "cone.stl");
  const auto screen = run_mneedle("screen '" + (dir / "cone.stl").string() + "' --scene '" +
                                  std::string(MNEEDLE_SOURCE_ROOT) +
                                  "/designs/scenes/silicone_phantom.toml' --model analytic --json");
  ASSERT_EQ(screen.exit_code, 0) << screen.err;
  std::ofstream(dir / "r.json") << screen.out;
  std::ofstream(dir / "cone.stl", std::ios::app) << " ";  // one more byte
  const auto run = run_mneedle("report '" + (dir / "r.json").string() + "' -o '" +
                               (dir / "r.html").string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("design cone: not shown in 3-D, " + (dir / "cone.stl").string() +
                         " changed since the run (SHA-256 differs)"),
            std::string::npos)
      << run.err;
  const std::string page = file_text(dir / "r.html");
  EXPECT_EQ(count(page, "<option value="), 0u);
  EXPECT_NE(page.find("changed since the run"), std::string::npos);
  EXPECT_NE(page.find("<h2>Ranking</h2>"), std::string::npos);  // the rest is all there
  fs::remove_all(dir);
}

TEST(ReportCommand, ResultThatIsNotJsonOrNotAResultIsOneLineNamingTheFile) {
  const fs::path dir = work("bad");
  std::ofstream(dir / "broken.json") << "{\"needles\": [";
  auto run = run_mneedle("report '" + (dir / "broken.json").string() + "' -o '" +
                         (dir / "r.html").string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find((dir / "broken.json").string() + ": not JSON"), std::string::npos)
      << run.err;
  std::ofstream(dir / "huge.json") << "{\"needles\": [1e999]}";  // beyond a double
  run = run_mneedle("report '" + (dir / "huge.json").string() + "' -o '" +
                    (dir / "r.html").string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find((dir / "huge.json").string() + ": not JSON"), std::string::npos)
      << run.err;
  std::ofstream(dir / "fit.json") << "{\"parameters\": {}}";
  run = run_mneedle("report '" + (dir / "fit.json").string() + "' -o '" +
                    (dir / "r.html").string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(
      run.err.find((dir / "fit.json").string() + ": not a result of simulate, screen or optimize"),
      std::string::npos)
      << run.err;
  EXPECT_EQ(count(run.err, "\n"), 1u) << run.err;
  EXPECT_FALSE(fs::exists(dir / "r.html"));
  fs::remove_all(dir);
}

// -o naming a folder: one line saying so (it said "cannot write the report (Success)", the
// error code read after the clean-up had reset it).
TEST(ReportCommand, AnOutputThatIsAFolderIsNamedAsOne) {
  const fs::path dir = work("folder");
  const auto sim = run_mneedle("simulate '" + std::string(MNEEDLE_SOURCE_ROOT) +
                               "/designs/scenes/silicone_phantom.toml' --model analytic --json");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  std::ofstream(dir / "result.json") << sim.out;
  fs::create_directories(dir / "out");
  const auto run = run_mneedle("report '" + (dir / "result.json").string() + "' -o '" +
                               (dir / "out").string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find((dir / "out").string() + ": is a folder, not a file"), std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("Success"), std::string::npos) << run.err;
  fs::remove_all(dir);
}

TEST(ReportCommand, OptimizeReportShowsTheHistoryAndTheBestDesign) {
  const fs::path dir = work("optimize");
  const auto run = run_mneedle(
      "optimize --plugin cone --scene '" + std::string(MNEEDLE_SOURCE_ROOT) +
      "/designs/scenes/optimize_silicone.toml' --vary half_angle --model analytic --max-evals 4 "
      "--json --report '" +
      dir.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto printed = nlohmann::json::parse(run.out);
  const std::string page = file_text(dir / "report.html");
  EXPECT_NE(page.find("<h2>History</h2>"), std::string::npos);
  EXPECT_NE(page.find("every evaluation (" + std::to_string(printed["history"].size()) + ")"),
            std::string::npos);
  EXPECT_EQ(count(page, "<figure class=\"plot\">"), 2u);
  EXPECT_NE(page.find("<option value=\"0\">best design</option>"), std::string::npos);
  EXPECT_NE(page.find("<h2>Strength</h2>"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
