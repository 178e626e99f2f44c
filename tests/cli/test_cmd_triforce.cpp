// Runs the built `mneedle fit`, `predict` and `stats` end to end and checks status and output.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include "../plot/svg_reader.h"
#include "run_mneedle.h"

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include "mneedle/measurement/triforce_model.h"

namespace {

using mneedle::test::CommandRun;
using mneedle::test::run_mneedle;

const std::filesystem::path kWork = std::filesystem::temp_directory_path() /
                                    ("mneedle_test_triforce_" + std::to_string(::getpid()));

// Removes the scratch directory when the test program ends.
struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    std::filesystem::remove_all(kWork, ignored);
  }
} const kScratchCleanup;

// A recording like the rig's: approach, loading at 1 mm/s from contact at 2 mm, hold, retraction.
std::string write_recording() {
  mneedle::TriforceParams p;
  p.layers[0] = {0.0, 1.0, 500.0, 0.8, 0.5, 4e4};
  const mneedle::TriforceModel model(p);
  const mneedle::InsertionConditions c{1e-3, std::numbers::pi / 2.0};
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::filesystem::create_directories(kWork);
  const auto file = kWork / "recording.csv";
  std::ofstream out(file);
  out << "time_s,travel_mm,fz_N\n";
  double t = 0.0;
  for (; t <= 17.0; t += 0.02) {
    const double travel = 1e-3 * t;
    out << t << "," << travel * 1e3 << ","
        << model.loading(travel - 2e-3, c).total_N() + noise(random) << "\n";
  }
  for (int i = 0; i < 100; ++i, t += 0.02) out << t << ",17," << 3.0 + noise(random) << "\n";
  for (double travel = 17.0; travel > 0.0; travel -= 0.02, t += 0.02)
    out << t << "," << travel << ",-0.5\n";
  return file.string();
}

TEST(CmdTriforce, FitJsonReportsParametersErrorsAndCurveMetrics) {
  const auto file = write_recording();
  const auto run = run_mneedle("fit '" + file + "' --model triforce --json --starts 4 --out '" +
                               (kWork / "fit").string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["model"], "triforce");
  EXPECT_TRUE(j["params"].contains("K0_N"));
  EXPECT_TRUE(j["stderr"].contains("K0_N"));
  EXPECT_FALSE(j["stderr"].contains("mu"));  // fixed by default
  ASSERT_EQ(j["curves"].size(), 1u);
  EXPECT_GT(j["curves"][0]["r2"].get<double>(), 0.99);
  EXPECT_LT(j["curves"][0]["rmse_N"].get<double>(), 0.02);
  EXPECT_NEAR(j["curves"][0]["speed_m_per_s"].get<double>(), 1e-3, 1e-5);
  EXPECT_TRUE(std::filesystem::exists(kWork / "fit" / "fit.json"));
  EXPECT_TRUE(std::filesystem::exists(kWork / "fit" / "recording_fit.csv"));
}

// Each curve writes <name>_fit.csv under --out: two curves of one name from two folders would
// share a file (the second overwrote the first), and a folder under a file cannot be made (it
// ended as internal error 4). Both are refused with one line before the fit runs.
TEST(CmdTriforce, FitRefusesTwoCurvesOfOneNameAndAnOutputFolderUnderAFile) {
  const std::string file = write_recording();
  std::filesystem::create_directories(kWork / "other");
  std::filesystem::copy_file(file, kWork / "other" / "recording.csv",
                             std::filesystem::copy_options::overwrite_existing);
  const CommandRun twice =
      run_mneedle("fit '" + file + "' '" + (kWork / "other" / "recording.csv").string() +
                  "' --out '" + (kWork / "twice").string() + "'");
  EXPECT_EQ(twice.exit_code, 1);
  EXPECT_NE(twice.err.find("would both write recording_fit.csv"), std::string::npos) << twice.err;
  EXPECT_FALSE(std::filesystem::exists(kWork / "twice"));
  const CommandRun under = run_mneedle("fit '" + file + "' --out '" + file + "/x'");
  EXPECT_EQ(under.exit_code, 1);
  EXPECT_NE(under.err.find("--out '" + file + "/x': cannot create the folder"), std::string::npos)
      << under.err;
}

