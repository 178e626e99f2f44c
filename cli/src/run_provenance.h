#pragma once
// The provenance of this process's run (docs/cli.md, "Provenance"): main() starts it with the
// command line, each command records the inputs it reads, and every output carries it — a
// "provenance" object in JSON, a "# provenance: {…}" first line in CSV, a comment in VTU and
// SVG files. One process runs one command, so one record per process is the whole story.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mneedle/base/provenance.h"

namespace mneedle {
struct Scene;
struct TriangleMesh;
struct PreparedNeedle;
}  // namespace mneedle

namespace mneedle::cli {

/// Started by main() with argv; commands add to it.
Provenance& run_provenance();

/// `text` with every byte that is not valid UTF-8 replaced by U+FFFD: JSON holds only UTF-8, and a
/// Latin-1 file name on the command line must not fail the output after the run.
std::string valid_utf8(const std::string& text);

/// Adds a file with the SHA-256 of its bytes; InputError when it cannot be read.
void record_input(const std::string& role, const std::filesystem::path& file);

/// The scene file, and every STL needle it names, each with its file's SHA-256.
void record_scene(const Scene& scene, const std::filesystem::path& file);

/// A needle mesh made in memory (a plugin's), with mesh_sha256 (needle/mesh.h) of it in the
/// needle frame.
void record_mesh(const std::string& name, const TriangleMesh& mesh);

/// record_mesh for every needle of the scene that a plugin made (an STL needle's file is
/// recorded by record_scene). `needles` are prepare_needles' output, in the scene's order.
void record_plugin_meshes(const Scene& scene, const std::vector<PreparedNeedle>& needles);

nlohmann::ordered_json provenance_json();

/// `tree` with the run's provenance as a top-level key when it is an object without one (last in
/// an ordered_json, in key order in a json); what every command prints or writes goes through this.
template <class Json>
Json with_provenance(Json tree) {
  if (tree.is_object() && !tree.contains("provenance")) tree["provenance"] = provenance_json();
  return tree;
}

/// Appends the provenance as one line to FOLDER/provenance.jsonl: a folder that several runs
/// wrote into (screen --resume) keeps one line per run. InputError naming the file on failure.
void append_provenance_line(const std::filesystem::path& folder);

/// One line without a newline: "# provenance: " and the compact JSON.
std::string provenance_comment();

/// What `mneedle --version` prints: the version and revision, then the libraries it was built
/// with, one per line.
std::string version_text();

}  // namespace mneedle::cli
