// Runs the built `mneedle toughness` end to end: J, crack area, what was cut, the integrand CSV
// and the errors.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>

#include "../plot/svg_reader.h"
#include "refdata.h"
#include "run_mneedle.h"

namespace {

using mneedle::test::CommandRun;
using mneedle::test::run_mneedle;

const std::string kCurves = std::string(MNEEDLE_TEST_ASSETS) + "/curves/";
const std::string kPair =
    "toughness '" + kCurves + "toughness_first.csv' '" + kCurves + "toughness_second.csv' ";
const std::filesystem::path kRefdata =
    std::filesystem::path(MNEEDLE_SOURCE_ROOT) / ".." / "shared" / "refdata";
const std::filesystem::path kWork = std::filesystem::temp_directory_path() /
                                    ("mneedle_test_toughness_" + std::to_string(::getpid()));
constexpr double kJ = 19.0;  // the assets' toughness (tests/core/test_toughness.cpp)
const double kShaftArea = std::numbers::pi * 115e-6 * 115e-6;

struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    std::filesystem::remove_all(kWork, ignored);
  }
} const kScratchCleanup;

std::string plugins() {
  return " --plugin-dir '" + std::string(MNEEDLE_PLUGIN_BUILD_DIR) + "'";
}

nlohmann::json json_of(const CommandRun& run) {
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return nlohmann::json::parse(run.out);
}

// Copies an asset with another header line, e.g. "z [mm],F (mN)"; returns the copy's path.
std::string renamed(const std::string& asset, const std::string& header) {
  std::filesystem::create_directories(kWork);
  std::ifstream in(kCurves + asset);
  const auto file = kWork / (header.substr(0, 4) + "_" + asset);
  std::ofstream out(file);
  std::string line;
  do {
    std::getline(in, line);
  } while (!line.empty() && line[0] == '#');  // comments, then the header
  out << header << "\n" << in.rdbuf();
  return file.string();
}

TEST(CmdToughness, JsonGivesTheKnownJAndTheCrackArea) {
  const auto j = json_of(run_mneedle(kPair + "--area 0.0415476mm^2 --json"));
  EXPECT_NEAR(j["toughness_J_per_m2"].get<double>(), kJ, 0.01 * kJ);
  EXPECT_NEAR(j["crack_area_m2"].get<double>(), kShaftArea, 1e-6 * kShaftArea);
  EXPECT_EQ(j["crack_area_source"], "given");
  EXPECT_EQ(j["second_pass"], "file");
  EXPECT_NEAR(j["end_depth_m"].get<double>(), 399e-6, 1e-9);
  EXPECT_EQ(j["first"]["cut"]["hold"], 51);
  EXPECT_EQ(j["first"]["cut"]["retraction"], 100);
  EXPECT_EQ(j["first"]["cut"]["before_contact"], 100);
  EXPECT_EQ(j["second"]["cut"]["repeated_depth"], 22);
  EXPECT_EQ(j["second"]["cut"]["receding_depth"], 8);
  EXPECT_EQ(j["second"]["cut"]["beyond_end"], 26);
  EXPECT_TRUE(j["warnings"].empty());
}

TEST(CmdToughness, PluginNeedleGivesItsShaftSectionAsTheCrackArea) {
  const auto j = json_of(run_mneedle(kPair +
                                     "--plugin cone --set diameter=230um --set length=1mm "
                                     "--set half_angle=26.565deg --json" +
                                     plugins()));
  EXPECT_NEAR(j["crack_area_m2"].get<double>(), kShaftArea, 0.01 * kShaftArea);
  EXPECT_NEAR(j["toughness_J_per_m2"].get<double>(), kJ, 0.015 * kJ);
  EXPECT_NEAR(j["needle_tip_length_m"].get<double>(), 230e-6, 10e-6);
  EXPECT_EQ(j["crack_area_source"].get<std::string>().find("cone"), 0u);
}

