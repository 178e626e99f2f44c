#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "shape_kit.h"

namespace mneedle::shape_kit {
namespace {

TEST(ShapeKitMeshBuilder, JoinsVerticesCloserThanTheTolerance) {
  MeshBuilder mesh(1e-9);
  mesh.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  mesh.add_triangle({1 + 1e-12, 0, 0}, {1, 1, 0}, {0, 1 - 1e-12, 0});
  EXPECT_EQ(mesh.vertices().size(), 4u);
  EXPECT_EQ(mesh.triangles().size(), 2u);
}

TEST(ShapeKitMeshBuilder, KeepsVerticesFartherApartThanTheTolerance) {
  MeshBuilder mesh(1e-9);
  EXPECT_NE(mesh.vertex({0, 0, 0}), mesh.vertex({1e-8, 0, 0}));
}

TEST(ShapeKitMeshBuilder, DropsTrianglesThatCollapse) {
  MeshBuilder mesh(1e-9);
  mesh.add_triangle({0, 0, 0}, {1, 0, 0}, {1e-12, 0, 0});  // two corners joined
  mesh.add_triangle({0, 0, 0}, {1, 0, 0}, {2, 0, 0});      // collinear
  EXPECT_TRUE(mesh.triangles().empty());
}

TEST(ShapeKitMeshBuilder, FanOfAConvexPolygonCoversItsArea) {
  MeshBuilder mesh(1e-9);
  mesh.add_convex_polygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1.5, 0}, {0, 1, 0}});
  EXPECT_EQ(mesh.triangles().size(), 3u);
}

TEST(ShapeKitMeshBuilder, SignedVolumeOfATetrahedronAndItsFlip) {
  MeshBuilder mesh(1e-9);
  const Point3 o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  mesh.add_triangle(o, y, x);
  mesh.add_triangle(o, x, z);
  mesh.add_triangle(o, z, y);
  mesh.add_triangle(x, y, z);
  EXPECT_NEAR(mesh.signed_volume(), 1.0 / 6, 1e-15);
  mesh.flip();
  EXPECT_NEAR(mesh.signed_volume(), -1.0 / 6, 1e-15);
}

TEST(ShapeKitMeshBuilder, RefusesNonFiniteCoordinates) {
  MeshBuilder mesh(1e-9);
  EXPECT_THROW(mesh.vertex({std::nan(""), 0, 0}), std::runtime_error);
}

TEST(ShapeKitMeshBuilder, SegmentCountMustBeAWholeNumber) {
  EXPECT_EQ(segment_count(64), 64);
  EXPECT_THROW(segment_count(64.5), ParameterError);
  // All the digits: a value a hair off a whole number was reported as that number ("got 64").
  try {
    segment_count(64.0000001);
    ADD_FAILURE() << "64.0000001 segments accepted";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("got 64.0000001"), std::string::npos) << e.what();
  }
  EXPECT_THROW(segment_count(2), ParameterError);
}

}  // namespace
}  // namespace mneedle::shape_kit
