#include "report_needles.h"

#include <exception>
#include <fstream>
#include <iostream>

#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/provenance.h"
#include "mneedle/design_source.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

using nlohmann::json;

// An input path as the run named it (relative to its working directory), else beside the result.
std::filesystem::path locate(const std::string& name, const std::filesystem::path& result_dir) {
  const std::filesystem::path given(name);
  if (given.is_absolute() || std::filesystem::exists(given) || result_dir.empty()) return given;
  const auto beside = result_dir / given;
  return std::filesystem::exists(beside) ? beside : given;
}

// The rebuilt mesh is the one the run evaluated, or the reason it is not.
bool same_mesh(const TriangleMesh& mesh, const json& recorded, const std::string& what,
               std::vector<std::string>& notes) {
  if (!recorded.is_string()) return true;  // older results carry no hash: nothing to check
  if (mesh_sha256(mesh) == recorded.get<std::string>()) return true;
  notes.push_back(what +
                  ": not shown in 3-D, its mesh rebuilt today differs from the one the run "
                  "evaluated (mesh SHA-256; the file or plugin changed since)");
  return false;
}

PluginRegistry registry_of(const std::vector<std::string>& plugin_dirs) {
  return PluginRegistry::discover({plugin_dirs.begin(), plugin_dirs.end()});
}

void simulate_needles(const json& r, const std::filesystem::path& dir,
                      const std::vector<std::string>& plugin_dirs, RebuiltNeedles& out) {
  std::string scene_name, scene_sha;
  for (const json& i : r.value("provenance", json::object()).value("inputs", json::array()))
    if (i.value("role", "") == "scene") {
      scene_name = i.value("name", "");
      scene_sha = i.value("sha256", "");
    }
  if (scene_name.empty()) {
    out.notes.push_back("no 3-D view: the result names no scene file in its provenance");
    return;
  }
  const auto file = locate(scene_name, dir);
  if (!std::filesystem::exists(file)) {
    out.notes.push_back("no 3-D view: the scene " + scene_name + " is not there any more");
    return;
  }
  if (!scene_sha.empty() && sha256_of_file(file) != scene_sha) {
    out.notes.push_back("no 3-D view: the scene " + file.string() +
                        " changed since the run (SHA-256 differs)");
    return;
  }
  Scene scene = load_scene(file);
  if (r.contains("axis") && r.at("axis").is_string())
    for (NeedleSpec& n : scene.needles)
      if (auto* stl = std::get_if<StlGeometry>(&n.geometry)) stl->axis = r.at("axis");
  const auto needles = prepare_needles(registry_of(plugin_dirs), scene);
  const json& recorded = r.value("needles", json::array());
  for (std::size_t i = 0; i < needles.size(); ++i) {
    const json hash = i < recorded.size() ? recorded[i].value("mesh_sha256", json()) : json();
    if (same_mesh(needles[i].mesh, hash, "needle " + needles[i].name, out.notes))
      out.views.push_back({needles[i].name, needles[i].mesh, static_cast<int>(i)});
  }
}

void screen_needles(const json& r, const std::filesystem::path& dir,
                    const std::vector<std::string>& plugin_dirs, RebuiltNeedles& out) {
  std::optional<PluginRegistry> registry;
  const json designs = r.value("designs", json::array());
  for (std::size_t k = 0; k < designs.size(); ++k) {
    const json& d = designs[k];
    if (!d.value("ok", false)) continue;  // an error row has no needle to show
    const std::string name = d.value("design", "");
    try {
      NeedleSource source;
      if (d.contains("plugin")) {
        if (!registry) registry = registry_of(plugin_dirs);
        source = needle_from_plugin(*registry, d.at("plugin").get<std::string>(),
                                    d.at("params").get<std::map<std::string, double>>());
      } else {
        const auto file = locate(d.value("source", ""), dir);
        if (d.contains("file_sha256") && std::filesystem::exists(file) &&
            sha256_of_file(file) != d.at("file_sha256").get<std::string>()) {
          out.notes.push_back("design " + name + ": not shown in 3-D, " + file.string() +
                              " changed since the run (SHA-256 differs)");
          continue;
        }
        source =
            needle_from_file(file, d.value("metres_per_unit", 1e-3),
                             parse_axis_choice(d.value("axis", "auto")), d.value("repair", false));
      }
      if (same_mesh(source.mesh, d.value("mesh_sha256", json()), "design " + name, out.notes))
        out.views.push_back({name, std::move(source.mesh), static_cast<int>(k)});
    } catch (const std::exception& e) {
      out.notes.push_back("design " + name + ": not shown in 3-D (" + e.what() + ")");
    }
  }
}

void optimize_needles(const json& r, const std::vector<std::string>& plugin_dirs,
                      RebuiltNeedles& out) {
  const json& best = r.value("best", json::object());
  if (!r.contains("plugin") || !best.contains("params")) {
    out.notes.push_back("no 3-D view: the result names no plugin and parameters");
    return;
  }
  const NeedleSource source =
      needle_from_plugin(registry_of(plugin_dirs), r.at("plugin").get<std::string>(),
                         best.at("params").get<std::map<std::string, double>>());
  if (same_mesh(source.mesh, best.value("mesh_sha256", json()), "the best design", out.notes))
    out.views.push_back({"best design", source.mesh, -1});
}

}  // namespace

RebuiltNeedles rebuild_needles(const json& result, const std::filesystem::path& result_dir,
                               const std::vector<std::string>& plugin_dirs) {
  RebuiltNeedles out;
  const report::ResultKind kind = report::result_kind(result, "report");
  try {
    switch (kind) {
      case report::ResultKind::Simulate:
        simulate_needles(result, result_dir, plugin_dirs, out);
        break;
      case report::ResultKind::Screen:
        screen_needles(result, result_dir, plugin_dirs, out);
        break;
      case report::ResultKind::Optimize:
        optimize_needles(result, plugin_dirs, out);
        break;
    }
  } catch (const std::exception& e) {
    out.notes.push_back(std::string("no 3-D view: ") + e.what());
  }
  return out;
}

void write_report_file(const std::filesystem::path& html, const json& result,
                       const std::string& source, const std::filesystem::path& result_dir,
                       const std::vector<std::string>& plugin_dirs) {
  report::ReportInput input;
  input.result = result;
  input.source = source;
  RebuiltNeedles needles = rebuild_needles(result, result_dir, plugin_dirs);
  input.needles = std::move(needles.views);
  input.notes = std::move(needles.notes);
  input.made_by = json(provenance_json());
  for (const auto& n : input.notes) std::cerr << "mneedle: report: " << n << "\n";
  report::write_report(html, input);
}

void write_report_folder(const std::filesystem::path& dir, const json& result,
                         const std::vector<std::string>& plugin_dirs) {
  create_output_folder(dir, "--report");
  const json tree = with_provenance(result);
  require_finite_json(tree, "--report");
  const auto file = dir / "result.json";
  {
    std::ofstream out(file, std::ios::binary);
    out << tree.dump(2) << "\n";
    if (!out.flush()) throw InputError("--report: cannot write '" + file.string() + "'");
  }
  write_report_file(dir / "report.html", tree, file.string(), {}, plugin_dirs);
}

}  // namespace mneedle::cli
