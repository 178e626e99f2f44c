#include "mneedle/screening.h"
#include "mneedle/base/provenance.h"

#include <toml++/toml.h>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/blas_threads.h"
#include "mneedle/design_evaluation.h"
#include "mneedle/design_source.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/strength/needle_material.h"
#include "screening_batch.h"

namespace mneedle {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool is_mesh_file(const fs::path& p) {
  static const std::set<std::string> kMesh = {".stl", ".obj", ".ply", ".off"};
  return kMesh.count(lower_extension(p)) > 0;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// FNV-1a: a stable fingerprint, not a cryptographic one.
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 14695981039346656037ull) {
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string hex(std::uint64_t v) {
  std::ostringstream s;
  s << std::hex << v;
  return s.str();
}

std::string where(const fs::path& file, const toml::source_region& region) {
  return file.string() + ":" + std::to_string(region.begin.line);
}

Quantity list_value(const toml::node& node, const std::string& at) {
  if (const auto* s = node.as_string()) {
    try {
      return parse_quantity(s->get());
    } catch (const InputError& e) {
      throw InputError(at + ": " + e.what());
    }
  }
  if (const auto v = node.value<double>()) return {*v, Dimension::Dimensionless};
  throw InputError(at + ": expected a quantity such as \"230 um\" or a number");
}

std::vector<DesignInput> read_design_list(const fs::path& file) {
  toml::table doc;
  try {
    doc = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(file.string() + ":" + std::to_string(e.source().begin.line) + ": " +
                     std::string(e.description()));
  }
  for (const auto& [key, node] : doc)
    if (key.str() != "designs")
      throw InputError(where(file, node.source()) + ": unknown key '" + std::string(key.str()) +
                       "' (a design list holds [[designs]] tables)");
  const auto* designs = doc["designs"].as_array();
  if (!designs || designs->empty())
    throw InputError(file.string() + ": a design list needs at least one [[designs]] table");
  std::vector<DesignInput> out;
  for (const auto& node : *designs) {
    const auto* t = node.as_table();
    const std::string at = where(file, node.source());
    if (!t) throw InputError(at + ": each entry of designs must be a table");
    DesignInput d;
    d.file = file;
    for (const auto& [key, value] : *t) {
      const std::string k(key.str());
      const std::string at_key = where(file, value.source()) + ": designs." + k;
      if (k == "name" || k == "plugin") {
        if (!value.is_string()) throw InputError(at_key + ": expected a string");
        (k == "name" ? d.name : d.plugin.emplace()) = value.as_string()->get();
      } else {
        d.parameters[k] = list_value(value, at_key);
      }
    }
    if (!d.plugin) throw InputError(at + ": designs entry without 'plugin'");
    if (d.name.empty()) d.name = *d.plugin + "_" + std::to_string(out.size() + 1);
    out.push_back(std::move(d));
  }
  return out;
}

// Exact: the name, the file's bytes, and every number at full precision (17 digits), so two
// designs that differ in anything never share a row.
std::string exact(double value) {
  std::ostringstream out;
  out << std::setprecision(17) << value;
  return out.str();
}

std::string design_fingerprint(const DesignInput& d) {
  const std::string name = "name=" + d.name + "|";
  if (!d.plugin) return name + read_bytes(d.file) + "|unit=" + exact(d.metres_per_unit);
  std::string text = name + "plugin=" + *d.plugin;
  for (const auto& [k, q] : d.parameters) text += "|" + k + "=" + exact(q.value_si);
  return text;
}

// The design's mesh with what lets run_insertion reduce the model: an axisymmetric profile for
// the cylinder and cone plugins and for round meshes, the x = 0 and y = 0 mirror planes (a vertex
// lookup) for any mesh: needle_symmetry, as simulate takes them.
struct ScreenedNeedle {
  TriangleMesh mesh;
  EvaluationOptions options;
  std::string frame_note;                // how a mesh file's axis, tip and holder were found
  std::map<std::string, double> params;  // plugin designs: the shape's parameters, SI
};

ScreenedNeedle design_needle(const DesignInput& d, const PluginRegistry& registry,
                             const ScreeningOptions& o) {
  const std::string where = d.file.string() + ": " + d.name;
  const NeedleSource source =
      d.plugin
          ? needle_from_plugin(registry, *d.plugin,
                               scene_parameters(registry.shape(*d.plugin), d.parameters, where))
          : needle_from_file(d.file, d.metres_per_unit, parse_axis_choice(o.axis), o.repair);
  ScreenedNeedle n;
  n.frame_note = source.frame_note;
  n.params = source.params;
  n.options.fidelity = parse_fidelity(o.fidelity);
  n.options.model = parse_pre_model(o.model);
  n.options.symmetry = needle_symmetry(registry, source, where);
  n.mesh = source.mesh;
  return n;
}

// No NaN or Inf may reach results.jsonl/csv (nlohmann would write them as null).
std::optional<std::string> non_finite_key(const json& j, const std::string& path = "") {
  if (j.is_number_float() && !std::isfinite(j.get<double>())) return path;
  if (j.is_object())
    for (const auto& [k, v] : j.items())
      if (auto bad = non_finite_key(v, path.empty() ? k : path + "." + k)) return bad;
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i)
      if (auto bad = non_finite_key(j[i], path + "[" + std::to_string(i) + "]")) return bad;
  return std::nullopt;
}

json optional_number(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

json evaluation_json(const DesignEvaluation& e) {
  const auto& g = e.geometry;
  const auto& s = e.strength;
  return {{"triangles", g.triangles},
          {"volume_m3", g.volume_m3},
          {"area_m2", g.area_m2},
          {"length_m", g.length_m},
          {"tip_length_m", g.tip_length_m},
          {"alpha_area_m2", g.alpha_area_m2},
          {"beta_area_m2", g.beta_area_m2},
          {"depth_m", e.depth_m},
          {"force_at_depth_N", e.force_at_depth_n},
          {"peak_force_N", e.peak_force_n},
          {"curve", curve_json(e.curve)},
          {"puncture", e.puncture ? json{{"depth_m", e.puncture->depth_m},
                                         {"force_N", e.puncture->force_N},
                                         {"post_force_N", e.puncture->post_force_N},
                                         {"criterion", e.puncture->criterion},
                                         {"at_first_contact", e.puncture->at_first_contact},
                                         {"lower_bound", e.puncture->lower_bound}}
                                  : json(nullptr)},
          {"punctured", e.puncture.has_value()},
          {"puncture_at_first_contact", e.puncture && e.puncture->at_first_contact},
          {"puncture_lower_bound", e.puncture && e.puncture->lower_bound},
          {"puncture_depth_m",
           optional_number(e.puncture ? std::optional(e.puncture->depth_m) : std::nullopt)},
          {"puncture_force_N",
           optional_number(e.puncture ? std::optional(e.puncture->force_N) : std::nullopt)},
          {"post_puncture_force_N",
           optional_number(e.puncture ? std::optional(e.puncture->post_force_N) : std::nullopt)},
          {"puncture_criterion", e.puncture ? json(e.puncture->criterion) : json(nullptr)},
          {"target_depth_m", e.depth_m},
          {"reaches_target_depth", e.reaches_target},
          {"models_run", e.models_run},
          {"reductions", e.reductions},
          {"insertion_seconds", e.insertion_seconds},
          {"material", e.material},
          {"buckling_N", s.buckling_n},
          {"strength_N", s.strength_n},
          {"capacity_N", s.capacity_n},
          {"governing", s.governing},
          {"margin", std::isfinite(e.margin) ? json(e.margin) : json(nullptr)},
          {"safety_factor", e.safety_factor},
          {"passes", e.passes},
          {"notes", e.notes}};
}

// The hash names a design's inputs, so --resume can tell which finished rows still apply.
std::string row_hash(const DesignInput& d, const std::string& scene_hash,
                     const std::string& fidelity, const std::string& material) {
  // Version 3 rows hash the design's name and full-precision values and carry
  // puncture_at_first_contact; version 4 rows carry the force curve (the report plots it);
  // version 5 rows carry puncture_lower_bound; older rows are redone.
  constexpr const char* kRowVersion = "5";
  std::string fingerprint;
  try {
    fingerprint = design_fingerprint(d);
  } catch (const std::exception&) {
    fingerprint = d.name + d.file.string();  // unreadable: evaluation reports why
  }
  // The build's source revision too: a row another build computed is not this one's result
  // (a resumed capacity of 41.18 N was ranked beside this build's 40.71 N).
  return hex(fnv1a(fingerprint + "|" + scene_hash + "|" + fidelity + "|" + material + "|" +
                   kRowVersion + "|" + source_revision()));
}

json percentiles_json(const Percentiles& p) {
  if (p.count == 0) return {{"count", 0}, {"p5", nullptr}, {"p50", nullptr}, {"p95", nullptr}};
  return {{"count", p.count}, {"p5", p.p5}, {"p50", p.p50}, {"p95", p.p95}};
}

// screen --uncertainty: the design in every sampled scene (run_uncertainty's draws, the same for
// every design), summarised for its row.
json design_uncertainty(const ScreenedNeedle& needle, const std::string& scene_text,
                        const std::string& scene_source, const std::string& material,
                        const ScreeningOptions& o) {
  UncertaintyOptions u = o.uncertainty;
  u.jobs = 1;  // the designs share the jobs
  u.sensitivity = false;
  u.fidelity = o.fidelity;
  u.model = o.model;
  const SceneEvaluator evaluate = [&](const Scene& sampled) {
    return evaluate_design(needle.mesh, sampled, material, needle.options);
  };
  const UncertaintyResult r = run_uncertainty(scene_text, scene_source, o.vary, u, evaluate);
  json inputs = json::array();
  for (const auto& v : o.vary) inputs.push_back(v.text);
  return {{"samples", u.samples},
          {"seed", u.seed},
          {"method", u.latin_hypercube ? "lhs" : "mc"},
          {"vary", inputs},
          {"pass_probability", r.pass_probability},
          {"pass_probability_standard_error", r.pass_probability_standard_error},
          {"punctured_fraction", r.punctured_fraction},
          {"first_contact_fraction", r.first_contact_fraction},
          {"failed_samples", r.failed},
          {"puncture_depth_m", percentiles_json(r.puncture_depth_m)},
          {"puncture_force_N", percentiles_json(r.puncture_force_n)},
          {"peak_force_N", percentiles_json(r.peak_force_n)},
          {"margin", percentiles_json(r.margin)}};
}

ScreeningRow evaluate_row(const DesignInput& d, const Scene& scene, const std::string& scene_text,
                          const std::string& scene_source, const std::string& hash,
                          const std::string& material, const PluginRegistry& registry,
                          const ScreeningOptions& o) {
  ScreeningRow row;
  row.design = d.name;
  row.hash = hash;
  const auto start = std::chrono::steady_clock::now();
  json j = {{"design", d.name}, {"source", d.file.string()}};
  try {
    const ScreenedNeedle needle = design_needle(d, registry, o);
    row.frame_note = needle.frame_note;
    if (!needle.frame_note.empty()) j["frame_note"] = needle.frame_note;
    // What rebuilds the mesh (the report's 3-D view): the plugin and its parameters, or the
    // file with its unit, axis and repair.
    if (d.plugin) {
      j["plugin"] = *d.plugin;
      j["params"] = needle.params;
    } else {
      j["metres_per_unit"] = d.metres_per_unit;
      j["axis"] = o.axis;
      j["repair"] = o.repair;
    }
    // provenance of the row (docs/cli.md, "Provenance"): the file as read, the mesh as evaluated
    if (!d.plugin) j["file_sha256"] = sha256_of_file(d.file);
    j["mesh_sha256"] = mesh_sha256(needle.mesh);
    const DesignEvaluation e = evaluate_design(needle.mesh, scene, material, needle.options);
    row.ok = true;
    row.peak_force_n = e.peak_force_n;
    if (e.puncture) {
      row.puncture_depth_m = e.puncture->depth_m;
      row.puncture_force_n = e.puncture->force_N;
      row.puncture_at_first_contact = e.puncture->at_first_contact;
      row.puncture_lower_bound = e.puncture->lower_bound;
    }
    row.margin = e.margin;
    row.passes = e.passes;
    const json evaluation = evaluation_json(e);
    if (const auto key = non_finite_key(evaluation))
      throw SolverError("non-finite value of " + *key + " (not written)");
    j.update(evaluation);
    if (!o.vary.empty()) {
      j["uncertainty"] = design_uncertainty(needle, scene_text, scene_source, material, o);
      row.pass_probability = j["uncertainty"]["pass_probability"].get<double>();
      const auto& depth = j["uncertainty"]["puncture_depth_m"];
      if (!depth["p50"].is_null()) row.median_puncture_depth_m = depth["p50"].get<double>();
      if (const auto key = non_finite_key(j["uncertainty"]))
        throw SolverError("non-finite value of uncertainty." + *key + " (not written)");
    }
  } catch (const OutOfMemoryError& e) {
    row.ok = false;
    row.retry = true;
    row.error = e.what();
    j["error"] = row.error;
    j["retry"] = true;
  } catch (const std::exception& e) {
    row.ok = false;
    row.error = e.what();
    j["error"] = row.error;
  }
  j["hash"] = row.hash;
  j["ok"] = row.ok;
  j["fidelity"] = o.fidelity;
  j["model"] = o.model;
  j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  row.json = j.dump();
  return row;
}

ScreeningRow error_row(const DesignInput& d, const std::string& message) {
  ScreeningRow row;
  row.design = d.name;
  row.error = message;
  row.json =
      json{{"design", d.name}, {"source", d.file.string()}, {"ok", false}, {"error", message}}
          .dump();
  return row;
}

ScreeningRow row_from_json(const std::string& line) {
  const json j = json::parse(line);
  ScreeningRow row;
  row.design = j.at("design").get<std::string>();
  row.hash = j.value("hash", "");  // an error row of a design that could not be read has none
  row.ok = j.at("ok").get<bool>();
  row.retry = j.value("retry", false);
  row.resumed = true;
  row.json = line;
  if (row.ok) {
    row.peak_force_n = j.at("peak_force_N").get<double>();
    if (!j.at("puncture_depth_m").is_null()) {
      row.puncture_depth_m = j.at("puncture_depth_m").get<double>();
      row.puncture_force_n = j.at("puncture_force_N").get<double>();
      row.puncture_at_first_contact = j.value("puncture_at_first_contact", false);
      row.puncture_lower_bound = j.value("puncture_lower_bound", false);
    }
    row.margin = j.at("margin").is_null() ? INFINITY : j.at("margin").get<double>();
    row.passes = j.at("passes").get<bool>();
    if (j.contains("uncertainty")) {
      const auto& u = j.at("uncertainty");
      row.pass_probability = u.at("pass_probability").get<double>();
      if (!u.contains("pass_probability_standard_error")) {
        // A row written before the key existed: the same from its own counts.
        json with = j;
        with["uncertainty"]["pass_probability_standard_error"] = binomial_standard_error(
            *row.pass_probability, u.at("samples").get<double>() - u.value("failed_samples", 0.0));
        row.json = with.dump();
      }
      if (!u.at("puncture_depth_m").at("p50").is_null())
        row.median_puncture_depth_m = u.at("puncture_depth_m").at("p50").get<double>();
    }
  } else {
    row.error = j.value("error", "");
  }
  row.frame_note = j.value("frame_note", "");  // a failed mesh file may have one too
  return row;
}

// Rows finished by an earlier run, by hash; a half-written last line (a killed run) is ignored.
// A run killed while writing leaves a last line without its newline: cut it off so the next row
// starts on a line of its own (the design is then evaluated again).
void truncate_partial_line(const fs::path& file) {
  std::error_code error;
  if (!fs::exists(file, error)) return;
  const std::string bytes = read_bytes(file);
  if (bytes.empty() || bytes.back() == '\n') return;
  const auto keep = bytes.rfind('\n');
  fs::resize_file(file, keep == std::string::npos ? 0 : keep + 1);
}

// A device or a pipe in the results' place would be read without end.
void require_regular_results(const fs::path& jsonl) {
  std::error_code error;
  if (fs::exists(jsonl, error) && !fs::is_regular_file(jsonl, error))
    throw InputError(jsonl.string() + ": not a regular file");
}

std::map<std::string, ScreeningRow> finished_rows(const fs::path& jsonl) {
  std::map<std::string, ScreeningRow> done;
  require_regular_results(jsonl);
  truncate_partial_line(jsonl);
  std::ifstream in(jsonl);
  std::string line;
  while (std::getline(in, line)) {
    try {
      ScreeningRow row = row_from_json(line);
      done[row.hash] = std::move(row);
    } catch (const std::exception&) {
    }
  }
  return done;
}

std::string csv_field(const json& j, const char* key) {
  if (!j.contains(key) || j[key].is_null()) return "";
  if (j[key].is_string()) {
    std::string s = j[key].get<std::string>();
    std::replace(s.begin(), s.end(), '"', '\'');
    return "\"" + s + "\"";
  }
  return j[key].dump();
}

constexpr const char* kCsvColumns[] = {"design",
                                       "ok",
                                       "puncture_depth_m",
                                       "puncture_force_N",
                                       "post_puncture_force_N",
                                       "puncture_criterion",
                                       "puncture_at_first_contact",
                                       "target_depth_m",
                                       "reaches_target_depth",
                                       "peak_force_N",
                                       "force_at_depth_N",
                                       "capacity_N",
                                       "governing",
                                       "margin",
                                       "passes",
                                       "material",
                                       "fidelity",
                                       "model",
                                       "triangles",
                                       "volume_m3",
                                       "tip_length_m",
                                       "seconds",
                                       "error",
                                       "hash"};

std::string csv_header() {
  std::string header;
  for (const char* c : kCsvColumns) {
    if (!header.empty()) header += ',';
    header += c;
  }
  return header;
}

std::string csv_line(const json& j) {
  std::string line;
  for (const char* c : kCsvColumns) {
    if (!line.empty()) line += ',';
    line += csv_field(j, c);
  }
  return line;
}

// The CSV's first lines: one "# provenance: {...}" per run that wrote into the folder (the lines
// of provenance.jsonl, which the CLI appends before it screens; docs/cli.md, "Provenance"), then
// the header. mneedle's CSV reader and pandas' comment='#' skip them.
std::string csv_preamble(const fs::path& out) {
  std::string text;
  std::ifstream runs(out / "provenance.jsonl");
  for (std::string line; std::getline(runs, line);)
    if (!line.empty()) text += "# provenance: " + line + "\n";
  return text + csv_header() + "\n";
}

// results.jsonl is the record; results.csv its table. A run killed between writing a row's JSON
// line and its CSV line would leave the CSV one design short for good (the design is resumed
// from the JSON line and not written again), so --resume rewrites the CSV from the JSON lines,
// through a temporary file so that a kill during the rewrite loses nothing. Every later run into
// the folder rewrites it too, so that its preamble names every run whose rows it holds.
void rebuild_csv(const fs::path& out) {
  std::error_code error;
  if (!fs::exists(out / "results.jsonl", error)) return;
  require_regular_results(out / "results.jsonl");
  std::ifstream in(out / "results.jsonl");
  const fs::path temporary = out / "results.csv.partial";
  {
    std::ofstream csv(temporary, std::ios::trunc);
    csv << csv_preamble(out);
    // A design that failed for want of memory is evaluated again on --resume (its row then
    // follows): the table leaves such rows out and keeps the last row of each design.
    std::vector<json> rows;
    std::map<std::string, std::size_t> last;
    for (std::string line; std::getline(in, line);) {
      try {
        rows.push_back(json::parse(line));
      } catch (const json::exception&) {
        continue;  // a line that is not a row was not resumed either; the design is evaluated again
      }
      const std::string hash = rows.back().value("hash", "");
      if (!hash.empty()) last[hash] = rows.size() - 1;
    }
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const std::string hash = rows[k].value("hash", "");
      if (!hash.empty() && (last[hash] != k || rows[k].value("retry", false))) continue;
      try {
        csv << csv_line(rows[k]) << "\n";
      } catch (const json::exception&) {
      }
    }
    csv.flush();
    if (!csv) throw InputError((out / "results.csv").string() + ": cannot write results");
  }
  std::error_code renamed;
  fs::rename(temporary, out / "results.csv", renamed);
  if (renamed)
    throw InputError((out / "results.csv").string() + ": cannot replace it (" + renamed.message() +
                     ")");
}

}  // namespace

