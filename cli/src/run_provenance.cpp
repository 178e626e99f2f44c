#include "run_provenance.h"

#include <assimp/version.h>
#include <nlopt.h>
#include <plplot.h>

#include <CGAL/version.h>
#include <Eigen/Core>
#include <array>
#include <cstring>
#include <fstream>
#include <sstream>
#include <variant>

#include "mneedle/base/error.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/scene/scene.h"

#ifdef MNEEDLE_HAVE_CHOLMOD
#include <cholmod.h>
#endif

namespace mneedle::cli {

Provenance& run_provenance() {
  static Provenance p;
  return p;
}

std::string valid_utf8(const std::string& text) {
  const std::string quoted =
      nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return nlohmann::json::parse(quoted).get<std::string>();
}

void record_input(const std::string& role, const std::filesystem::path& file) {
  run_provenance().inputs.push_back({role, valid_utf8(file.string()), sha256_of_file(file)});
}

void record_scene(const Scene& scene, const std::filesystem::path& file) {
  record_input("scene", file);
  for (const NeedleSpec& n : scene.needles)
    if (const auto* stl = std::get_if<StlGeometry>(&n.geometry))
      record_input("needle " + n.name, stl->path);
}

void record_mesh(const std::string& name, const TriangleMesh& mesh) {
  run_provenance().inputs.push_back(
      {valid_utf8("needle mesh " + name), valid_utf8(name), mesh_sha256(mesh)});
}

void record_plugin_meshes(const Scene& scene, const std::vector<PreparedNeedle>& needles) {
  for (std::size_t i = 0; i < needles.size() && i < scene.needles.size(); ++i)
    if (std::holds_alternative<PluginGeometry>(scene.needles[i].geometry))
      record_mesh(needles[i].name, needles[i].mesh);
}

nlohmann::ordered_json provenance_json() {
  const Provenance& p = run_provenance();
  nlohmann::ordered_json j;
  j["tool"] = "mneedle";
  j["version"] = p.version;
  j["source_revision"] = p.source_revision;
  j["command"] = p.command;
  j["time_utc"] = p.time_utc;
  j["seed"] = p.seed ? nlohmann::ordered_json(*p.seed) : nlohmann::ordered_json(nullptr);
  j["inputs"] = nlohmann::ordered_json::array();
  for (const InputDigest& in : p.inputs)
    j["inputs"].push_back({{"role", in.role}, {"name", in.name}, {"sha256", in.sha256}});
  return j;
}

void append_provenance_line(const std::filesystem::path& folder) {
  const std::filesystem::path file = folder / "provenance.jsonl";
  std::ofstream out(file, std::ios::app);
  out << provenance_json().dump() << "\n";
  if (!out) throw InputError(file.string() + ": cannot write");
}

std::string provenance_comment() {
  return "# provenance: " + provenance_json().dump();
}

std::string version_text() {
  std::ostringstream out;
  out << "mneedle " << tool_version() << " (source revision " << source_revision() << ")\n";
  int major = 0, minor = 0, bugfix = 0;
  nlopt_version(&major, &minor, &bugfix);
  std::array<char, 80> plplot{};
  c_plgver(plplot.data());
  out << "  CGAL " << CGAL_VERSION_STR << "\n"
      << "  Eigen " << EIGEN_WORLD_VERSION << '.' << EIGEN_MAJOR_VERSION << '.'
      << EIGEN_MINOR_VERSION << "\n"
      << "  NLopt " << major << '.' << minor << '.' << bugfix << "\n"
#ifdef MNEEDLE_HAVE_CHOLMOD
      << "  CHOLMOD " << CHOLMOD_MAIN_VERSION << '.' << CHOLMOD_SUB_VERSION << '.'
      << CHOLMOD_SUBSUB_VERSION << "\n"
#else
      << "  CHOLMOD not built in (Eigen's sparse Cholesky)\n"
#endif
      << "  assimp " << aiGetVersionMajor() << '.' << aiGetVersionMinor() << '.'
      << aiGetVersionPatch() << "\n"
      << "  PLplot " << plplot.data();  // CLI11 ends the text with a newline
  return out.str();
}

}  // namespace mneedle::cli
