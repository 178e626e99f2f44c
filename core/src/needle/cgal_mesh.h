#pragma once
// PRIVATE to mneedle::core: the bridge between the public TriangleMesh value type and CGAL.
// Including this header pulls in CGAL (about 7 s of compile time): only the few .cpp files
// that run CGAL algorithms include it, never a public header.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "mneedle/needle/mesh.h"

namespace mneedle {

using CgalKernel = CGAL::Epick;
using CgalPoint = CgalKernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<CgalPoint>;

/// True when the triangles form a polygon mesh CGAL can hold in a halfedge structure:
/// manifold, consistently oriented, no triangle using a vertex twice.
bool is_halfedge_representable(const TriangleMesh& mesh);

/// Converts to a CGAL surface mesh. Vertex i of `mesh` becomes vertex index i (isolated
/// vertices included) and triangle f becomes face index f, so per-vertex and per-face data
/// can be indexed alike on both sides. Throws mneedle::InputError when the triangles are not
/// halfedge-representable (validate_mesh reports why in detail).
SurfaceMesh to_surface_mesh(const TriangleMesh& mesh);

/// Converts back; removed (garbage) elements are skipped and indices compacted.
TriangleMesh from_surface_mesh(const SurfaceMesh& surface);

}  // namespace mneedle