std::vector<DesignInput> collect_designs(const std::vector<fs::path>& inputs,
                                         double metres_per_unit) {
  std::vector<DesignInput> out;
  // A unit the file declares (mneedle's own STL header, `unit=um`) is its numbers' unit, as a
  // scene's STL needle reads it; --unit is for files that say none (a 1 um file read as mm
  // made a needle 1000 times too large).
  auto add_file = [&](const fs::path& p) {
    const auto declared = declared_length_unit(p);
    out.push_back({p.stem().string(),
                   p,
                   declared ? length_unit_scale(*declared) : metres_per_unit,
                   std::nullopt,
                   {}});
  };
  for (const auto& input : inputs) {
    if (!fs::exists(input)) throw InputError(input.string() + ": no such file or folder");
    if (fs::is_directory(input)) {
      std::vector<fs::path> files;
      for (const auto& entry : fs::directory_iterator(input))
        if (entry.is_regular_file() && is_mesh_file(entry.path())) files.push_back(entry.path());
      std::sort(files.begin(), files.end());
      for (const auto& f : files) add_file(f);
    } else if (lower_extension(input) == ".toml") {
      for (auto& d : read_design_list(input)) out.push_back(std::move(d));
    } else if (is_mesh_file(input)) {
      add_file(input);
    } else {
      throw InputError(input.string() +
                       ": not a mesh file (.stl .obj .ply .off) or design list (.toml)");
    }
  }
  if (out.empty()) {
    std::string names;
    for (const auto& input : inputs) names += (names.empty() ? "" : ", ") + input.string();
    throw InputError(
        "screen: no mesh files (.stl, .obj, .ply, .off) or design lists (.toml) found "
        "in " +
        names);
  }
  return out;
}

