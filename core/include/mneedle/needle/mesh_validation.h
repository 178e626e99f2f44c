#pragma once
// Checks that a needle mesh bounds a solid (closed, manifold, outward, not self-intersecting)
// and repairs the defects that can be repaired without guessing.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "mneedle/needle/mesh.h"

namespace mneedle {

struct MeshValidation {
  bool valid = false;
  /// One message per defect with its count, e.g. "mesh is not closed (12 border edges)".
  std::vector<std::string> errors;
  std::size_t non_finite_vertices = 0;
  std::size_t border_edges = 0;
  std::size_t non_manifold_edges = 0;     ///< edges shared by more than two triangles
  std::size_t non_manifold_vertices = 0;  ///< vertices where separate fans of triangles meet
  std::size_t inconsistent_faces = 0;     ///< triangles oriented against their neighbours
  std::size_t self_intersections = 0;     ///< pairs of intersecting non-adjacent triangles
  std::size_t degenerate_faces = 0;       ///< zero-area triangles (collinear or repeated corners)
  std::size_t bodies = 0;  ///< separate solid pieces (outward shells sharing no vertex)
  bool outward = false;    ///< every shell bounds its volume with normals pointing out
  double volume_m3 = 0.0;  ///< signed volume; positive when outward
};

/// Runs every check; never throws for a bad mesh (the defects are in the result).
MeshValidation validate_mesh(const TriangleMesh& mesh);

struct RepairReport {
  /// What changed, e.g. "reoriented 3 faces"; empty when nothing needed changing.
  std::vector<std::string> changes;
};

/// Merges duplicate vertices, orients every shell outward, removes degenerate faces and
/// stitches border edges that coincide. Does not fill holes or resolve self-intersections:
/// validate the result to see whether the repair sufficed.
RepairReport repair_mesh(TriangleMesh& mesh);

/// Throws mneedle::InputError "<source_name>: <defect>[; <defect>...]" if the mesh is invalid.
void require_valid_mesh(const TriangleMesh& mesh, std::string_view source_name);

}  // namespace mneedle