// What gave numbers with exit 0: an angle whose sine is negative (-90 deg predicted -50 N) or
// repeats (200 deg), a params file missing a parameter (the built-in beta tripled the peak), a
// parameter both fixed and free or fixed twice (nothing fitted, or the first value kept).
TEST(CmdTriforce, AnglesOutsideTheQuarterTurnMissingParametersAndFixFreeClashesAreRefused) {
  const std::string file = write_recording();
  const std::filesystem::path dir = kWork / "clash";
  ASSERT_EQ(run_mneedle("fit '" + file + "' --starts 2 --out '" + dir.string() + "'").exit_code, 0);
  const std::string params = (dir / "fit.json").string();
  const auto refused = [](const std::string& arguments, const std::string& message) {
    const CommandRun run = run_mneedle(arguments);
    EXPECT_EQ(run.exit_code, 1) << arguments;
    EXPECT_NE(run.err.find(message), std::string::npos) << run.err;
  };
  refused("predict --params '" + params + "' --depth 5mm --angle -90deg",
          "--angle: -90 deg is outside (0, 90] deg");
  refused("predict --params '" + params + "' --depth 5mm --angle 200deg",
          "--angle: 200 deg is outside (0, 90] deg");
  refused("fit '" + file + "' --angle 0deg", "--angle: 0 deg is outside (0, 90] deg");
  nlohmann::json j;
  std::ifstream(params) >> j;
  j["params"].erase("beta");
  const std::filesystem::path partial = dir / "partial.json";
  std::ofstream(partial) << j.dump();
  refused("predict --params '" + partial.string() + "' --depth 5mm", ": params: missing beta");
  refused("fit '" + file + "' --fix beta=0 --free beta", "--fix beta: also given to --free");
  refused("fit '" + file + "' --fix beta=0 --fix beta=1", "--fix beta: given twice");
  refused("fit '" + file + "' --fix K0_N=2", "--fix K0_N: \"2\" needs a unit");
  // Bounded work (50 detected layers ran over 90 s); 0 starts ran as 1.
  refused("fit '" + file + "' --starts 0", "--starts 0: must be 1 to 1000");
  refused("fit '" + file + "' --detect-layers 50", "--detect-layers 50: must be at most 10");
  std::string starts;
  for (int i = 1; i <= 10; ++i) starts += " --layer-start " + std::to_string(i) + "mm";
  refused("fit '" + file + "'" + starts,
          "--layer-start and --detect-layers: up to 11 layers, at most 10");
  refused("fit '" + file + "' --layer-start 1mm --detect-layers 10",
          "--layer-start and --detect-layers: up to 11 layers, at most 10");
}

// A sample that steps back 5 mm in the middle of the loading branch is merged into the one it
// repeats, as toughness and energy do, and said so: kept, it made the fit's residual 12 times
// larger without a word. The fit then matches the clean curve's to 5 % (one sample of 750).
TEST(CmdTriforce, FitMergesASampleThatStepsBackAndSaysSo) {
  const std::string clean = write_recording();
  std::ifstream in(clean);
  std::string text, line;
  for (int i = 0; std::getline(in, line); ++i) {
    if (i == 500) line = line.substr(0, line.find(',')) + ",5," + line.substr(line.rfind(',') + 1);
    text += line + "\n";
  }
  const auto stepped = kWork / "stepped.csv";
  std::ofstream(stepped) << text;
  const auto sd = [](const CommandRun& run) {
    return nlohmann::json::parse(run.out)["residual_sd_N"].get<double>();
  };
  const CommandRun a = run_mneedle("fit '" + clean + "' --starts 2 --json");
  const CommandRun b = run_mneedle("fit '" + stepped.string() + "' --starts 2 --json");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_NEAR(sd(b) / sd(a), 1.0, 0.05);
  EXPECT_NE(b.out.find("1 samples stepping back"), std::string::npos) << b.out;
}

