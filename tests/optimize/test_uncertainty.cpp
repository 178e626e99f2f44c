// Uncertainty from scene values drawn from distributions: the distributions, the --vary syntax,
// editing a scene, percentiles, a known answer, reproducibility and failed samples.
#include "mneedle/uncertainty.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "mneedle/base/error.h"
#include "mneedle/scene/scene.h"
#include "mneedle/screening_mpi.h"

namespace {

namespace fs = std::filesystem;
using mneedle::DistributionKind;
const std::string kRoot = MNEEDLE_SOURCE_ROOT;
constexpr double kZ95 = 1.6448536269514722;  // standard normal 95 % quantile

std::string file_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

double layer_E(const mneedle::Scene& scene, std::size_t layer) {
  return scene.tissue.layers.at(layer).material.youngs_modulus;
}

TEST(Distribution, QuantilesMatchTheirClosedForms) {
  // boost::math's inverse CDFs are accurate to a few ulps: 1e-12 is far above that and far
  // below any error that would matter.
  const mneedle::Distribution normal{DistributionKind::Normal, 10.0, 2.0};
  EXPECT_NEAR(mneedle::distribution_quantile(normal, 0.5), 10.0, 1e-12);
  EXPECT_NEAR(mneedle::distribution_quantile(normal, 0.95), 10.0 + 2.0 * kZ95, 1e-11);
  const double sigma = std::sqrt(std::log1p(0.09));
  const mneedle::Distribution lognormal{DistributionKind::LogNormal, 80e3, sigma};
  EXPECT_NEAR(mneedle::distribution_quantile(lognormal, 0.5), 80e3, 1e-7);
  EXPECT_NEAR(mneedle::distribution_quantile(lognormal, 0.95), 80e3 * std::exp(sigma * kZ95), 1e-7);
  const mneedle::Distribution uniform{DistributionKind::Uniform, 10e-6, 30e-6};
  EXPECT_NEAR(mneedle::distribution_quantile(uniform, 0.05), 11e-6, 1e-18);
}

TEST(VariedValue, ParsesEveryDistributionWithUnitsAndPercentages) {
  const auto e = mneedle::parse_varied_value("dermis.E=lognormal(80kPa,30%)");
  EXPECT_EQ(e.path, "dermis.E");
  EXPECT_EQ(e.distribution.kind, DistributionKind::LogNormal);
  EXPECT_DOUBLE_EQ(e.distribution.a, 80e3);
  EXPECT_DOUBLE_EQ(e.distribution.b, std::sqrt(std::log1p(0.09)));
  EXPECT_EQ(e.distribution.dimension, mneedle::Dimension::Pressure);
  const auto t = mneedle::parse_varied_value(" stratum_corneum.thickness = uniform(10um, 30 um) ");
  EXPECT_EQ(t.path, "stratum_corneum.thickness");
  EXPECT_DOUBLE_EQ(t.distribution.a, 10e-6);
  EXPECT_DOUBLE_EQ(t.distribution.b, 30e-6);
  const auto n = mneedle::parse_varied_value("needle.diameter=normal(230um,10%)");
  EXPECT_DOUBLE_EQ(n.distribution.b, 23e-6);
  const auto nu = mneedle::parse_varied_value("dermis.nu=normal(0.45,0.02)");
  EXPECT_EQ(nu.distribution.dimension, mneedle::Dimension::Dimensionless);
  EXPECT_DOUBLE_EQ(nu.distribution.b, 0.02);
}

TEST(VariedValue, BadSpecIsOneErrorNamingItAndTheProblem) {
  const std::pair<const char*, const char*> cases[] = {
      {"dermis.E", "PATH=DISTRIBUTION"},
      {"E=uniform(1kPa,2kPa)", "layer and a key"},
      {"dermis.E=gamma(1kPa,2kPa)", "unknown distribution"},
      {"dermis.E=uniform(2kPa,1kPa)", "LOW < HIGH"},
      {"dermis.E=lognormal(80kPa,5kPa)", "percentage"},
      {"dermis.E=uniform(10um,3kPa)", "dermis.E"},
      {"dermis.E=normal(80kPa,0%)", "> 0"},
      {"dermis.E=normal(80kPa)", "two values"},
      {"dermis.E=uniform(80,90kPa)", "dermis.E"}};
  for (const auto& [spec, expected] : cases) {
    try {
      mneedle::parse_varied_value(spec);
      ADD_FAILURE() << spec << ": expected an InputError";
    } catch (const mneedle::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(spec), std::string::npos) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(SceneWithValues, SetsLayerMaterialFractureNeedleAndDottedPathValues) {
  const fs::path file = kRoot + "/designs/scenes/human_skin.toml";
  const std::string text = file_text(file);
  const auto v = [](const char* spec) { return mneedle::parse_varied_value(spec); };
  const std::string edited =
      mneedle::scene_with_values(text, file.string(),
                                 {{v("dermis.E=uniform(1kPa,2kPa)"), 123456.789},
                                  {v("stratum_corneum.thickness=uniform(1um,2um)"), 17.5e-6},
                                  {v("fracture.critical_pressure=uniform(1MPa,2MPa)"), 2.5e6},
                                  {v("needle.diameter=uniform(1um,2um)"), 250e-6},
                                  {v("requirements.target_depth=uniform(1um,2um)"), 4e-4}});
  const mneedle::Scene scene = mneedle::parse_scene(edited, file.string());
  EXPECT_EQ(layer_E(scene, 2), 123456.789);  // exactly: written with 17 significant digits
  EXPECT_DOUBLE_EQ(scene.tissue.layers[0].thickness, 17.5e-6);
  EXPECT_DOUBLE_EQ(scene.tissue.fracture->critical_pressure, 2.5e6);
  EXPECT_DOUBLE_EQ(*scene.requirements.target_depth, 4e-4);
  const auto& geometry = std::get<mneedle::PluginGeometry>(scene.needles[0].geometry);
  EXPECT_EQ(geometry.parameters.at("diameter").value_si, 250e-6);
  // and nothing else moved
  const mneedle::Scene original = mneedle::parse_scene(text, file.string());
  EXPECT_DOUBLE_EQ(layer_E(scene, 1), layer_E(original, 1));
}

TEST(SceneWithValues, UnknownPathOrWrongDimensionIsAnErrorNamingThePath) {
  const fs::path file = kRoot + "/designs/scenes/human_skin.toml";
  const std::string text = file_text(file);
  const std::pair<const char*, const char*> cases[] = {
      {"dermis.Young=uniform(1kPa,2kPa)", "no such value"},
      {"hypodermis.E=uniform(1kPa,2kPa)", "no such value"},
      {"dermis.E=uniform(1um,2um)", "pressure"},
      {"dermis.nu=uniform(1kPa,2kPa)", "plain number"},
      {"dermis.model=uniform(1kPa,2kPa)", "not a number or a quantity"}};
  for (const auto& [spec, expected] : cases) {
    try {
      mneedle::scene_with_values(text, file.string(), {{mneedle::parse_varied_value(spec), 1.0}});
      ADD_FAILURE() << spec << ": expected an InputError";
    } catch (const mneedle::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file.string()), std::string::npos) << what;
      EXPECT_NE(what.find(mneedle::parse_varied_value(spec).path), std::string::npos) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
    }
  }
}

TEST(SceneWithValues, TheSameValueVariedTwiceIsAnError) {
  const fs::path file = kRoot + "/designs/scenes/human_skin.toml";
  const auto a = mneedle::parse_varied_value("fracture.toughness=uniform(1J/m^2,2J/m^2)");
  const auto b = mneedle::parse_varied_value("tissue.fracture.toughness=uniform(1J/m^2,2J/m^2)");
  try {
    mneedle::scene_with_values(file_text(file), file.string(), {{a, 1.5}, {b, 1.5}});
    FAIL() << "expected an InputError";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("varied twice"), std::string::npos) << e.what();
  }
}

