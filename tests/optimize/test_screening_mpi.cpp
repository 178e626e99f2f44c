// Screening shared by MPI ranks, in one process: what a launcher's environment says, and a
// single-rank session (no mpirun) giving screen_designs' rows. Two ranks run end to end in
// tests/cli/test_cmd_screen.cpp.
#include "mneedle/screening_mpi.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "mneedle/base/error.h"
#include "mneedle/blas_threads.h"
#include "skin_scene.h"

namespace {

namespace fs = std::filesystem;
const std::string kRoot = MNEEDLE_SOURCE_ROOT;

// Sets one environment variable for the scope of a test and restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = ::getenv(name)) old_ = old;
    if (value)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(MpiLaunchSize, ReadsTheProcessCountOpenMpiOrMpichGiveEveryProcess) {
  ScopedEnv pmi("PMI_SIZE", nullptr);
  {
    ScopedEnv ompi("OMPI_COMM_WORLD_SIZE", "4");
    EXPECT_EQ(mneedle::mpi_launch_size(), 4);
  }
  {
    ScopedEnv ompi("OMPI_COMM_WORLD_SIZE", nullptr);
    ScopedEnv mpich("PMI_SIZE", "3");
    EXPECT_EQ(mneedle::mpi_launch_size(), 3);
  }
}

TEST(MpiLaunchSize, IsEmptyWithoutALauncherOrWithAValueThatIsNotACount) {
  ScopedEnv pmi("PMI_SIZE", nullptr);
  {
    ScopedEnv ompi("OMPI_COMM_WORLD_SIZE", nullptr);
    EXPECT_FALSE(mneedle::mpi_launch_size().has_value());
  }
  for (const char* bad : {"", "two", "3x", "-1", "0"}) {
    ScopedEnv ompi("OMPI_COMM_WORLD_SIZE", bad);
    EXPECT_FALSE(mneedle::mpi_launch_size().has_value()) << "'" << bad << "'";
  }
}

TEST(MpiLaunchRank, IsTheLaunchersRankOrZeroWithoutOne) {
  ScopedEnv pmi("PMI_RANK", nullptr);
  {
    ScopedEnv ompi("OMPI_COMM_WORLD_RANK", "1");
    EXPECT_EQ(mneedle::mpi_launch_rank(), 1);
  }
  ScopedEnv ompi("OMPI_COMM_WORLD_RANK", nullptr);
  EXPECT_EQ(mneedle::mpi_launch_rank(), 0);
}

TEST(MpiSession, OneRankWithoutALauncherScreensAsScreenDesignsDoes) {
  if (!mneedle::mpi_built_in()) {
    // Built without MPI: asking for it is a one-line error naming the option.
    try {
      mneedle::MpiSession session(1);
      FAIL() << "expected an InputError";
    } catch (const mneedle::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("MNEEDLE_MPI"), std::string::npos) << e.what();
    }
    return;
  }
  const fs::path dir = fs::temp_directory_path() / ("mneedle_mpi1_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "list.toml")
      << "[[designs]]\nname = \"cone_a\"\nplugin = \"cone\"\ndiameter = \"150 um\"\n\n"
         "[[designs]]\nname = \"missing\"\nplugin = \"no_such_shape\"\n\n"
         "[[designs]]\nname = \"bevel\"\nplugin = \"sharp_bevel\"\nbevel_angle = \"20 deg\"\n";
  // The skin scene with the pressure criterion: the closed-form model run here has no stress
  // field for the scene's own stress criterion, and every row would be the same error.
  const fs::path scene_file =
      mneedle::test::write_skin_scene_with_criterion("pressure", dir / "human_skin_pressure.toml");
  const mneedle::Scene scene = mneedle::load_scene(scene_file);
  const auto registry = mneedle::PluginRegistry::discover({MNEEDLE_PLUGIN_BUILD_DIR});
  const auto designs = mneedle::collect_designs({dir / "list.toml"}, 1e-3);
  mneedle::ScreeningOptions options;
  options.model = "analytic";
  options.out = dir / "serial";
  const auto serial = mneedle::screen_designs(designs, scene, scene_file, registry, options);

  mneedle::MpiSession session(2);  // a singleton: rank 0 of 1, two threads
  EXPECT_EQ(session.rank(), 0);
  EXPECT_EQ(session.size(), 1);
  EXPECT_TRUE(session.agree(true).all);
  options.out = dir / "mpi";
  options.jobs = 2;
  int reported = 0;
  const auto rows = mneedle::screen_designs_mpi(session, designs, scene, scene_file, registry,
                                                options, [&](const auto&) { ++reported; });
  EXPECT_EQ(reported, 3);
  ASSERT_EQ(rows.size(), serial.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].design, serial[i].design);
    EXPECT_EQ(rows[i].ok, serial[i].ok) << rows[i].error;
    EXPECT_EQ(rows[i].error, serial[i].error);
    EXPECT_EQ(rows[i].puncture_depth_m, serial[i].puncture_depth_m) << rows[i].design;
    EXPECT_EQ(rows[i].peak_force_n, serial[i].peak_force_n) << rows[i].design;
  }
  EXPECT_FALSE(rows[1].ok);  // the unknown shape is an error row; the others went on
  std::ifstream jsonl(dir / "mpi" / "results.jsonl");
  int lines = 0;
  for (std::string line; std::getline(jsonl, line);) ++lines;
  EXPECT_EQ(lines, 3);
  fs::remove_all(dir);
}

}  // namespace
