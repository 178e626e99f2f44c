#include "mneedle/screening.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "mneedle/error.h"

namespace {

namespace fs = std::filesystem;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;

class Screening : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("mneedle_screening_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "in");
    for (const char* name : {"cone", "cylinder", "sharp_bevel"})
      fs::copy_file(kRoot + "/designs/" + name + ".stl",
                    dir_ / "in" / (std::string(name) + ".stl"));
    fs::copy_file(std::string(MNEEDLE_TEST_ASSETS) + "/meshes/open_box.stl",
                  dir_ / "in" / "broken.stl");
    std::ofstream(dir_ / "in" / "notes.txt") << "not a design\n";
    std::ofstream(dir_ / "list.toml")
        << "[[designs]]\nname = \"bevel_20\"\nplugin = \"sharp_bevel\"\n"
           "bevel_angle = \"20 deg\"\n";
    scene_ = mneedle::load_scene(scene_file_);
    registry_ = mneedle::PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> jsonl_lines() const {
    std::ifstream in(dir_ / "out" / "results.jsonl");
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }

  fs::path dir_;
  fs::path scene_file_ = kRoot + "/designs/scenes/human_skin.toml";
  mneedle::Scene scene_;
  mneedle::PluginRegistry registry_;
};

TEST_F(Screening, CollectsMeshFilesOfAFolderSortedAndDesignListEntries) {
  const auto designs = mneedle::collect_designs({dir_ / "in", dir_ / "list.toml"}, 1e-3);
  ASSERT_EQ(designs.size(), 5u);
  EXPECT_EQ(designs[0].name, "broken");
  EXPECT_EQ(designs[1].name, "cone");
  EXPECT_EQ(designs[4].name, "bevel_20");
  EXPECT_EQ(*designs[4].plugin, "sharp_bevel");
}

TEST_F(Screening, DesignListErrorsNameFileAndLine) {
  std::ofstream(dir_ / "bad.toml") << "[[designs]]\nname = \"x\"\n";
  try {
    mneedle::collect_designs({dir_ / "bad.toml"}, 1e-3);
    FAIL() << "expected an InputError";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml:1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("plugin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(mneedle::collect_designs({dir_ / "missing"}, 1e-3), mneedle::InputError);
}

TEST_F(Screening, BadDesignGetsAnErrorRowAndEveryOtherIsEvaluatedAndWritten) {
  mneedle::ScreeningOptions options;
  options.out = dir_ / "out";
  options.jobs = 2;
  const auto designs = mneedle::collect_designs({dir_ / "in", dir_ / "list.toml"}, 1e-3);
  const auto rows = mneedle::screen_designs(designs, scene_, scene_file_, registry_, options);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_FALSE(rows[0].ok);
  EXPECT_NE(rows[0].error.find("not closed"), std::string::npos) << rows[0].error;
  for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_TRUE(rows[i].ok) << rows[i].error;
  EXPECT_EQ(jsonl_lines().size(), 5u);
  const auto ranked = mneedle::rank_rows(rows);
  EXPECT_FALSE(ranked.back().ok);
}

TEST_F(Screening, ResumeRedoesOnlyWhatAKilledRunHadNotFinished) {
  mneedle::ScreeningOptions options;
  options.out = dir_ / "out";
  const auto designs = mneedle::collect_designs({dir_ / "in"}, 1e-3);
  const auto first = mneedle::screen_designs(designs, scene_, scene_file_, registry_, options);
  // A run killed while writing its third row: two whole lines and half of one.
  auto lines = jsonl_lines();
  ASSERT_EQ(lines.size(), 4u);
  {
    std::ofstream out(dir_ / "out" / "results.jsonl", std::ios::trunc);
    out << lines[0] << "\n" << lines[1] << "\n" << lines[2].substr(0, lines[2].size() / 2);
  }
  options.resume = true;
  const auto second = mneedle::screen_designs(designs, scene_, scene_file_, registry_, options);
  ASSERT_EQ(second.size(), 4u);
  EXPECT_TRUE(second[0].resumed);
  EXPECT_TRUE(second[1].resumed);
  EXPECT_FALSE(second[2].resumed);
  EXPECT_FALSE(second[3].resumed);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(second[i].hash, first[i].hash);
    EXPECT_DOUBLE_EQ(second[i].peak_force_n, first[i].peak_force_n);
  }
}

TEST_F(Screening, ChangedDesignBytesAreNotResumed) {
  mneedle::ScreeningOptions options;
  options.out = dir_ / "out";
  auto designs = mneedle::collect_designs({dir_ / "in" / "cone.stl"}, 1e-3);
  mneedle::screen_designs(designs, scene_, scene_file_, registry_, options);
  fs::copy_file(kRoot + "/designs/cylinder.stl", dir_ / "in" / "cone.stl",
                fs::copy_options::overwrite_existing);
  options.resume = true;
  const auto rows = mneedle::screen_designs(designs, scene_, scene_file_, registry_, options);
  EXPECT_FALSE(rows[0].resumed);
}

}  // namespace
