#pragma once
// Runs the built `mneedle` binary for end-to-end tests: exit status, stdout and stderr.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "skin_scene.h"

namespace mneedle::test {

struct CommandRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string mneedle_binary() {
  return std::string(MNEEDLE_BINARY_ROOT) + "/cli/mneedle";
}

/// Runs a shell command line (its words quoted by the caller): exit status, stdout, stderr.
inline CommandRun run_command(const std::string& command_line) {
  static int counter = 0;
  const std::filesystem::path err_file =
      std::filesystem::temp_directory_path() /
      ("mneedle_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".err");
  const std::string command = command_line + " 2>'" + err_file.string() + "'";
  CommandRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;)
    run.out.append(buffer, n);
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err_file);
  std::stringstream text;
  text << in.rdbuf();
  run.err = text.str();
  std::filesystem::remove(err_file);
  return run;
}

inline CommandRun run_mneedle(const std::string& arguments) {
  return run_command("'" + mneedle_binary() + "' " + arguments);
}

/// write_skin_scene_with_criterion (skin_scene.h) into the temp folder, one file per process and
/// criterion, removed when the process ends (the test files hold it in constants).
inline std::string skin_scene_with_criterion(const std::string& criterion) {
  struct RemovedAtExit {
    std::vector<std::filesystem::path> files;
    ~RemovedAtExit() {
      std::error_code ignored;
      for (const auto& f : files) std::filesystem::remove(f, ignored);
    }
  };
  static RemovedAtExit written;
  const std::filesystem::path file = write_skin_scene_with_criterion(
      criterion, std::filesystem::temp_directory_path() /
                     ("mneedle_skin_" + criterion + "_" + std::to_string(::getpid()) + ".toml"));
  written.files.push_back(file);
  return file.string();
}

#ifdef MNEEDLE_MPIEXEC
/// The words of `mpirun -n RANKS --oversubscribe mneedle ARGUMENTS… --mpi` under the MPI
/// launcher CMake found (docs/performance.md, "Screening on a cluster"): two ranks on any
/// machine; as root Open MPI wants the two variables set here.
inline std::vector<std::string> mpirun(int ranks, std::vector<std::string> arguments) {
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  std::vector<std::string> words{"-n", std::to_string(ranks), "--oversubscribe", mneedle_binary()};
  words.insert(words.end(), arguments.begin(), arguments.end());
  words.push_back("--mpi");
  return words;
}

/// The launcher's command line, under coreutils' timeout: a hang in the ranks' protocol must
/// fail the test, not hold up the suite.
inline std::string shell_words(const std::vector<std::string>& words) {
  std::string line = std::string("timeout 300 '") + MNEEDLE_MPIEXEC + "'";
  for (const auto& w : words) line += " '" + w + "'";
  return line;
}
#endif

/// A whole output file as text ("" when it is missing).
inline std::string file_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace mneedle::test
