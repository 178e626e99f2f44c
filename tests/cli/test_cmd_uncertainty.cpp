// `mneedle uncertainty` end to end: the JSON a notebook reads, the table, and bad --vary values.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "../plot/svg_reader.h"
#include "run_mneedle.h"

namespace {

using mneedle::test::run_mneedle;
const std::string kRoot = MNEEDLE_SOURCE_ROOT;
const std::string kSilicone = kRoot + "/designs/scenes/paper_a_silicone_blunt_bevel.toml";
// A flat punch on the axisymmetric FE model, puncturing within its insertion at fast fidelity.
const std::string kPunch = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/puncture_punch.toml";

TEST(UncertaintyCommand, JsonGivesInputsSummarySensitivityAndEverySample) {
  const auto run = run_mneedle("uncertainty '" + kSilicone +
                               "' --vary 'silicone.E=lognormal(0.2MPa,20%)' "
                               "--vary 'fracture.critical_pressure=uniform(0.5MPa,0.8MPa)' "
                               "--samples 8 --seed 3 --model analytic --jobs 2 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["samples"], 8);
  EXPECT_EQ(j["seed"], 3);
  ASSERT_EQ(j["inputs"].size(), 2u);
  EXPECT_EQ(j["inputs"][0]["path"], "silicone.E");
  EXPECT_EQ(j["inputs"][0]["unit"], "Pa");
  EXPECT_DOUBLE_EQ(j["inputs"][1]["p5_si"].get<double>(), 0.515e6);
  ASSERT_EQ(j["rows"].size(), 8u);
  for (const auto& row : j["rows"]) {
    EXPECT_TRUE(row["ok"].get<bool>()) << row.dump();
    EXPECT_TRUE(row["values_si"].contains("silicone.E"));
  }
  for (const char* key : {"puncture_depth_m", "puncture_force_N", "peak_force_N", "margin"}) {
    const auto& p = j["summary"][key];
    ASSERT_TRUE(p.contains("count")) << key;
    if (p["count"].get<int>() == 0) continue;  // e.g. no resolved puncture: nulls
    EXPECT_LE(p["p5"].get<double>(), p["p50"].get<double>()) << key;
    EXPECT_LE(p["p50"].get<double>(), p["p95"].get<double>()) << key;
  }
  EXPECT_EQ(j["summary"]["peak_force_N"]["count"], 8);
  const double pass = j["summary"]["pass_probability"].get<double>();
  EXPECT_GE(pass, 0.0);
  EXPECT_LE(pass, 1.0);
  EXPECT_TRUE(j["summary"].contains("pass_probability_standard_error"));
  ASSERT_EQ(j["sensitivity"].size(), 2u);
  EXPECT_GE(j["sensitivity"][0]["depth_effect_m"].get<double>(),
            j["sensitivity"][1]["depth_effect_m"].get<double>());
  EXPECT_TRUE(j.contains("provenance"));
  // The same seed again: the same rows.
  const auto again = run_mneedle("uncertainty '" + kSilicone +
                                 "' --vary 'silicone.E=lognormal(0.2MPa,20%)' "
                                 "--vary 'fracture.critical_pressure=uniform(0.5MPa,0.8MPa)' "
                                 "--samples 8 --seed 3 --model analytic --json");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out)["rows"], j["rows"]);
}