TEST(Percentiles, InterpolateBetweenOrderStatisticsAsNumpysDefault) {
  // numpy.percentile([5, 1, 4, 2, 3], [5, 50, 95]) = [1.2, 3, 4.8]
  const auto p = mneedle::percentiles({5, 1, 4, 2, 3});
  EXPECT_EQ(p.count, 5u);
  EXPECT_DOUBLE_EQ(p.p5, 1.2);
  EXPECT_DOUBLE_EQ(p.p50, 3.0);
  EXPECT_DOUBLE_EQ(p.p95, 4.8);
  EXPECT_EQ(mneedle::percentiles({}).count, 0u);
}

class Uncertainty : public ::testing::Test {
 protected:
  // Paper A's silicone with its hollow cylinder, target 1 mm: with the closed-form (linear)
  // indentation of a flat-ended needle, F = k d and the pressure F / A_sec reaches P_c at
  // d = P_c A_sec / k: the puncture depth is linear in the critical pressure.
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mneedle_uncertainty_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    const fs::path shipped = kRoot + "/designs/scenes/paper_a_silicone_cylinder.toml";
    scene_ = dir_ / "cylinder.toml";
    std::ofstream(scene_) << mneedle::scene_with_values(
        file_text(shipped), shipped.string(),
        {{mneedle::parse_varied_value("requirements.target_depth=uniform(1um,2um)"), 1e-3}});
    registry_ = mneedle::PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
    options_.model = "analytic";
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_, scene_;
  mneedle::PluginRegistry registry_;
  mneedle::UncertaintyOptions options_;
};