// A blank group name and a significance level outside [1e-6, 0.5] are refused with one line
// (a group called "" was compared; 1e-300 ended in the range quantile's own error).
TEST(CmdTriforce, StatsRefusesABlankGroupAndAnAlphaOutOfRange) {
  std::filesystem::create_directories(kWork);
  const auto blank = kWork / "blank_group.csv";
  std::ofstream(blank) << "group,value\na,1\n,2\nb,3\nb,4\n";
  const CommandRun run = run_mneedle("stats '" + blank.string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("blank_group.csv:3: column 'group': no group name"), std::string::npos)
      << run.err;
  const auto good = kWork / "two_groups.csv";
  std::ofstream(good) << "group,value\na,1\na,2\nb,3\nb,4.5\n";
  const CommandRun tiny = run_mneedle("stats '" + good.string() + "' --alpha 1e-300");
  EXPECT_EQ(tiny.exit_code, 1);
  EXPECT_NE(tiny.err.find("--alpha 1e-300: must be in [1e-6, 0.5]"), std::string::npos) << tiny.err;
}

// --compare scores the prediction that is printed: with --depth, the measured samples that deep
// only (it compared the whole curve whatever --depth said).
TEST(CmdTriforce, PredictCompareKeepsToTheDepthAskedForAndTheSampleLimitCountsTheRows) {
  const std::string file = write_recording();
  const std::filesystem::path dir = kWork / "compare_depth";
  ASSERT_EQ(run_mneedle("fit '" + file + "' --starts 2 --out '" + dir.string() + "'").exit_code, 0);
  const auto samples = [&](const std::string& depth) {
    const CommandRun run = run_mneedle("predict --params '" + (dir / "fit.json").string() +
                                       "' --compare '" + file + "'" + depth + " --json");
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return nlohmann::json::parse(run.out)["comparison"]["samples"].get<std::size_t>();
  };
  const std::size_t all = samples(""), shallow = samples(" --depth 5mm");
  // The loading branch runs about 15 mm below contact in 20 um samples: 5 mm of it is a third.
  EXPECT_LT(shallow, all / 2);
  EXPECT_GT(shallow, 200u);
  // The sample limit counts what is written: 86 mm in and out at 1 mm/s in 0.05 s steps is
  // 3 440 steps and the three phases' closing samples (3 440 passed, and 3 443 rows came).
  const std::string params = "predict --params '" + (dir / "fit.json").string() +
                             "' --depth 86mm --speed 1mm/s --csv --max-samples ";
  const CommandRun exact = run_mneedle(params + "3443");
  ASSERT_EQ(exact.exit_code, 0) << exact.err;
  std::istringstream rows(exact.out);
  int count = 0;
  for (std::string line; std::getline(rows, line);) count += std::isdigit(line[0]) ? 1 : 0;
  EXPECT_EQ(count, 3443);
  EXPECT_EQ(run_mneedle(params + "3442").exit_code, 1);
}

