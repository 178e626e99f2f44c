// Provenance of every output (docs/cli.md, "Provenance"): the record itself, and end to end —
// the same inputs under SOURCE_DATE_EPOCH give the same bytes, every input's digest is the one
// `sha256sum` gives, CSV carries it as its first line, output folders keep one line per run.
#include "run_provenance.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"
#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::run_mneedle;
using Json = nlohmann::json;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;
const std::string kScene = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/stl_needle.toml";
const std::string kNeedle = std::string(MNEEDLE_TEST_ASSETS) + "/scenes/tiny_needle.stl";

class Provenance : public ::testing::Test {
 protected:
  void SetUp() override {
    mneedle::cli::run_provenance() = mneedle::start_provenance("mneedle test");
  }
  void TearDown() override { ::unsetenv("SOURCE_DATE_EPOCH"); }
};

TEST_F(Provenance, RecordedFilesCarryTheirRoleNameAndDigest) {
  mneedle::cli::record_input("curve", kNeedle);
  const Json j = Json::parse(mneedle::cli::provenance_json().dump());
  EXPECT_EQ(j["tool"], "mneedle");
  EXPECT_EQ(j["version"], mneedle::tool_version());
  EXPECT_EQ(j["command"], "mneedle test");
  EXPECT_TRUE(j["seed"].is_null());
  ASSERT_EQ(j["inputs"].size(), 1u);
  EXPECT_EQ(j["inputs"][0]["role"], "curve");
  EXPECT_EQ(j["inputs"][0]["name"], kNeedle);
  EXPECT_EQ(j["inputs"][0]["sha256"], mneedle::sha256_of_file(kNeedle));
}

TEST_F(Provenance, CommentIsOneLineOfJson) {
  mneedle::cli::run_provenance().seed = 7;
  const std::string line = mneedle::cli::provenance_comment();
  ASSERT_EQ(line.rfind("# provenance: {", 0), 0u) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_EQ(Json::parse(line.substr(14))["seed"], 7);
}

TEST_F(Provenance, FolderKeepsOneLinePerRun) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_prov_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  mneedle::cli::append_provenance_line(dir);
  mneedle::cli::append_provenance_line(dir);
  std::ifstream in(dir / "provenance.jsonl");
  int lines = 0;
  for (std::string line; std::getline(in, line); ++lines)
    EXPECT_EQ(Json::parse(line)["tool"], "mneedle");
  EXPECT_EQ(lines, 2);
  fs::remove_all(dir);
  EXPECT_THROW(mneedle::cli::append_provenance_line(dir / "gone"), mneedle::InputError);
}

TEST_F(Provenance, VersionNamesEveryLibrary) {
  const auto run = run_mneedle("--version");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out.rfind("mneedle " + mneedle::tool_version() + " (source revision ", 0), 0u)
      << run.out;
  for (const char* lib : {"CGAL 5.", "Eigen 3.", "NLopt 2.", "CHOLMOD ", "assimp 5.", "PLplot 5."})
    EXPECT_NE(run.out.find(lib), std::string::npos) << lib << " missing from\n" << run.out;
}

TEST_F(Provenance, SameInputsUnderSourceDateEpochGiveTheSameBytes) {
  ::setenv("SOURCE_DATE_EPOCH", "1700000000", 1);
  const std::string args = "force '" + kScene + "' --json --step 250um";
  const auto first = run_mneedle(args);
  const auto second = run_mneedle(args);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_EQ(first.out, second.out);
  const Json p = Json::parse(first.out)["provenance"];
  EXPECT_EQ(p["time_utc"], "2023-11-14T22:13:20Z");
  EXPECT_EQ(p["command"], "mneedle force " + kScene + " --json --step 250um");
  // the scene and the STL both needles name, each with the digest sha256sum prints
  ASSERT_EQ(p["inputs"].size(), 3u) << p.dump(2);
  EXPECT_EQ(p["inputs"][0]["role"], "scene");
  EXPECT_EQ(p["inputs"][0]["sha256"], mneedle::sha256_of_file(kScene));
  EXPECT_EQ(p["inputs"][1]["sha256"], mneedle::sha256_of_file(kNeedle));
}

TEST_F(Provenance, BadSourceDateEpochIsOneLineAndExitOne) {
  ::setenv("SOURCE_DATE_EPOCH", "yesterday", 1);
  const auto run = run_mneedle("force '" + kScene + "' --json");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err,
            "mneedle: error: SOURCE_DATE_EPOCH: 'yesterday' is not a whole number of seconds "
            "since 1970-01-01 UTC\n");
  EXPECT_TRUE(run.out.empty());
}