void check_screening_scene(const Scene& scene, const PluginRegistry& registry,
                           const ScreeningOptions& options) {
  // As every command that runs a scene checks it (docs/scene.md): its own needles are built and
  // placed although the designs replace them, so a scene `scene check` refuses is refused here.
  check_needle_placement(scene, prepare_needles(registry, scene));
  if (options.material) {
    // An unknown name would fail every row after its FE run: refused first, as in `optimize`.
    try {
      find_needle_material(*options.material, scene_needle_materials(scene));
    } catch (const InputError& e) {
      throw InputError(std::string("screen: needle material: ") + e.what());
    }
  }
}

ScreeningRow screening_error_row(const DesignInput& d, const std::string& message) {
  return error_row(d, message);
}

ScreeningRow screening_row_from_json(const std::string& line) {
  ScreeningRow row = row_from_json(line);
  row.resumed = false;
  return row;
}

ScreeningBatch::ScreeningBatch(const std::vector<DesignInput>& designs, const Scene& scene,
                               const fs::path& scene_file, const PluginRegistry& registry,
                               const ScreeningOptions& options,
                               std::function<void(const ScreeningRow&)> on_row, bool writes)
    : designs_(designs),
      scene_(scene),
      registry_(registry),
      options_(options),
      on_row_(writes ? std::move(on_row) : nullptr),
      scene_text_(read_bytes(scene_file)),
      scene_source_(scene_file.string()),
      scene_hash_(hex(fnv1a(scene_text_))),
      material_(design_material(scene, options.material)),
      rows_(designs.size()) {
  parse_fidelity(options.fidelity);  // bad names fail the run, not every row
  parse_pre_model(options.model);
  // Once, here: a mesh file's hash reads the whole file, which claim() must not do under its lock.
  hashes_.reserve(designs.size());
  for (std::size_t i = 0; i < designs.size(); ++i)
    hashes_.push_back(row_hash(designs[i], scene_hash_,
                               options.fidelity + "|" + options.model + "|axis=" + options.axis +
                                   (options.repair ? "|repair" : "") + uncertainty_key(options),
                               material_));
  if (!writes || !options.out) return;
  const fs::path& out = *options.out;
  if (options.resume) done_ = finished_rows(out / "results.jsonl");
  rebuild_csv(out);
  create_output_folder(out, "--out");
  const bool fresh_csv = !fs::exists(out / "results.csv");
  jsonl_.open(out / "results.jsonl", std::ios::app);
  csv_.open(out / "results.csv", std::ios::app);
  // Name the file that cannot be opened (a folder of its name, no permission).
  if (!jsonl_) throw InputError((out / "results.jsonl").string() + ": cannot write results");
  if (!csv_) throw InputError((out / "results.csv").string() + ": cannot write results");
  if (fresh_csv) csv_ << csv_preamble(out) << std::flush;
}