TEST(CmdToughness, TextSaysJWithUnitsAndWhatWasCut) {
  const auto run = run_mneedle(kPair + "--area 41547.6um^2");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("fracture toughness J = 18.9"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(" J/m^2"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("51 in the hold, 100 in the retraction"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("merged 22 repeated and 8 receding depths"), std::string::npos) << run.out;
}

TEST(CmdToughness, IntegrandCsvHasDepthBothForcesAndTheirDifference) {
  std::filesystem::create_directories(kWork);
  const auto csv = (kWork / "integrand.csv").string();
  const auto j =
      json_of(run_mneedle(kPair + "--area 0.0415476mm^2 --json --integrand '" + csv + "'"));
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "depth_m,first_force_N,second_force_N,difference_N");
  double z = 0, f = 0, s = 0, d = 0, last_z = -1, work = 0, prev_z = 0, prev_d = 0;
  char comma = 0;
  int rows = 0;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    row >> z >> comma >> f >> comma >> s >> comma >> d;
    ASSERT_GT(z, last_z);
    ASSERT_NEAR(d, f - s, 1e-12);
    if (rows++ > 0) work += 0.5 * (d + prev_d) * (z - prev_z);
    last_z = prev_z = z;
    prev_d = d;
  }
  EXPECT_GT(rows, 300);
  EXPECT_NEAR(last_z, j["end_depth_m"].get<double>(), 1e-12);
  EXPECT_NEAR(work, j["work_difference_J"].get<double>(), 1e-6 * std::abs(work));
}

TEST(CmdToughness, ColumnsFoundByNameWithBracketedUnits) {
  const auto reference = json_of(run_mneedle(kPair + "--area 1mm^2 --json"));
  const double expected = reference["toughness_J_per_m2"].get<double>();
  const auto j = json_of(run_mneedle(
      "toughness '" + renamed("toughness_first.csv", "t [s],z [mm],F (mN)") + "' '" +
      renamed("toughness_second.csv", "position (um),force [N]") + "' --area 1mm^2 --json"));
  EXPECT_NEAR(j["toughness_J_per_m2"].get<double>(), expected, 1e-9 * expected);
}

TEST(CmdToughness, OtherColumnsAreChosenByOptionAndNeedTheirUnit) {
  const std::string first = "toughness '" + kCurves + "toughness_first.csv' ";
  const auto reference = json_of(run_mneedle(first + "--second-from tail --area 1mm^2 --json"));
  const std::string file = "toughness '" + renamed("toughness_first.csv", "time_s,pos,load") + "'";
  const std::string options = " --second-from tail --area 1mm^2 --depth-col pos --force-col load";
  const auto j = json_of(run_mneedle(file + options + " --depth-unit mm --force-unit mN --json"));
  EXPECT_NEAR(j["toughness_J_per_m2"].get<double>(), reference["toughness_J_per_m2"].get<double>(),
              1e-12);
  EXPECT_EQ(j["second_pass"], "tail");
  EXPECT_NEAR(j["puncture"]["peak_depth_m"].get<double>(), 229e-6, 1.5e-6);
  const auto no_unit = run_mneedle(file + options);
  EXPECT_EQ(no_unit.exit_code, 1);
  EXPECT_NE(no_unit.err.find(":1: column 'pos' has no unit suffix"), std::string::npos)
      << no_unit.err;
}

