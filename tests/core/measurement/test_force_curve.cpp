#include "mneedle/measurement/force_curve.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "mneedle/base/error.h"
#include "refdata.h"

namespace {

const std::string kCurves = std::string(MNEEDLE_TEST_ASSETS) + "/curves/";
const std::filesystem::path kRefdata =
    std::filesystem::path(MNEEDLE_SOURCE_ROOT) / ".." / "shared" / "refdata";

const std::filesystem::path kWork = std::filesystem::temp_directory_path() /
                                    ("mneedle_test_force_curve_" + std::to_string(::getpid()));

// Removes the scratch directory when the test program ends.
struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    std::filesystem::remove_all(kWork, ignored);
  }
} const kScratchCleanup;

// A noise-free curve sampled every `step` of travel from `first` to `last`.
mneedle::ForceCurve sampled(double (*force)(double), double first, double last, double step) {
  mneedle::ForceCurve c;
  c.source = "sampled.csv";
  for (int i = 0; first + i * step <= last + 1e-12; ++i) {
    c.depth_m.push_back(first + i * step);
    c.force_N.push_back(force(first + i * step));
    c.line.push_back(static_cast<std::size_t>(i) + 2);
  }
  return c;
}

std::string error_of(const std::string& file, const mneedle::CurveColumns& columns = {}) {
  try {
    const auto curve = mneedle::read_force_curve_csv(kCurves + file, columns);
    mneedle::extract_loading_branch(curve);
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ForceCurve, ReadsColumnsAndConvertsUnitsFromTheirSuffix) {
  const auto c = mneedle::read_force_curve_csv(kCurves + "loading_hold_retraction.csv");
  ASSERT_EQ(c.depth_m.size(), c.force_N.size());
  ASSERT_EQ(c.time_s.size(), c.force_N.size());
  EXPECT_NEAR(c.depth_m[1], 0.1e-3, 1e-12);  // travel_mm
  EXPECT_NEAR(c.time_s[1], 0.1, 1e-12);
  EXPECT_EQ(c.line.front(), 2u);
}

// A column named like time whose unit is none (`time`, a temperature `t_C`) is not read as the
// clock: the curve reads without a time (it refused the whole file, pointing at an option that
// does not exist).
TEST(ForceCurve, ATimeLikeColumnWithoutATimeUnitIsLeftUnread) {
  const auto file = std::filesystem::temp_directory_path() / "mneedle_time_without_unit.csv";
  for (const char* name : {"time", "t_C"}) {
    std::ofstream(file) << name << ",travel_mm,fz_N\n0,0,0\n1,0.1,0.5\n2,0.2,1\n";
    const auto c = mneedle::read_force_curve_csv(file);
    EXPECT_EQ(c.depth_m.size(), 3u) << name;
    EXPECT_TRUE(c.time_s.empty()) << name;
  }
  std::filesystem::remove(file);
}

TEST(ForceCurve, ExplicitUnitOverridesTheSuffix) {
  const mneedle::CurveColumns columns{"", "fz_N", "", "", "mN"};
  const auto c = mneedle::read_force_curve_csv(kCurves + "loading_hold_retraction.csv", columns);
  const auto plain = mneedle::read_force_curve_csv(kCurves + "loading_hold_retraction.csv");
  EXPECT_NEAR(c.force_N[40], plain.force_N[40] * 1e-3, 1e-15);
}

TEST(ForceCurve, MissingColumnNamesFileAndHeaderLine) {
  const auto msg = error_of("missing_column.csv");
  EXPECT_NE(msg.find("missing_column.csv:1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("no force column"), std::string::npos) << msg;
}

TEST(ForceCurve, AskedColumnThatIsAbsentIsNamed) {
  const mneedle::CurveColumns columns{"depth_mm", "", "", "", ""};
  const auto msg = error_of("loading_hold_retraction.csv", columns);
  EXPECT_NE(msg.find(":1: no column 'depth_mm'"), std::string::npos) << msg;
}

TEST(ForceCurve, TextInANumberNamesFileLineAndColumn) {
  const auto msg = error_of("text_in_number.csv");
  EXPECT_NE(msg.find("text_in_number.csv:4"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'abc' is not a number"), std::string::npos) << msg;
}

// 10^308 N passed as a puncture force (work 5e302 J); 10^308 kN, finite only before its unit,
// was dropped as noise and reported as "no loading branch" on the last line. Both are refused on
// their own line. Excel's "CSV UTF-8" byte-order mark no longer hides the first column's name.
TEST(ForceCurve, ASampleBeyondAnyMeasurementIsRefusedOnItsLineAndAByteOrderMarkIsSkipped) {
  std::filesystem::create_directories(kWork);
  const auto write = [](const std::string& name, const std::string& text) {
    const auto path = kWork / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  };
  struct Case {
    std::string header, value, problem;
  };
  for (const auto& [header, value, problem] :
       {Case{"force [N]", "1e308", "is beyond any measurement"},
        Case{"force [kN]", "1e308", "overflows in SI units"},
        Case{"force [N]", "-2e9", "is beyond any measurement"}}) {
    const auto file =
        write("big.csv", "depth [mm]," + header + "\n0,0\n0.1,0.01\n0.2," + value + "\n");
    try {
      mneedle::read_force_curve_csv(file, {});
      FAIL() << header << " " << value;
    } catch (const mneedle::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("big.csv:4: column '" + header + "': '" + value + "' " +
                                           problem),
                std::string::npos)
          << e.what();
    }
  }
  // A time column may hold clock time (Unix seconds): read, not refused.
  const auto clock = write("clock.csv",
                           "time [s],depth [mm],force [N]\n1733600000,0,0\n"
                           "1733600001,0.1,0.01\n");
  EXPECT_NEAR(mneedle::read_force_curve_csv(clock, {}).time_s[1], 1733600001.0, 1e-6);
  const auto bom = write("bom.csv",
                         "\xEF\xBB\xBF"
                         "depth [mm],force [N]\n0,0\n0.1,0.01\n");
  const auto curve = mneedle::read_force_curve_csv(bom, {});
  ASSERT_EQ(curve.depth_m.size(), 2u);
  EXPECT_EQ(curve.depth_column, "depth [mm]");
  EXPECT_NEAR(curve.force_N[1], 0.01, 1e-15);
}

TEST(ForceCurve, FlatRecordingHasNoLoadingBranch) {
  const auto msg = error_of("no_loading_branch.csv");
  EXPECT_NE(msg.find("no_loading_branch.csv:10"), std::string::npos) << msg;
  EXPECT_NE(msg.find("no loading branch"), std::string::npos) << msg;
}

TEST(ForceCurve, LoadingBranchStartsAtContactAndCutsHoldAndRetraction) {
  const auto raw = mneedle::read_force_curve_csv(kCurves + "loading_hold_retraction.csv");
  const auto b = mneedle::extract_loading_branch(raw);
  EXPECT_NEAR(b.baseline_N, -0.010, 1e-3);
  EXPECT_GT(b.contact_travel_m, 1.75e-3);
  EXPECT_LT(b.contact_travel_m, 2.05e-3);
  EXPECT_NEAR(b.curve.depth_m.back() + b.contact_travel_m, 6.0e-3, 0.11e-3);
  EXPECT_NEAR(static_cast<double>(b.hold_samples), 9.5, 0.6);
  EXPECT_NEAR(static_cast<double>(b.retraction_samples), 60.0, 1.0);
  EXPECT_NEAR(b.curve.depth_m.front(), 0.0, 1e-15);
  // Force is baseline-corrected: 0.5 (x - 2)^2 N at 4 mm travel.
  const auto it = std::find_if(b.curve.depth_m.begin(), b.curve.depth_m.end(),
                               [&](double d) { return d + b.contact_travel_m > 3.99e-3; });
  const auto i = static_cast<std::size_t>(it - b.curve.depth_m.begin());
  EXPECT_NEAR(b.curve.force_N[i], 2.0, 0.01);
  EXPECT_NE(b.summary.find(" in the hold"), std::string::npos) << b.summary;
}

TEST(ForceCurve, CurveRisingFromItsFirstSampleStartsAtContactWithNoBaselineRemoved) {
  // As `mneedle force --csv` writes it: (0, 0), then 50 N/m from the first sample on. The first
  // 5 % of the samples rise, so none of them is a baseline (docs/model.md, "Curve reading").
  const auto b =
      mneedle::extract_loading_branch(sampled([](double z) { return 50.0 * z; }, 0.0, 2e-3, 10e-6));
  EXPECT_TRUE(b.starts_at_contact);
  EXPECT_FALSE(b.contact_before_first_sample);
  EXPECT_EQ(b.contact_index, 0u);
  EXPECT_EQ(b.baseline_N, 0.0);
  EXPECT_EQ(b.contact_travel_m, 0.0);
  EXPECT_DOUBLE_EQ(b.curve.force_N.back(), 0.1);  // 50 N/m at 2 mm, nothing subtracted
  EXPECT_NE(b.summary.find("no baseline removed"), std::string::npos) << b.summary;
}

TEST(ForceCurve, CurveLoadedAtItsFirstStepIsMeasuredFromTravelZero) {
  // As `mneedle simulate --csv` writes it: depth below the surface from its first step (80 um)
  // on, already loaded there. Contact is the surface, travel 0, not the first sample.
  const auto b = mneedle::extract_loading_branch(
      sampled([](double z) { return 1e3 * std::pow(z, 1.5); }, 80e-6, 1.6e-3, 80e-6));
  EXPECT_TRUE(b.contact_before_first_sample);
  EXPECT_EQ(b.contact_index, 0u);
  EXPECT_EQ(b.contact_travel_m, 0.0);
  EXPECT_EQ(b.baseline_N, 0.0);
  EXPECT_EQ(b.curve.depth_m.front(), 80e-6);
  EXPECT_EQ(b.curve.force_N.front(), 1e3 * std::pow(80e-6, 1.5));
}

TEST(ForceCurve, ApproachShorterThanTheBaselineWindowKeepsItsOffsetAndContact) {
  // 201 samples: the baseline window is the first 10, but only 5 are approach (0.5 mN offset,
  // contact at the 5th, travel 40 um). The loaded samples of the window are left out of it.
  const auto b = mneedle::extract_loading_branch(
      sampled([](double z) { return 0.5e-3 + (z > 40e-6 + 1e-12 ? 50.0 * (z - 40e-6) : 0.0); }, 0.0,
              2e-3, 10e-6));
  EXPECT_FALSE(b.starts_at_contact);
  EXPECT_EQ(b.contact_index, 4u);
  EXPECT_NEAR(b.contact_travel_m, 40e-6, 1e-15);  // reference: the construction, exact to rounding
  EXPECT_EQ(b.baseline_N, 0.5e-3);
  EXPECT_EQ(b.noise_N, 0.0);
}

TEST(ForceCurve, TravelDecreasingFromTheFirstSampleIsNamedBeforeTheForce) {
  // Rows of a loading written deepest first: the force falls with the travel, so without the
  // travel check it reads as "never rises above the noise".
  std::filesystem::create_directories(kWork);
  const auto file = kWork / "decreasing.csv";
  {
    std::ofstream out(file);
    out << "time_s,travel_mm,fz_N\n";
    for (int i = 0; i < 60; ++i) {
      const double travel = 6.0 - 0.1 * i;
      out << 0.1 * i << "," << travel << "," << 0.15 * travel * travel << "\n";
    }
  }
  std::string msg = "no error";
  try {
    mneedle::extract_loading_branch(mneedle::read_force_curve_csv(file));
  } catch (const mneedle::InputError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("decreasing.csv:3: column 'travel_mm' decreases from its first sample"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("6 mm at line 2 to 100 um at line 61"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("noise"), std::string::npos) << msg;
}

TEST(ForceCurve, HoldSegmentStartsAtTheEndOfLoading) {
  const auto raw = mneedle::read_force_curve_csv(kCurves + "loading_hold_retraction.csv");
  const auto b = mneedle::extract_loading_branch(raw);
  const auto hold = mneedle::hold_segment(raw, b);
  ASSERT_GE(hold.time_s.size(), 10u);
  EXPECT_NEAR(hold.time_s.front(), 0.0, 1e-12);
  EXPECT_NEAR(hold.force_N.back(), 8.0 - 0.9, 0.02);
  EXPECT_NEAR(hold.time_s.back() - hold.time_s[hold.time_s.size() - 2], 0.1, 1e-9);
}

TEST(ForceCurve, LoadingSpeedIsTheSlopeOfTravelOverTime) {
  const auto raw = mneedle::read_force_curve_csv(kCurves + "loading_hold_retraction.csv");
  EXPECT_NEAR(mneedle::loading_speed(mneedle::extract_loading_branch(raw)), 1e-3, 1e-6);
}

TEST(ForceCurve, RealPhantomRecordingContactsAFewMillimetresIn) {
  const auto file =
      kRefdata / "phantom_insertions" / "skin-on-muscle_1_0_3_2_2024-06-19-11-43-49.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto b = mneedle::extract_loading_branch(mneedle::read_force_curve_csv(file));
  EXPECT_GT(b.contact_travel_m, 1.0e-3);
  EXPECT_LT(b.contact_travel_m, 4.0e-3);
  EXPECT_GT(b.hold_samples, 400u);  // 5 s at about 100 Hz
  EXPECT_GT(b.retraction_samples, 1000u);
  EXPECT_NEAR(mneedle::loading_speed(b), 1e-3, 0.05e-3);
}

TEST(ForceCurve, DigitisedLiverCurveWithoutTimeColumnIsReadable) {
  const auto file = kRefdata / "okamura_liver" / "depth_force_curveA_mm.csv";
  MNEEDLE_NEED_REFDATA(file);
  const auto raw = mneedle::read_force_curve_csv(file);
  EXPECT_TRUE(raw.time_s.empty());
  const auto b = mneedle::extract_loading_branch(raw);
  // Flat (digitised noise) to 5.35 mm, next point 9.46 mm at 0.025 N: contact lies in between.
  EXPECT_GT(b.contact_travel_m, 4e-3);
  EXPECT_LT(b.contact_travel_m, 9.5e-3);
  EXPECT_GT(*std::max_element(b.curve.force_N.begin(), b.curve.force_N.end()), 2.0);
}

TEST(ForceAt, InterpolatesBetweenSamplesAndHoldsTheEnds) {
  mneedle::ForceCurve c;
  c.depth_m = {0.0, 1e-3, 3e-3};
  c.force_N = {0.0, 1.0, 0.0};
  EXPECT_DOUBLE_EQ(mneedle::force_at(c, 0.5e-3), 0.5);
  EXPECT_DOUBLE_EQ(mneedle::force_at(c, 2.5e-3), 0.25);
  EXPECT_DOUBLE_EQ(mneedle::force_at(c, -1.0), 0.0);
  EXPECT_DOUBLE_EQ(mneedle::force_at(c, 1e-3), 1.0);
  EXPECT_DOUBLE_EQ(mneedle::force_at(c, 1.0), 0.0);
}

}  // namespace