// P(pass) with its binomial standard error over the samples that ran (docs/model.md, "Uncertainty
// from tissue variability"), on a share strictly between 0 and 1: paper A's silicone cylinder on
// the closed form punctures at a depth linear in P_c (440 um at 0.663 MPa), before the 300 um
// target for P_c below about 0.45 MPa.
TEST(UncertaintyCommand, PassProbabilityComesWithItsBinomialStandardError) {
  const auto run = run_mneedle("uncertainty '" + kRoot +
                               "/designs/scenes/paper_a_silicone_cylinder.toml' --vary "
                               "'fracture.critical_pressure=uniform(0.3MPa,0.6MPa)' --samples 20 "
                               "--seed 1 --model analytic --no-sensitivity --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const auto& s = j["summary"];
  const double p = s["pass_probability"].get<double>();
  EXPECT_GT(p, 0.0);
  EXPECT_LT(p, 1.0);
  EXPECT_DOUBLE_EQ(s["pass_probability_standard_error"].get<double>(),
                   std::sqrt(p * (1.0 - p) / 20.0));
}

TEST(UncertaintyCommand, TableGivesPercentilesProbabilityAndRanking) {
  const auto run = run_mneedle("uncertainty '" + kSilicone +
                               "' --vary 'fracture.critical_pressure=uniform(0.5MPa,0.8MPa)' "
                               "--samples 5 --model analytic");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  for (const char* text : {"puncture depth", "median", "95 %", "passes:", "one at a time",
                           "fracture.critical_pressure"})
    EXPECT_NE(run.out.find(text), std::string::npos) << text << "\n" << run.out;
}

TEST(UncertaintyCommand, AnInputThatCannotMoveThePeakForceHasNoEffectOnItNotItsRoundOff) {
  // In skin the force after the puncture continues the intact curve (docs/model.md, "The broken
  // top layer"), so the layer's strength moves the puncture but not the force at the target
  // depth; the two ends' peaks differ only in round-off (3e-12 relative before the rule), which
  // the table printed as "peak force 6.69464e-08 uN".
  const auto run = run_mneedle("uncertainty '" + kRoot +
                               "/designs/scenes/paper_a_skin_cylinder.toml' --vary "
                               "'stratum_corneum.strength=uniform(15MPa,28MPa)' --samples 2 "
                               "--seed 1 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["sensitivity"].size(), 1u);
  const auto& s = j["sensitivity"][0];
  EXPECT_GT(s["depth_effect_m"].get<double>(), 10e-6);  // 80.6 um at fast
  EXPECT_EQ(s["peak_effect_N"].get<double>(), 0.0);
  const double low = s["low"]["peak_force_N"].get<double>();
  EXPECT_NEAR(s["high"]["peak_force_N"].get<double>(), low, 1e-9 * low);
}

TEST(UncertaintyCommand, BadVaryIsOneLineNamingItAndExitOne) {
  for (const std::string vary : {"silicone.E=uniform(2MPa,1MPa)", "silicone.E=beta(1,2)",
                                 "silicone.Young=uniform(1MPa,2MPa)", "silicone.E=uniform(1,2)"}) {
    const auto run = run_mneedle("uncertainty '" + kSilicone + "' --vary '" + vary +
                                 "' --samples 3 --model analytic");
    EXPECT_EQ(run.exit_code, 1) << vary << ": " << run.err;
    EXPECT_NE(run.err.find("silicone."), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find('\n'), run.err.size() - 1) << "one line: " << run.err;
  }
}

TEST(UncertaintyCommand, PlotDrawsTheDistributionWithItsPercentiles) {
  const auto svg = std::filesystem::temp_directory_path() / "mneedle_uncertainty_plot.svg";
  std::filesystem::remove(svg);
  const auto run = run_mneedle("uncertainty '" + kPunch +
                               "' --vary 'silicone.E=lognormal(0.2MPa,20%)' --samples 6 "
                               "--no-sensitivity --plot '" +
                               svg.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto t = mneedle::test::texts(mneedle::test::read_svg(svg));
  for (const char* label :
       {"5 %", "median", "95 %", "share of samples at or below [%]", "puncture depth [um]"})
    EXPECT_TRUE(mneedle::test::has_text(t, label)) << label;
  bool titled = false;  // the title says how many samples the distribution has
  for (const auto& x : t)
    titled = titled || x.text.find("6 samples with a resolved") != std::string::npos;
  EXPECT_TRUE(titled);
}

#ifdef MNEEDLE_MPIEXEC
using mneedle::test::mpirun;
using mneedle::test::run_command;
using mneedle::test::shell_words;

// What a run's result is, without the provenance (its time and command line differ).
nlohmann::json result_of(const std::string& json_text) {
  auto j = nlohmann::json::parse(json_text);
  j.erase("provenance");
  return j;
}

TEST(UncertaintyCommand, TwoMpiRanksGiveTheSerialResultBitForBit) {
  // The axisymmetric FE model, Monte Carlo and Latin hypercube; the serial run with two jobs
  // holds OpenBLAS at one thread per run, as every rank of the MPI job does.
  for (const char* method : {"mc", "lhs"}) {
    const std::vector<std::string> arguments{
        "uncertainty", kPunch, "--vary", "silicone.E=lognormal(0.2MPa,20%)",
        "--samples",   "6",    "--seed", "7",
        "--method",    method, "--json"};
    std::string serial_line = "'" + mneedle::test::mneedle_binary() + "'";
    for (const auto& w : arguments) serial_line += " '" + w + "'";
    const auto serial = run_command(serial_line + " --jobs 2");
    ASSERT_EQ(serial.exit_code, 0) << serial.err;
    for (const char* jobs : {"1", "2"}) {
      auto words = mpirun(2, arguments);
      words.insert(words.end() - 1, {"--jobs", jobs});
      const auto mpi = run_command(shell_words(words));
      ASSERT_EQ(mpi.exit_code, 0) << mpi.err;
      EXPECT_EQ(result_of(mpi.out), result_of(serial.out)) << method << ", --jobs " << jobs;
    }
  }
}

TEST(UncertaintyCommand, MpiFailureBeforeTheSamplesIsOneLineFromRankZero) {
  const auto run =
      run_command(shell_words(mpirun(2, {"uncertainty", kPunch, "--vary",
                                         "silicone.Young=uniform(1MPa,2MPa)", "--samples", "3"})));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("mneedle: error: "), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("mneedle: error: "), run.err.rfind("mneedle: error: ")) << run.err;
  EXPECT_NE(run.err.find("silicone.Young"), std::string::npos) << run.err;
}

TEST(UncertaintyCommand, MpiMissingSceneIsOneLineAndEveryRankStops) {
  // Rank 0 records its inputs' hashes; a scene it cannot read must stop every rank, not leave
  // the others waiting for it (the launcher's timeout would fail this test after 300 s).
  const auto run =
      run_command(shell_words(mpirun(2, {"uncertainty", "/nonexistent/scene.toml", "--vary",
                                         "silicone.E=uniform(1MPa,2MPa)", "--samples", "2"})));
  EXPECT_NE(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("/nonexistent/scene.toml"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("mneedle: error: "), run.err.rfind("mneedle: error: ")) << run.err;
}

TEST(UncertaintyCommand, StartedByMpirunWithoutMpiRefusesOnce) {
  auto words = mpirun(
      2, {"uncertainty", kPunch, "--vary", "silicone.E=uniform(0.1MPa,0.3MPa)", "--samples", "2"});
  words.pop_back();  // no --mpi
  const auto run = run_command(shell_words(words));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("without --mpi"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("mneedle: error: "), run.err.rfind("mneedle: error: ")) << run.err;
}
#endif

}  // namespace
