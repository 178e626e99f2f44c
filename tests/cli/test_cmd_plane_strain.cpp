// Runs the built `mneedle plane-strain` end to end: paper C's run without cohesion, its CSV and
// plot, and what happens to bad input.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "../plot/svg_reader.h"
#include "run_mneedle.h"

namespace {

using mneedle::test::run_mneedle;

const std::filesystem::path kWork = std::filesystem::temp_directory_path() /
                                    ("mneedle_test_plane_strain_" + std::to_string(::getpid()));

struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    std::filesystem::remove_all(kWork, ignored);
  }
} const kScratchCleanup;

const std::string kPaperC =
    "plane-strain --tissue 7kPa,0.475 --block 160mm,86mm --thickness 15mm --needle-width 8mm "
    "--tip-angle 50deg --friction 0.5 --element-size 1.6mm";

TEST(CmdPlaneStrain, PaperCRunGivesTheLibrarysLedgerWithItsFiles) {
  std::filesystem::create_directories(kWork);
  const auto csv = (kWork / "steps.csv").string(), svg = (kWork / "force.svg").string();
  const auto run = run_mneedle(kPaperC + " --json --csv '" + csv + "' --plot '" + svg + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  // The library's value for this problem (test_plane_strain_insertion: 44.58 mJ at 1.6 mm
  // cells); the CLI adds only parsing, so the same number to round-off.
  EXPECT_NEAR(j["end"]["external_work_J"].get<double>(), 44.58e-3, 0.01e-3);
  EXPECT_DOUBLE_EQ(j["end"]["travel_m"].get<double>(), 0.086);  // default travel: the depth
  EXPECT_DOUBLE_EQ(j["problem"]["shoulder_radius_m"].get<double>(), 2e-3);
  EXPECT_NEAR(j["problem"]["tip_angle_rad"].get<double>(), 50.0 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(j["steps"]["travel_m"].size(), 433u);
  EXPECT_LT(j["max_abs_balance_error"].get<double>(), 0.02);
  EXPECT_TRUE(j["warnings"].empty());
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("travel [m],force [N],", 0), 0u) << header;
  int rows = 0;
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_EQ(rows, 433);
  EXPECT_GT(std::filesystem::file_size(svg), 1000u);
}

TEST(CmdPlaneStrain, CohesiveRunReportsThePunctureAndTheCrack) {
  const auto run = run_mneedle(kPaperC +
                               " --toughness 17.43J/m2 --cohesive-openings 7mm,7.5mm "
                               "--initial-cut 3.2mm --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  // The library's values for this problem (test_plane_strain_insertion): the first cell fails
  // at 24.29 mm travel (0.777 N), 20.36 mJ dissipated by 86 mm; the CLI only parses.
  EXPECT_NEAR(j["puncture"]["travel_m"].get<double>(), 24.29e-3, 0.01e-3);
  EXPECT_NEAR(j["puncture"]["force_N"].get<double>(), 0.777, 0.001);
  EXPECT_NEAR(j["end"]["fracture_energy_J"].get<double>(), 20.36e-3, 0.01e-3);
  EXPECT_DOUBLE_EQ(j["problem"]["cohesion"]["viscosity_m"].get<double>(), 0.5e-3);
  EXPECT_EQ(j["steps"]["crack_depth_m"].size(), 433u);
}

TEST(CmdPlaneStrain, EnergyPlotDrawsEveryTermOfTheLedgerLikePaperCsFigure14) {
  std::filesystem::create_directories(kWork);
  const auto svg = (kWork / "energy.svg").string();
  const auto run = run_mneedle(kPaperC +
                               " --toughness 17.43J/m2 --cohesive-openings 7mm,7.5mm "
                               "--initial-cut 3.2mm --energy-plot '" +
                               svg + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto t = mneedle::test::texts(mneedle::test::read_svg(svg));
  // 77 mJ of work at the end: the axis picks mJ.
  for (const char* label :
       {"energy [mJ]", "needle travel [mm]", "external work", "strain energy", "friction work",
        "cohesive work", "fracture energy (dissipated)", "crack runs"})
    EXPECT_TRUE(mneedle::test::has_text(t, label)) << label;
}

TEST(CmdPlaneStrain, EnergyPlotWithoutCohesionLeavesTheCohesiveTermsOut) {
  std::filesystem::create_directories(kWork);
  const auto svg = (kWork / "energy_cut.svg").string();
  const auto run = run_mneedle(kPaperC + " --travel 20mm --energy-plot '" + svg + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto t = mneedle::test::texts(mneedle::test::read_svg(svg));
  EXPECT_TRUE(mneedle::test::has_text(t, "external work"));
  EXPECT_TRUE(mneedle::test::has_text(t, "friction work"));
  EXPECT_FALSE(mneedle::test::has_text(t, "cohesive work"));
}

TEST(CmdPlaneStrain, CohesiveOptionsWithoutToughnessAreRefused) {
  const auto run = run_mneedle(kPaperC + " --initial-cut 3.2mm");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("need --toughness"), std::string::npos) << run.err;
}

// 0 is the library's "default" radius; on the command line it would be a sharp shoulder, which
// is not offered (it ran with the default 2 mm, exit 0).
TEST(CmdPlaneStrain, AZeroShoulderRadiusIsRefusedNotReplacedByTheDefault) {
  const auto run = run_mneedle(kPaperC + " --shoulder-radius 0mm");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--shoulder-radius 0mm: must be positive"), std::string::npos) << run.err;
}

TEST(CmdPlaneStrain, ValueWithoutUnitIsOneLineNamingTheOption) {
  const auto run = run_mneedle(
      "plane-strain --tissue 7kPa,0.475 --block 160mm,86mm --thickness 15 --needle-width 8mm "
      "--tip-angle 50deg");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--thickness"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("needs a unit"), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

TEST(CmdPlaneStrain, BadMaterialIsRefusedNamingTheField) {
  const auto run = run_mneedle(
      "plane-strain --tissue 7kPa,0.6 --block 160mm,86mm --thickness 15mm --needle-width 8mm "
      "--tip-angle 50deg");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("poisson_ratio"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out.empty()) << run.out;
}

}  // namespace