ScreeningBatch::~ScreeningBatch() = default;

std::string ScreeningBatch::uncertainty_key(const ScreeningOptions& o) {
  if (o.vary.empty()) return "";
  std::string key = "|uncertainty=" + std::to_string(o.uncertainty.samples) + "," +
                    std::to_string(o.uncertainty.seed) + "," +
                    (o.uncertainty.latin_hypercube ? "lhs" : "mc");
  for (const auto& v : o.vary) key += "," + v.text;
  return key;
}

std::string ScreeningBatch::fingerprint() const {
  std::string all = std::to_string(designs_.size());
  for (const auto& h : hashes_) all += "|" + h;
  return hex(fnv1a(all));
}

bool ScreeningBatch::recorded(std::size_t i) {
  std::lock_guard<std::mutex> lock(record_mutex_);
  return !rows_[i].json.empty();
}

std::optional<std::size_t> ScreeningBatch::claim() {
  std::lock_guard<std::mutex> lock(claim_mutex_);
  while (next_ < designs_.size()) {
    const std::size_t i = next_++;
    if (!done_.empty()) {
      // A design that failed for want of memory is evaluated again (the limit may be gone).
      const auto previous = done_.find(hashes_[i]);
      if (previous != done_.end() && !previous->second.retry) {
        ScreeningRow row = previous->second;
        record(i, std::move(row));
        continue;
      }
    }
    {
      // Out of room for results: what is evaluated now would be lost, so nothing more is.
      std::lock_guard<std::mutex> record_lock(record_mutex_);
      if (!write_error_.empty()) {
        rows_[i] = error_row(designs_[i], "not evaluated: " + write_error_);
        continue;
      }
    }
    return i;
  }
  return std::nullopt;
}

