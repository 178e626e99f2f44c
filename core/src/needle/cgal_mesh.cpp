#include "needle/cgal_mesh.h"

#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <unordered_map>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

std::vector<std::vector<std::size_t>> to_polygon_soup(const TriangleMesh& mesh) {
  std::vector<std::vector<std::size_t>> polygons;
  polygons.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) polygons.push_back({t[0], t[1], t[2]});
  return polygons;
}

bool indices_in_range(const TriangleMesh& mesh) {
  for (const Triangle& t : mesh.triangles) {
    for (std::uint32_t v : t) {
      if (v >= mesh.vertices.size()) return false;
    }
  }
  return true;
}

}  // namespace

bool is_halfedge_representable(const TriangleMesh& mesh) {
  return indices_in_range(mesh) &&
         CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(to_polygon_soup(mesh));
}

SurfaceMesh to_surface_mesh(const TriangleMesh& mesh) {
  if (!is_halfedge_representable(mesh)) {
    throw InputError(
        "mesh is not a consistently oriented manifold: it cannot be converted to a surface mesh");
  }
  SurfaceMesh surface;
  surface.reserve(static_cast<SurfaceMesh::size_type>(mesh.vertices.size()),
                  static_cast<SurfaceMesh::size_type>(3 * mesh.triangles.size() / 2),
                  static_cast<SurfaceMesh::size_type>(mesh.triangles.size()));
  std::vector<SurfaceMesh::Vertex_index> vertex_of(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& p = mesh.vertices[i];
    vertex_of[i] = surface.add_vertex(CgalPoint(p[0], p[1], p[2]));
  }
  for (const Triangle& t : mesh.triangles) {
    // Euler::add_face relinks fans around a vertex, so any face order of a valid soup works.
    const std::array<SurfaceMesh::Vertex_index, 3> corners{vertex_of[t[0]], vertex_of[t[1]],
                                                           vertex_of[t[2]]};
    if (CGAL::Euler::add_face(corners, surface) == SurfaceMesh::null_face()) {
      throw InputError("mesh is not a manifold: a triangle could not be added to the surface mesh");
    }
  }
  return surface;
}

TriangleMesh from_surface_mesh(const SurfaceMesh& surface) {
  TriangleMesh mesh;
  std::unordered_map<SurfaceMesh::Vertex_index, std::uint32_t> index_of;
  index_of.reserve(surface.number_of_vertices());
  mesh.vertices.reserve(surface.number_of_vertices());
  for (SurfaceMesh::Vertex_index v : surface.vertices()) {
    const CgalPoint& p = surface.point(v);
    index_of.emplace(v, static_cast<std::uint32_t>(mesh.vertices.size()));
    mesh.vertices.push_back({p.x(), p.y(), p.z()});
  }
  mesh.triangles.reserve(surface.number_of_faces());
  for (SurfaceMesh::Face_index f : surface.faces()) {
    Triangle t{};
    std::size_t corner = 0;
    for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(surface.halfedge(f), surface)) {
      if (corner < 3) t[corner] = index_of.at(v);
      ++corner;
    }
    if (corner != 3) throw SolverError("surface mesh has a face that is not a triangle");
    mesh.triangles.push_back(t);
  }
  return mesh;
}

}  // namespace mneedle
