#pragma once
// Reading needle meshes from CAD files and writing them back as binary STL.

#include <filesystem>
#include <optional>
#include <string_view>

#include "mneedle/needle/mesh.h"

namespace mneedle {

/// Loads a triangle mesh from STL (binary or ASCII), OBJ, PLY or OFF; polygons are
/// triangulated and vertices at identical positions welded. `metres_per_unit` is the length
/// of one file unit in metres (e.g. length_unit_scale("mm") = 1e-3): the result is in metres.
/// Throws mneedle::InputError, its message starting with the file name, for a missing or empty
/// file, an unsupported or unreadable format, a truncated binary STL, a non-finite coordinate or
/// a file without triangles. The mesh is not validated here: see validate_mesh.
TriangleMesh load_mesh(const std::filesystem::path& file, double metres_per_unit);

/// Writes a binary STL with coordinates divided by `metres_per_unit` (the file's unit).
/// `header` fills the 80-byte header (truncated; never starting with "solid", which readers
/// take for ASCII STL). Throws mneedle::InputError if the file cannot be written.
/// The length unit a mesh file declares for itself: "unit=um", "unit=mm" or "unit=m" in a binary
/// STL's 80-byte header or an ASCII STL's `solid` line (what `mneedle generate` writes). Empty
/// when the file says nothing (most CAD exports) or is not an STL.
std::optional<std::string> declared_length_unit(const std::filesystem::path& file);

void write_stl_binary(const TriangleMesh& mesh, const std::filesystem::path& file,
                      double metres_per_unit, std::string_view header = "mneedle");

}  // namespace mneedle