ScreeningRow ScreeningBatch::evaluate(std::size_t i) const {
  // Nothing may escape (a worker thread would terminate the process): whatever fails becomes
  // this design's error row and the others go on.
  try {
    return evaluate_row(designs_[i], scene_, scene_text_, scene_source_, hashes_[i], material_,
                        registry_, options_);
  } catch (const std::exception& e) {
    return error_row(designs_[i], e.what());
  }
}

void ScreeningBatch::record(std::size_t i, ScreeningRow row) {
  std::lock_guard<std::mutex> lock(record_mutex_);
  try {
    if (!row.resumed && jsonl_.is_open()) {
      const std::string line = csv_line(json::parse(row.json));
      // Flushed per row: a run killed half-way keeps every finished design.
      jsonl_ << row.json << "\n" << std::flush;
      csv_ << line << "\n" << std::flush;
      if (!jsonl_ || !csv_) {
        write_error_ =
            "the results in --out could not be written (" + std::string(std::strerror(errno)) + ")";
        row = error_row(designs_[i], "evaluated, but " + write_error_ +
                                         "; rerun with --resume once there is room");
      }
    }
    if (on_row_) on_row_(row);
  } catch (const std::exception& e) {
    row = error_row(designs_[i], std::string("reporting the row failed: ") + e.what());
  }
  rows_[i] = std::move(row);
}

