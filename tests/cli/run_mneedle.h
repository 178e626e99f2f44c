#pragma once
// Runs the built `mneedle` binary for end-to-end tests: exit status, stdout and stderr.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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

/// A whole output file as text ("" when it is missing).
inline std::string file_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace mneedle::test