TEST_F(Provenance, PluginNeedlesCarryTheDigestOfTheirMesh) {
  const auto run = run_mneedle("force '" + kRoot + "/designs/scenes/silicone_phantom.toml' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json inputs = Json::parse(run.out)["provenance"]["inputs"];
  ASSERT_GE(inputs.size(), 2u) << inputs.dump(2);
  EXPECT_EQ(inputs[1]["role"].get<std::string>().rfind("needle mesh ", 0), 0u);
  EXPECT_EQ(inputs[1]["sha256"].get<std::string>().size(), 64u);
}

TEST_F(Provenance, CsvStartsWithTheProvenanceLine) {
  const auto run = run_mneedle("force '" + kScene + "' --csv --step 250um");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(run.out);
  std::string first, header;
  std::getline(lines, first);
  std::getline(lines, header);
  ASSERT_EQ(first.rfind("# provenance: ", 0), 0u) << first;
  EXPECT_EQ(Json::parse(first.substr(14))["inputs"][0]["sha256"], mneedle::sha256_of_file(kScene));
  EXPECT_EQ(header, "needle,depth_m,force_N,alpha_N,beta_N,friction_N");
}

// screen's provenance named only the scene; every design's file is an input too (a design list
// once). A single local optimize run draws nothing random: its seed is null, as documented;
// scattered starts draw from it: recorded.
TEST_F(Provenance, ScreenNamesEveryDesignFileAndOnlyASearchThatDrawsRecordsItsSeed) {
  const std::string skin = mneedle::test::skin_scene_with_criterion("pressure");
  const auto run =
      run_mneedle("screen '" + kRoot + "/designs/cone.stl' '" + kRoot +
                  "/designs/cylinder.stl' --scene '" + skin + "' --model analytic --json");
  const Json inputs = Json::parse(run.out)["provenance"]["inputs"];
  std::map<std::string, std::string> digest;
  for (const auto& i : inputs) digest[i["role"].get<std::string>()] = i["sha256"];
  EXPECT_EQ(digest["design cone"], mneedle::sha256_of_file(kRoot + "/designs/cone.stl"))
      << inputs.dump(2);
  EXPECT_EQ(digest["design cylinder"], mneedle::sha256_of_file(kRoot + "/designs/cylinder.stl"))
      << inputs.dump(2);
  const auto optimize = run_mneedle("optimize --plugin cone --scene '" + skin +
                                    "' --vary half_angle --model analytic --max-evals 3 --json");
  ASSERT_EQ(optimize.exit_code, 0) << optimize.err;
  EXPECT_TRUE(Json::parse(optimize.out)["provenance"]["seed"].is_null());
  // Scattered starts draw from the seed: recorded.
  const auto scattered =
      run_mneedle("optimize --plugin cone --scene '" + skin +
                  "' --vary half_angle --model analytic --max-evals 4 --starts 2 --seed 7 --json");
  ASSERT_EQ(scattered.exit_code, 0) << scattered.err;
  EXPECT_EQ(Json::parse(scattered.out)["provenance"]["seed"], 7);
}

TEST_F(Provenance, ScreenRowsCarryTheFileAndMeshDigests) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_prov_s" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  fs::copy_file(kRoot + "/designs/cone.stl", dir / "in" / "cone.stl");
  // The skin scene with the pressure criterion, which the closed-form model takes for any tip.
  const std::string args = "screen '" + (dir / "in").string() + "' --scene '" +
                           mneedle::test::skin_scene_with_criterion("pressure") +
                           "' --model analytic --out '" + (dir / "out").string() + "'";
  ASSERT_EQ(run_mneedle(args).exit_code, 0);
  ASSERT_EQ(run_mneedle(args + " --resume").exit_code, 0);
  std::ifstream rows(dir / "out" / "results.jsonl");
  std::string row;
  ASSERT_TRUE(std::getline(rows, row));
  const Json j = Json::parse(row);
  EXPECT_EQ(j["file_sha256"], mneedle::sha256_of_file(dir / "in" / "cone.stl"));
  EXPECT_EQ(j["mesh_sha256"].get<std::string>().size(), 64u);
  std::ifstream runs(dir / "out" / "provenance.jsonl");
  int lines = 0;
  for (std::string line; std::getline(runs, line);) ++lines;
  EXPECT_EQ(lines, 2);  // the first run and the resumed one
  fs::remove_all(dir);
}

}  // namespace