TEST_F(Uncertainty, PunctureDepthLinearInAnInputHasThePercentilesOfThatInput) {
  const auto pc = mneedle::parse_varied_value("fracture.critical_pressure=uniform(0.5MPa,0.8MPa)");
  options_.samples = 24;
  options_.latin_hypercube = true;
  const auto r = mneedle::run_uncertainty(scene_, {pc}, registry_, options_);
  ASSERT_EQ(r.samples.size(), 24u);
  ASSERT_TRUE(r.nominal.puncture_depth_m.has_value());
  // c = d / P_c from the scene as written (0.663 MPa). The crossing is bisected to 1e-6 of a
  // depth step, about 1e-7 of the depth: 1e-6 relative is that with a margin, and far below
  // the spread tested (0.5 to 0.8 MPa).
  const double c = *r.nominal.puncture_depth_m / 0.663e6;
  std::vector<double> inputs;
  for (const auto& s : r.samples) {
    ASSERT_TRUE(s.ok) << s.error;
    ASSERT_TRUE(s.puncture_depth_m.has_value());
    EXPECT_NEAR(*s.puncture_depth_m / (c * s.values[0]), 1.0, 1e-6);
    inputs.push_back(s.values[0]);
  }
  const auto in = mneedle::percentiles(inputs);
  EXPECT_NEAR(r.puncture_depth_m.p5 / (c * in.p5), 1.0, 1e-6);
  EXPECT_NEAR(r.puncture_depth_m.p50 / (c * in.p50), 1.0, 1e-6);
  EXPECT_NEAR(r.puncture_depth_m.p95 / (c * in.p95), 1.0, 1e-6);
  // Latin hypercube: one draw per stratum of width (b - a) / N, so each sample percentile lies
  // within one stratum of the distribution's: 0.3 MPa / 24.
  const double stratum = 0.3e6 / 24.0;
  EXPECT_NEAR(in.p5, 0.515e6, stratum);
  EXPECT_NEAR(in.p50, 0.65e6, stratum);
  EXPECT_NEAR(in.p95, 0.785e6, stratum);
  EXPECT_DOUBLE_EQ(r.punctured_fraction, 1.0);
  // One at a time: the depth moves by c (q95 - q5) = c 0.27 MPa.
  ASSERT_EQ(r.sensitivity.size(), 1u);
  ASSERT_TRUE(r.sensitivity[0].depth_effect_m.has_value());
  EXPECT_TRUE(r.sensitivity[0].both_resolved);
  EXPECT_NEAR(*r.sensitivity[0].depth_effect_m / (c * 0.27e6), 1.0, 1e-6);
}

