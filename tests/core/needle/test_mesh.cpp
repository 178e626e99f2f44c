#include "mneedle/needle/mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace {

// Unit cube, outward oriented, 12 triangles.
mneedle::TriangleMesh unit_cube() {
  mneedle::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return m;
}

TEST(Mesh, UnitCubeHasUnitVolumeAndSixUnitsOfArea) {
  const auto cube = unit_cube();
  EXPECT_NEAR(mneedle::signed_volume(cube), 1.0, 1e-12);
  EXPECT_NEAR(mneedle::surface_area(cube), 6.0, 1e-12);
}

TEST(Mesh, FlippedCubeHasNegativeVolume) {
  auto cube = unit_cube();
  for (auto& t : cube.triangles) std::swap(t[1], t[2]);
  EXPECT_NEAR(mneedle::signed_volume(cube), -1.0, 1e-12);
}

TEST(Mesh, BoundingBoxSpansTheVertices) {
  auto cube = unit_cube();
  cube.vertices[6] = {2.0, 3.0, 4.0};
  const auto box = mneedle::bounding_box(cube);
  EXPECT_DOUBLE_EQ(box.min[0], 0.0);
  EXPECT_DOUBLE_EQ(box.max[1], 3.0);
  EXPECT_DOUBLE_EQ(box.max[2], 4.0);
}

}  // namespace

namespace {

// The digest's byte layout (docs/cli.md, "Provenance"): the value below is Python's
// hashlib.sha256(struct.pack('<3d', *v) for each vertex + struct.pack('<3I', *t)).hexdigest().
TEST(MeshDigest, IsTheSha256OfLittleEndianVerticesThenTriangles) {
  mneedle::TriangleMesh m;
  m.vertices = {{0.0, 0.0, 0.0}, {1e-3, 0.0, 0.0}, {0.0, 2.5e-4, -3.0}};
  m.triangles = {{0, 1, 2}};
  EXPECT_EQ(mneedle::mesh_sha256(m),
            "a5ba9493457cb95f461bbd45b8c59c548cd9385ea460c7073e66282d959bc130");
}

TEST(MeshDigest, MovesWhenOneCoordinateMovesByOneBit) {
  auto cube = unit_cube();
  const std::string before = mneedle::mesh_sha256(cube);
  cube.vertices[6][2] = std::nextafter(1.0, 2.0);
  EXPECT_NE(mneedle::mesh_sha256(cube), before);
}

}  // namespace
