#pragma once
// One self-contained HTML page from a result of `simulate`, `screen` or `optimize`: the inputs and
// their provenance, the table a reader needs (needles, ranking or history), every force–depth
// curve as the SVG figures of plot/, the strength margin, and a 3-D view of each needle that can
// be turned with the mouse (three.js, bundled into the page at build time: it opens offline and
// fetches nothing). docs/cli.md, "Reports".

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mneedle/needle/mesh.h"
#include "mneedle/plot/figure.h"

namespace mneedle::report {

/// The command a result came from, told by its keys (a screen has `designs` and `ranking`, an
/// optimisation `history`, a simulation `needles` and `total_curve`).
enum class ResultKind { Simulate, Screen, Optimize };

/// InputError "<where>: not a result of simulate, screen or optimize (...)" for anything else.
ResultKind result_kind(const nlohmann::json& result, const std::string& where);

/// A needle of the 3-D view: its name as the result gives it, its mesh in the needle frame (m).
struct NeedleView {
  std::string name;
  TriangleMesh mesh;
  /// Its entry in the result: the index in a simulation's `needles` or a screen's `designs`
  /// (names need not be unique); -1 when no table row shows it (an optimisation's best design).
  int entry = -1;
};

struct ReportInput {
  nlohmann::json result;            ///< the command's JSON, provenance included
  std::string source;               ///< where it was read from (for the title and messages)
  std::vector<NeedleView> needles;  ///< the 3-D view's needles (none: the view says why)
  std::vector<std::string> notes;   ///< said under the title (a needle that could not be rebuilt)
  nlohmann::json made_by;           ///< the provenance of the run that writes the report (or null)
};

/// The figures the report shows, in order (force against depth for every curve of the result;
/// an optimisation's objective against evaluation). Throws InputError naming the key when a
/// curve in the result is malformed.
std::vector<plot::Figure> report_figures(const nlohmann::json& result, const std::string& where);

/// The page as text. Throws InputError naming `source` and the key for a malformed result.
std::string html_report(const ReportInput& input);

/// Writes html_report(input) to `file` through a temporary file renamed at the end (a failed run
/// leaves no half-written page). InputError names the file when it cannot be written.
void write_report(const std::filesystem::path& file, const ReportInput& input);

}  // namespace mneedle::report