TEST_F(Uncertainty, LatinHypercubePutsOneSampleInEveryStratumOfEveryInputIndependently) {
  // Two inputs: each must fill its N strata once, and their strata must not be paired in the
  // same order (an identity shuffle would correlate the inputs perfectly).
  const auto pc = mneedle::parse_varied_value("fracture.critical_pressure=uniform(0.5MPa,0.8MPa)");
  const auto e = mneedle::parse_varied_value("silicone.E=uniform(0.15MPa,0.25MPa)");
  options_.samples = 16;
  options_.latin_hypercube = true;
  options_.sensitivity = false;
  const auto r = mneedle::run_uncertainty(scene_, {pc, e}, registry_, options_);
  std::vector<int> first(16, 0), second(16, 0);
  std::vector<std::size_t> stratum_a, stratum_b;
  for (const auto& s : r.samples) {
    const auto a = static_cast<std::size_t>((s.values[0] - 0.5e6) / 0.3e6 * 16);
    const auto b = static_cast<std::size_t>((s.values[1] - 0.15e6) / 0.1e6 * 16);
    ASSERT_LT(a, 16u);
    ASSERT_LT(b, 16u);
    ++first[a];
    ++second[b];
    stratum_a.push_back(a);
    stratum_b.push_back(b);
  }
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(first[i], 1) << i;
    EXPECT_EQ(second[i], 1) << i;
  }
  EXPECT_NE(stratum_a, stratum_b);
}

TEST_F(Uncertainty, ASceneThatCannotRunAsWrittenFailsBeforeAnySample) {
  // A target depth beyond the needle's length: evaluate_design refuses it (an InputError).
  const fs::path deep = dir_ / "deep.toml";
  std::ofstream(deep) << mneedle::scene_with_values(
      file_text(scene_), scene_.string(),
      {{mneedle::parse_varied_value("requirements.target_depth=uniform(1um,2um)"), 5e-3}});
  const auto pc = mneedle::parse_varied_value("fracture.critical_pressure=uniform(0.5MPa,0.8MPa)");
  int runs = 0;
  EXPECT_THROW(mneedle::run_uncertainty(deep, {pc}, registry_, options_, [&](int, int) { ++runs; }),
               mneedle::InputError);
  EXPECT_EQ(runs, 0);
}

TEST_F(Uncertainty, SameSeedGivesTheSameSamplesBitForBitWhateverTheJobs) {
  const auto pc = mneedle::parse_varied_value("fracture.critical_pressure=lognormal(0.663MPa,20%)");
  const auto e = mneedle::parse_varied_value("silicone.E=uniform(0.15MPa,0.25MPa)");
  options_.samples = 6;
  options_.seed = 7;
  options_.sensitivity = false;
  const auto one = mneedle::run_uncertainty(scene_, {pc, e}, registry_, options_);
  options_.jobs = 2;
  const auto two = mneedle::run_uncertainty(scene_, {pc, e}, registry_, options_);
  ASSERT_EQ(one.samples.size(), two.samples.size());
  for (std::size_t i = 0; i < one.samples.size(); ++i) {
    EXPECT_EQ(one.samples[i].values, two.samples[i].values) << i;
    EXPECT_EQ(one.samples[i].puncture_depth_m, two.samples[i].puncture_depth_m) << i;
    EXPECT_EQ(one.samples[i].peak_force_n, two.samples[i].peak_force_n) << i;
  }
  options_.seed = 8;
  const auto other = mneedle::run_uncertainty(scene_, {pc, e}, registry_, options_);
  EXPECT_NE(other.samples[0].values, one.samples[0].values);
}

