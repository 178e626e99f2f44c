#pragma once
// The needles of a result, rebuilt for the report's 3-D view from what the result records: a
// simulation's scene (and --axis), a screened row's file (unit, axis, repair) or plugin and
// parameters, an optimisation's plugin and best parameters. Each rebuilt mesh is checked against
// the hash the run recorded: a file that changed since is said, not shown. docs/cli.md, "Reports".

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mneedle/report/html_report.h"

namespace mneedle::cli {

struct RebuiltNeedles {
  std::vector<report::NeedleView> views;
  std::vector<std::string> notes;  // one per needle that could not be rebuilt, saying why
};

/// `result_dir`: the folder of the result file; relative input paths that do not exist from the
/// working directory are looked for there. Never throws for a needle that cannot be rebuilt (the
/// report goes on without it); InputError only for a result that is not one.
RebuiltNeedles rebuild_needles(const nlohmann::json& result,
                               const std::filesystem::path& result_dir,
                               const std::vector<std::string>& plugin_dirs);

/// `--report DIR` of simulate, screen and optimize: DIR/result.json (the command's JSON with its
/// provenance) and DIR/report.html from it, as `mneedle report DIR/result.json -o
/// DIR/report.html` would write them. Notes go to stderr. InputError names the folder or file.
void write_report_folder(const std::filesystem::path& dir, const nlohmann::json& result,
                         const std::vector<std::string>& plugin_dirs);

/// The report of a result already rebuilt (for `mneedle report`): the HTML file.
void write_report_file(const std::filesystem::path& html, const nlohmann::json& result,
                       const std::string& source, const std::filesystem::path& result_dir,
                       const std::vector<std::string>& plugin_dirs);

}  // namespace mneedle::cli