std::vector<ScreeningRow> ScreeningBatch::take_rows() {
  std::lock_guard<std::mutex> lock(record_mutex_);
  return std::move(rows_);
}

std::vector<ScreeningRow> screen_designs(const std::vector<DesignInput>& designs,
                                         const Scene& scene, const fs::path& scene_file,
                                         const PluginRegistry& registry,
                                         const ScreeningOptions& options,
                                         const std::function<void(const ScreeningRow&)>& on_row) {
  ScreeningBatch batch(designs, scene, scene_file, registry, options, on_row, true);
  auto worker = [&] {
    while (const auto i = batch.claim()) batch.record(*i, batch.evaluate(*i));
  };
  const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(designs.size())));
  // Each job factorises with CHOLMOD; OpenBLAS would start a thread per core in every one of them.
  std::optional<BlasThreadLimit> blas;
  if (jobs > 1) blas.emplace(1);
  std::vector<std::thread> pool;
  for (int j = 1; j < jobs; ++j) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return batch.take_rows();
}

std::vector<ScreeningRow> rank_rows(std::vector<ScreeningRow> rows) {
  std::stable_sort(rows.begin(), rows.end(), [](const ScreeningRow& a, const ScreeningRow& b) {
    if (a.ok != b.ok) return a.ok;
    if (!a.ok) return false;
    // --uncertainty: the probability of passing first, then the median puncture depth
    if (a.pass_probability && b.pass_probability) {
      if (*a.pass_probability != *b.pass_probability)
        return *a.pass_probability > *b.pass_probability;
      if (a.median_puncture_depth_m.has_value() != b.median_puncture_depth_m.has_value())
        return a.median_puncture_depth_m.has_value();
      if (a.median_puncture_depth_m && *a.median_puncture_depth_m != *b.median_puncture_depth_m)
        return *a.median_puncture_depth_m < *b.median_puncture_depth_m;
    }
    if (a.puncture_depth_m.has_value() != b.puncture_depth_m.has_value())
      return a.puncture_depth_m.has_value();
    // A depth that is only the first step's says nothing about the tip: after resolved ones.
    if (a.puncture_at_first_contact != b.puncture_at_first_contact)
      return !a.puncture_at_first_contact;
    // A depth that is only a lower bound (a flat end under the penetration criterion) after the
    // resolved ones too.
    if (a.puncture_lower_bound != b.puncture_lower_bound) return !a.puncture_lower_bound;
    if (a.puncture_depth_m && *a.puncture_depth_m != *b.puncture_depth_m)
      return *a.puncture_depth_m < *b.puncture_depth_m;
    if (a.puncture_force_n != b.puncture_force_n) return a.puncture_force_n < b.puncture_force_n;
    return a.peak_force_n < b.peak_force_n;
  });
  return rows;
}

nlohmann::json curve_json(const std::vector<CurveSample>& curve) {
  json points = json::array();
  for (const CurveSample& p : curve)
    points.push_back({{"depth_m", p.depth_m},
                      {"force_N", p.force_N},
                      {"stage", std::string(to_string(p.stage))}});
  return points;
}

}  // namespace mneedle
