// Tests the private TriangleMesh <-> CGAL::Surface_mesh bridge (core/src/cgal_mesh.h).
#include "needle/cgal_mesh.h"

#include <gtest/gtest.h>

#include "mneedle/base/error.h"

namespace {

using mneedle::TriangleMesh;

TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

TEST(CgalMesh, ConversionKeepsVertexAndFaceIndices) {
  const TriangleMesh mesh = tetrahedron();
  const mneedle::SurfaceMesh surface = mneedle::to_surface_mesh(mesh);
  ASSERT_EQ(surface.number_of_vertices(), 4u);
  ASSERT_EQ(surface.number_of_faces(), 4u);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const mneedle::CgalPoint& p = surface.point(
        mneedle::SurfaceMesh::Vertex_index(static_cast<mneedle::SurfaceMesh::size_type>(i)));
    EXPECT_EQ(p.x(), mesh.vertices[i][0]);
    EXPECT_EQ(p.y(), mesh.vertices[i][1]);
    EXPECT_EQ(p.z(), mesh.vertices[i][2]);
  }
}

TEST(CgalMesh, RoundTripReturnsTheSameMesh) {
  const TriangleMesh mesh = tetrahedron();
  const TriangleMesh back = mneedle::from_surface_mesh(mneedle::to_surface_mesh(mesh));
  EXPECT_EQ(back.vertices, mesh.vertices);
  ASSERT_EQ(back.triangles.size(), mesh.triangles.size());
  EXPECT_NEAR(mneedle::signed_volume(back), 1.0 / 6.0, 1e-15);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    // Same cyclic order: the face may start at another corner.
    const auto& a = mesh.triangles[f];
    const auto& b = back.triangles[f];
    const bool same = (a == b) || (a == mneedle::Triangle{b[1], b[2], b[0]}) ||
                      (a == mneedle::Triangle{b[2], b[0], b[1]});
    EXPECT_TRUE(same) << "face " << f;
  }
}

TEST(CgalMesh, InconsistentOrientationCannotBeConverted) {
  TriangleMesh mesh = tetrahedron();
  std::swap(mesh.triangles[0][1], mesh.triangles[0][2]);
  EXPECT_FALSE(mneedle::is_halfedge_representable(mesh));
  EXPECT_THROW(mneedle::to_surface_mesh(mesh), mneedle::InputError);
}

TEST(CgalMesh, OutOfRangeIndexIsNotRepresentable) {
  TriangleMesh mesh = tetrahedron();
  mesh.triangles[3][2] = 9;
  EXPECT_FALSE(mneedle::is_halfedge_representable(mesh));
}

}  // namespace