TEST(CmdToughness, BadInputIsOneLineNamingFileAndLine) {
  const auto expect_error = [](const std::string& args, const std::string& text) {
    const auto run = run_mneedle(args);
    EXPECT_EQ(run.exit_code, 1) << args;
    EXPECT_NE(run.err.find(text), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
  };
  const std::string second = "' '" + kCurves + "toughness_second.csv' --area 1mm^2";
  expect_error("toughness '" + kCurves + "missing_column.csv" + second,
               "missing_column.csv:1: no force column");
  expect_error("toughness '" + kCurves + "text_in_number.csv" + second,
               "text_in_number.csv:4: column 'fz_N': 'abc' is not a number");
  expect_error("toughness '" + kCurves + "no_loading_branch.csv" + second,
               "no_loading_branch.csv:10: no loading branch");
  expect_error(kPair + "--area 1mm^2 --plugin cone", "exactly one of --area, --needle or --plugin");
  expect_error(kPair, "exactly one of --area, --needle or --plugin");
  expect_error(kPair + "--area 1mm", "area '1mm'");
  expect_error("toughness '" + kCurves + "toughness_first.csv' --area 1mm^2",
               "give either SECOND.csv or --second-from");
  expect_error("toughness '" + kCurves + "toughness_second.csv' --second-from tail --area 1mm^2",
               "toughness_second.csv: no puncture");
  expect_error(kPair + "--area 1mm^2 --align surface", "expected contact or travel");
}

// The crack term of the cone pair of the assets (tests/core/measurement/test_toughness.cpp):
// J dA/dz with A(z) = pi (z/2)^2 until the tip is in at 230 um.
double crack_force(double z) {
  return z < 230e-6 ? kJ * 2 * std::numbers::pi * 0.25 * z : 0.0;
}

// A pass written from contact on, depth_m,force_N, as `mneedle force --csv` writes it: the cone
// pair, every 10 um to 2 mm.
std::string from_contact(const std::string& name, bool cracks) {
  std::filesystem::create_directories(kWork);
  const auto file = kWork / name;
  std::ofstream out(file);
  out << "depth_m,force_N\n" << std::setprecision(12);
  for (int i = 0; i <= 200; ++i) {
    const double z = 10e-6 * i;
    out << z << "," << 1000.0 * std::pow(z, 1.5) + (cracks ? crack_force(z) : 0.0) << "\n";
  }
  return "'" + file.string() + "' ";
}

TEST(CmdToughness, CurvesRecordedFromContactGiveTheKnownJ) {
  const auto j =
      json_of(run_mneedle("toughness " + from_contact("first.csv", true) +
                          from_contact("second.csv", false) + "--area 0.0415476mm^2 --json"));
  // Reference: the trapezoid rule over the written samples of the crack term, 4.4 % below kJ
  // (half a 10 um step of the term is lost where it ends); 1e-6 for the 12 digits written.
  // Before, the baseline was the median of the first samples of the rise: J = 367 J/m^2.
  double work = 0.0;
  for (int i = 1; i <= 200; ++i)
    work += 0.5 * (crack_force(10e-6 * i) + crack_force(10e-6 * (i - 1))) * 10e-6;
  const double expected = work / 0.0415476e-6;
  EXPECT_NEAR(expected, kJ, 0.05 * kJ);
  EXPECT_NEAR(j["toughness_J_per_m2"].get<double>(), expected, 1e-6 * expected);
  EXPECT_EQ(j["first"]["contact_travel_m"].get<double>(), 0.0);
  EXPECT_EQ(j["first"]["baseline_N"].get<double>(), 0.0);
  EXPECT_EQ(j["second"]["cut"]["before_contact"].get<int>(), 0);
  EXPECT_TRUE(j["warnings"].empty());
}

TEST(CmdToughness, MaxDepthThatIsNotPositiveOrKeepsTooFewSamplesIsRefused) {
  const auto pair = "toughness " + from_contact("first.csv", true) +
                    from_contact("second.csv", false) + "--area 0.0415476mm^2 --max-depth ";
  for (const std::string bad : {"0", "-1mm"}) {
    const auto run = run_mneedle(pair + bad);
    EXPECT_EQ(run.exit_code, 1) << bad;
    EXPECT_NE(run.err.find("--max-depth '" + bad + "': must be a positive length"),
              std::string::npos)
        << run.err;
  }
  const auto tiny = run_mneedle(pair + "1e-12mm");
  EXPECT_EQ(tiny.exit_code, 1);
  EXPECT_NE(tiny.err.find("--max-depth 1e-06 nm keeps 1 sample of "), std::string::npos)
      << tiny.err;
  EXPECT_NE(tiny.err.find("at least 3 of each are needed"), std::string::npos) << tiny.err;
  EXPECT_EQ(std::count(tiny.err.begin(), tiny.err.end(), '\n'), 1) << tiny.err;
  EXPECT_EQ(run_mneedle(pair + "20um").exit_code, 0);  // samples at 0, 10 and 20 um
}

TEST(CmdToughness, PhantomRecordingRunsWithASecondPassFromItsRetraction) {
  const auto file =
      kRefdata / "phantom_insertions" / "skin-on-muscle_2_0_3_1_2024-06-19-11-35-16.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto j = json_of(run_mneedle("toughness '" + file.string() +
                                     "' --second-from retraction --plugin cylinder "
                                     "--set diameter=1.27mm --set length=30mm --json" +
                                     plugins()));
  EXPECT_GT(j["toughness_J_per_m2"].get<double>(), 0.0);
  EXPECT_GT(j["first"]["cut"]["retraction"].get<int>(), 1000);
  EXPECT_TRUE(j["warnings"].empty());
}

TEST(CmdToughness, PlotDrawsBothPassesAndTheirDifference) {
  std::filesystem::create_directories(kWork);
  const auto svg = kWork / "j.svg";
  const auto run = run_mneedle(kPair + "--area 0.0415476mm^2 --plot '" + svg.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string text = mneedle::test::read_svg(svg);
  const auto t = mneedle::test::texts(text);
  for (const char* label : {"first pass F", "second pass F'", "F - F'"})
    EXPECT_TRUE(mneedle::test::has_text(t, label)) << label;
  for (const char* colour : {"#1F77B4", "#D62728", "#2CA02C"})
    EXPECT_FALSE(mneedle::test::polyline(text, colour).empty()) << colour;
}

}  // namespace
