// mneedle inspect FILE: load a needle mesh, validate (and optionally repair) it, and report
// its geometry and needle frame.

#include <CLI/CLI.hpp>

#include <charconv>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "commands.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/needle/mesh_validation.h"
#include "mneedle/needle/needle_frame.h"

#include "json_output.h"
#include "option_values.h"
#include "run_provenance.h"
#include "surface_report_json.h"

namespace mneedle::cli {
namespace {

struct InspectOptions {
  std::string file;
  std::string unit = "mm";
  std::string axis;
  std::string output;  // write the (repaired) mesh here, binary STL in --unit
  bool repair = false;
  bool json = false;
};

struct InspectResult {
  std::string file;
  std::string unit;
  TriangleMesh mesh;  // input coordinates, metres (after repair when asked)
  MeshValidation validation;
  RepairReport repair;
  std::optional<FrameInfo> frame;
  TriangleMesh framed;  // the mesh moved into the needle frame, for the surface analysis
};

AxisChoice parse_axis(const std::string& text) {
  if (text.empty()) return AxisChoice{};
  try {
    return parse_axis_choice(text);
  } catch (const InputError& e) {
    throw InputError(std::string("--axis: ") + e.what());
  }
}

bool frame_computable(const InspectResult& result) {
  return !result.mesh.triangles.empty() && result.validation.non_finite_vertices == 0;
}

InspectResult inspect(const InspectOptions& options) {
  InspectResult result;
  result.file = options.file;
  result.unit = options.unit;
  result.mesh = load_mesh(options.file, option_length_unit(options.unit));
  record_input("needle", options.file);
  if (options.repair) result.repair = repair_mesh(result.mesh);
  result.validation = validate_mesh(result.mesh);
  if (frame_computable(result))
    result.frame = find_needle_frame(result.mesh, parse_axis(options.axis));
  if (result.validation.valid) {
    result.framed = result.mesh;
    place_in_needle_frame(result.framed, parse_axis(options.axis));
  }
  return result;
}

// Adding +0.0 turns -0.0 into 0.0, which a reader of the report would take for a sign.
nlohmann::json vector_json(const Vec3& v) {
  return nlohmann::json::array({v[0] + 0.0, v[1] + 0.0, v[2] + 0.0});
}

// Geometry derived from the mesh; further per-mesh summaries belong here.
void add_geometry_fields(nlohmann::json& out, const InspectResult& result) {
  const BoundingBox box = bounding_box(result.mesh);
  out["bounding_box_m"] = {{"min", vector_json(box.min)}, {"max", vector_json(box.max)}};
  out["volume_m3"] = signed_volume(result.mesh);
  out["area_m2"] = surface_area(result.mesh);
  if (result.frame) {
    out["axis"] = vector_json(result.frame->axis);
    out["tip_m"] = vector_json(result.frame->tip);
    out["frame_note"] = result.frame->note;
    // Groups and tip areas need a closed, outward mesh in the needle frame.
    if (!result.framed.triangles.empty()) out.update(surface_report_json(result.framed));
  } else {
    out["axis"] = nullptr;
    out["tip_m"] = nullptr;
  }
}

nlohmann::json to_json(const InspectResult& result) {
  nlohmann::json out;
  out["file"] = result.file;
  out["unit"] = result.unit;
  out["valid"] = result.validation.valid;
  out["triangles"] = result.mesh.triangles.size();
  if (result.validation.non_finite_vertices == 0) add_geometry_fields(out, result);
  out["errors"] = result.validation.errors;
  out["repairs"] = result.repair.changes;
  return out;
}

std::string format_vector(const Vec3& v) {
  std::ostringstream out;
  out.precision(6);
  out << "(" << v[0] + 0.0 << ", " << v[1] + 0.0 << ", " << v[2] + 0.0 << ")";
  return out.str();
}

void print_text(const InspectResult& result, std::ostream& out) {
  const BoundingBox box = bounding_box(result.mesh);
  out.precision(6);
  out << result.file << " (unit " << result.unit << "): valid\n"
      << "  triangles:    " << result.mesh.triangles.size() << "\n"
      << "  bounding box: " << format_vector(box.min) << " to " << format_vector(box.max) << " m\n"
      << "  volume:       " << signed_volume(result.mesh) << " m^3\n"
      << "  surface area: " << surface_area(result.mesh) << " m^2\n";
  if (result.frame) {
    out << "  axis:         " << format_vector(result.frame->axis)
        << " (direction the tip points)\n"
        << "  tip:          " << format_vector(result.frame->tip) << " m\n"
        << "  frame:        " << result.frame->note << "\n";
  }
  for (const std::string& change : result.repair.changes)
    out << "  repaired:     " << change << "\n";
}

std::string defects_line(const InspectResult& result) {
  std::string line = result.file;
  for (std::size_t i = 0; i < result.validation.errors.size(); ++i) {
    line += (i == 0 ? ": " : "; ") + result.validation.errors[i];
  }
  if (!result.repair.changes.empty()) {
    line += " (still invalid after repair, which ";
    for (std::size_t i = 0; i < result.repair.changes.size(); ++i) {
      line += (i == 0 ? "" : ", ") + result.repair.changes[i];
    }
    line += ")";
  }
  return line;
}

void run_inspect(const InspectOptions& options) {
  InspectResult result;
  try {
    result = inspect(options);
  } catch (const InputError& error) {
    if (options.json) {
      const nlohmann::json out = {{"file", options.file},
                                  {"unit", options.unit},
                                  {"valid", false},
                                  {"errors", {error.what()}},
                                  {"repairs", nlohmann::json::array()}};
      std::cout << with_provenance(out).dump(2) << "\n";
    }
    throw;
  }
  // The text report prints numbers of the same tree: one check covers both formats.
  const nlohmann::json tree = to_json(result);
  require_finite_json(tree, "inspect " + options.file);
  if (options.json) std::cout << with_provenance(tree).dump(2) << "\n";
  if (!result.validation.valid) throw InputError(defects_line(result));
  if (!options.output.empty()) {
    // Input coordinates and unit, with the unit in the header so loaders read it back.
    write_stl_binary(result.mesh, options.output, option_length_unit(options.unit),
                     "mneedle inspect unit=" + options.unit);
    if (!options.json) {
      std::cout << "wrote " << options.output << " (" << result.mesh.triangles.size()
                << " triangles, unit " << options.unit << ")\n";
    }
  }
  if (!options.json) print_text(result, std::cout);
}

}  // namespace

void add_inspect_command(CLI::App& app) {
  auto options = std::make_shared<InspectOptions>();
  CLI::App* command = app.add_subcommand(
      "inspect", "Validate a needle mesh and report its size, volume, area, axis and tip");
  command->add_option("file", options->file, "Mesh file: STL (binary or ASCII), OBJ, PLY or OFF")
      ->required();
  command->add_option("--unit", options->unit, "Length unit of the file: um, mm or m")
      ->capture_default_str();
  command->add_flag("--repair", options->repair,
                    "Orient outward, remove degenerate faces and stitch borders before checking");
  command->add_option("--axis", options->axis,
                      "Direction the tip points, x,y,z in file coordinates, or 'auto' for the "
                      "principal axis (default: the tip at the lowest z)");
  command->add_option("-o,--output", options->output,
                      "Write the mesh (repaired with --repair) as binary STL in --unit; only a "
                      "valid mesh is written");
  command->add_flag("--json", options->json, "Print one JSON object on stdout");
  command->footer(
      "Example:\n  mneedle inspect designs/sharp_bevel.stl --unit mm --json\n"
      "  mneedle inspect scan.stl --unit um --repair --axis auto -o fixed.stl");
  command->callback([options] { run_inspect(*options); });
}

}  // namespace mneedle::cli
