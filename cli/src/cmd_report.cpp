// mneedle report: one self-contained HTML page from a simulate, screen or optimize result.
// docs/cli.md, "Reports".
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/report/html_report.h"
#include "report_needles.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct ReportArgs {
  std::filesystem::path result;
  std::filesystem::path out;
  std::vector<std::string> plugin_dirs;
};

void run(const ReportArgs& a) {
  record_input("result", a.result);
  const std::string text = read_input_file(a.result);
  nlohmann::json result;
  try {
    result = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // parse_error, and out_of_range for a number beyond a double (1e999)
    throw InputError(a.result.string() + ": not JSON (" + e.what() + ")");
  }
  report::result_kind(result, a.result.string());  // named before any needle is rebuilt
  write_report_file(a.out, result, a.result.string(), a.result.parent_path(), a.plugin_dirs);
  std::cout << "wrote " << a.out.string() << "\n";
}

}  // namespace

void add_report_command(CLI::App& app) {
  auto a = std::make_shared<ReportArgs>();
  auto* cmd = app.add_subcommand(
      "report",
      "One self-contained HTML page (tables, force-depth plots, 3-D needles) from a "
      "simulate, screen or optimize result");
  cmd->add_option("result", a->result, "JSON of simulate --json, screen --json or optimize --json")
      ->required();
  cmd->add_option("-o,--output", a->out, "HTML file to write")->required();
  cmd->add_option("--plugin-dir", a->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->footer(
      "The needles are rebuilt from the files and plugins the result names, and checked against\n"
      "the mesh hashes it recorded. Example:\n"
      "  mneedle screen designs --scene designs/scenes/silicone_phantom.toml --json > r.json\n"
      "  mneedle report r.json -o report.html");
  cmd->callback([a] { run(*a); });
}

}  // namespace mneedle::cli