TEST(CmdTriforce, PredictGoesInHoldsAndComesOut) {
  const auto file = write_recording();
  ASSERT_EQ(
      run_mneedle("fit '" + file + "' --starts 2 --out '" + (kWork / "p").string() + "'").exit_code,
      0);
  const auto run =
      run_mneedle("predict --model triforce --params '" + (kWork / "p" / "fit.json").string() +
                  "' --speed 2mm/s --angle 90deg --depth 10mm --hold 1s --step 0.1s --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const auto& phase = j["phase"];
  EXPECT_EQ(phase.front(), "insertion");
  EXPECT_EQ(phase.back(), "retraction");
  EXPECT_NEAR(j["depth_m"].back().get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(j["time_s"].back().get<double>(), 5.0 + 1.0 + 5.0, 1e-6);
  EXPECT_LT(j["force_N"].back().get<double>(), 1e-12);  // friction reversed or zero on the way out
}

TEST(CmdTriforce, StatsPrintsAnovaAndTukey) {
  const auto run = run_mneedle("stats '" + std::string(MNEEDLE_TEST_ASSETS) +
                               "/curves/grouped.csv' --value force_N --group group --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["anova"]["df_between"], 1);
  EXPECT_EQ(j["anova"]["df_within"], 4);
  ASSERT_EQ(j["tukey_hsd"].size(), 1u);
  EXPECT_NEAR(j["tukey_hsd"][0]["meandiff"].get<double>(), 5.0666667 - 5.4666667, 1e-6);
}

TEST(CmdTriforce, FitOnTravelThatDecreasesNamesTheColumnNotTheForce) {
  // A loading written deepest row first: travel 6 -> 0.1 mm. Read forwards the force only falls,
  // which used to be reported as "the force never rises above the noise".
  std::filesystem::create_directories(kWork);
  const auto file = kWork / "reversed.csv";
  {
    std::ofstream out(file);
    out << "time_s,travel_mm,fz_N\n";
    for (int i = 0; i < 60; ++i) {
      const double travel = 6.0 - 0.1 * i;
      out << 0.1 * i << "," << travel << "," << 0.15 * travel * travel << "\n";
    }
  }
  const auto run = run_mneedle("fit '" + file.string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("reversed.csv:3: column 'travel_mm' decreases from its first sample"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("noise"), std::string::npos) << run.err;
}

TEST(CmdTriforce, StatsRefusesMoreGroupsThanMaxGroupsBeforeComparingThem) {
  std::filesystem::create_directories(kWork);
  const auto file = kWork / "five_groups.csv";
  {
    std::ofstream out(file);
    out << "group,value\n";
    for (int g = 0; g < 5; ++g) out << "g" << g << "," << g << ".1\ng" << g << "," << g << ".3\n";
  }
  const auto refused = run_mneedle("stats '" + file.string() + "' --max-groups 4");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("five_groups.csv: 5 groups in column 'group', more than "
                             "--max-groups 4 (10 Tukey pairs)"),
            std::string::npos)
      << refused.err;
  EXPECT_TRUE(refused.out.empty()) << refused.out;
  const auto allowed = run_mneedle("stats '" + file.string() + "' --max-groups 5 --json");
  ASSERT_EQ(allowed.exit_code, 0) << allowed.err;
  EXPECT_EQ(nlohmann::json::parse(allowed.out)["tukey_hsd"].size(), 10u);
}

TEST(CmdTriforce, BadCurveFailsWithFileAndLine) {
  const auto run =
      run_mneedle("fit '" + std::string(MNEEDLE_TEST_ASSETS) + "/curves/text_in_number.csv'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("text_in_number.csv:4"), std::string::npos) << run.err;
}

TEST(CmdTriforce, FitAndPredictPlotTheirCurves) {
  const auto file = write_recording();
  const auto fit_svg = kWork / "fit.svg", predict_svg = kWork / "predict.svg";
  ASSERT_EQ(run_mneedle("fit '" + file + "' --starts 2 --out '" + (kWork / "q").string() +
                        "' --plot '" + fit_svg.string() + "'")
                .exit_code,
            0);
  ASSERT_EQ(run_mneedle("predict --params '" + (kWork / "q" / "fit.json").string() +
                        "' --compare '" + file + "' --plot '" + predict_svg.string() + "'")
                .exit_code,
            0);
  const auto fit = mneedle::test::texts(mneedle::test::read_svg(fit_svg));
  EXPECT_TRUE(mneedle::test::has_text(fit, "recording.csv measured"));
  EXPECT_TRUE(mneedle::test::has_text(fit, "recording.csv fitted"));
  const auto predict = mneedle::test::texts(mneedle::test::read_svg(predict_svg));
  EXPECT_TRUE(mneedle::test::has_text(predict, "predicted"));
  EXPECT_TRUE(mneedle::test::has_text(predict, "recording.csv measured"));
}

}  // namespace