TEST_F(Uncertainty, OneMpiRankGivesTheThreadedResultBitForBit) {
  // A singleton MPI job (no launcher): rank 0 deals every run to its own threads, through the
  // same dealer as N ranks; two ranks run end to end in tests/cli/test_cmd_uncertainty.cpp.
  if (!mneedle::mpi_built_in()) GTEST_SKIP() << "built without MPI (MNEEDLE_MPI=OFF)";
  const auto pc = mneedle::parse_varied_value("fracture.critical_pressure=lognormal(0.663MPa,20%)");
  options_.samples = 5;
  options_.jobs = 2;
  const auto threads = mneedle::run_uncertainty(scene_, {pc}, registry_, options_);
  mneedle::MpiSession session(options_.jobs);
  int calls = 0;
  const auto mpi = mneedle::run_uncertainty_mpi(session, scene_, {pc}, registry_, options_,
                                                [&](int, int) { ++calls; });
  ASSERT_TRUE(mpi.has_value());
  EXPECT_EQ(calls, 5 + 2);  // every sample and both sensitivity ends, reported on rank 0
  ASSERT_EQ(mpi->samples.size(), threads.samples.size());
  for (std::size_t i = 0; i < threads.samples.size(); ++i) {
    EXPECT_EQ(mpi->samples[i].values, threads.samples[i].values) << i;
    EXPECT_EQ(mpi->samples[i].puncture_depth_m, threads.samples[i].puncture_depth_m) << i;
    EXPECT_EQ(mpi->samples[i].margin, threads.samples[i].margin) << i;
  }
  EXPECT_EQ(mpi->puncture_depth_m.p50, threads.puncture_depth_m.p50);
  ASSERT_EQ(mpi->sensitivity.size(), 1u);
  EXPECT_EQ(mpi->sensitivity[0].depth_effect_m, threads.sensitivity[0].depth_effect_m);
}

TEST_F(Uncertainty, ASampleThatCannotRunIsAnErrorRowAndTheOthersGoOn) {
  // A normal wide enough to draw negative critical pressures, which the scene refuses.
  const auto pc = mneedle::parse_varied_value("fracture.critical_pressure=normal(0.663MPa,100%)");
  options_.samples = 20;
  const auto r = mneedle::run_uncertainty(scene_, {pc}, registry_, options_);
  EXPECT_GT(r.failed, 0u);
  EXPECT_LT(r.failed, 20u);
  std::size_t ran = 0;
  for (const auto& s : r.samples) {
    if (!s.ok) {
      EXPECT_LE(s.values[0], 0.0);
      EXPECT_NE(s.error.find("critical_pressure"), std::string::npos) << s.error;
    } else {
      EXPECT_GT(s.values[0], 0.0);
      ++ran;
    }
  }
  EXPECT_EQ(ran + r.failed, 20u);
  EXPECT_EQ(r.peak_force_n.count, ran);  // the spread is over the samples that ran
  // Its 5 % quantile is negative: that end fails, so there is no effect to rank.
  ASSERT_EQ(r.sensitivity.size(), 1u);
  EXPECT_FALSE(r.sensitivity[0].low.ok);
  EXPECT_FALSE(r.sensitivity[0].depth_effect_m.has_value());
}

TEST_F(Uncertainty, MisspeltPathFailsBeforeAnyRun) {
  const auto bad = mneedle::parse_varied_value("silicone.Young=uniform(0.1MPa,0.2MPa)");
  int runs = 0;
  EXPECT_THROW(
      mneedle::run_uncertainty(scene_, {bad}, registry_, options_, [&](int, int) { ++runs; }),
      mneedle::InputError);
  EXPECT_EQ(runs, 0);
}

}  // namespace
