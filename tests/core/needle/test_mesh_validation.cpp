#include "mneedle/needle/mesh_validation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/mesh_io.h"

namespace {

using mneedle::MeshValidation;
using mneedle::TriangleMesh;

TriangleMesh load(const std::string& name) {
  return mneedle::load_mesh(std::filesystem::path(MNEEDLE_TEST_ASSETS) / "meshes" / name, 1e-3);
}

bool has_error(const MeshValidation& v, const std::string& message) {
  for (const std::string& e : v.errors) {
    if (e == message) return true;
  }
  return false;
}

std::string joined(const MeshValidation& v) {
  std::string all;
  for (const std::string& e : v.errors) all += e + " | ";
  return all;
}

// An axis-aligned box with outward triangles; `inward` reverses every triangle.
void add_box(TriangleMesh& mesh, const mneedle::Vec3& lo, const mneedle::Vec3& hi, bool inward) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.push_back(
        {(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]});
  }
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {1, 3, 7, 5}, {3, 2, 6, 7}, {2, 0, 4, 6}};
  for (const auto& q : quads) {
    mneedle::Triangle a{base + q[0], base + q[1], base + q[2]};
    mneedle::Triangle b{base + q[0], base + q[2], base + q[3]};
    if (inward) {
      std::swap(a[1], a[2]);
      std::swap(b[1], b[2]);
    }
    mesh.triangles.push_back(a);
    mesh.triangles.push_back(b);
  }
}

TEST(MeshValidation, ClosedOutwardPyramidIsValid) {
  const MeshValidation v = mneedle::validate_mesh(load("pyramid_binary.stl"));
  EXPECT_TRUE(v.valid) << joined(v);
  EXPECT_TRUE(v.errors.empty());
  EXPECT_TRUE(v.outward);
  EXPECT_NEAR(v.volume_m3, 4e-9, 4e-15);
  EXPECT_EQ(v.border_edges, 0u);
  EXPECT_EQ(v.self_intersections, 0u);
}

TEST(MeshValidation, BoxBuiltInCodeIsValid) {
  TriangleMesh box;
  add_box(box, {0, 0, 0}, {1, 2, 3}, false);
  const MeshValidation v = mneedle::validate_mesh(box);
  EXPECT_TRUE(v.valid) << joined(v);
  EXPECT_NEAR(v.volume_m3, 6.0, 1e-12);
}

TEST(MeshValidation, EmptyMeshIsReported) {
  const MeshValidation v = mneedle::validate_mesh(TriangleMesh{});
  EXPECT_FALSE(v.valid);
  EXPECT_TRUE(has_error(v, "mesh is empty (no triangles)")) << joined(v);
}

TEST(MeshValidation, NonFiniteVertexIsReported) {
  TriangleMesh box;
  add_box(box, {0, 0, 0}, {1, 1, 1}, false);
  box.vertices[3][1] = std::nan("");
  const MeshValidation v = mneedle::validate_mesh(box);
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.non_finite_vertices, 1u);
  EXPECT_TRUE(has_error(v, "mesh has 1 vertex with non-finite coordinates")) << joined(v);
}

TEST(MeshValidation, OpenBoxCountsBorderEdges) {
  const MeshValidation v = mneedle::validate_mesh(load("open_box.stl"));
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.border_edges, 4u);
  EXPECT_TRUE(has_error(v, "mesh is not closed (4 border edges)")) << joined(v);
}

TEST(MeshValidation, OneFlippedFaceIsCounted) {
  const MeshValidation v = mneedle::validate_mesh(load("one_flipped_face.stl"));
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.inconsistent_faces, 1u);
  EXPECT_EQ(v.border_edges, 0u);
  EXPECT_TRUE(has_error(v, "mesh is not consistently oriented (1 flipped face)")) << joined(v);
}

TEST(MeshValidation, AllFacesFlippedIsInward) {
  const MeshValidation v = mneedle::validate_mesh(load("all_flipped.stl"));
  EXPECT_FALSE(v.valid);
  EXPECT_FALSE(v.outward);
  EXPECT_EQ(v.inconsistent_faces, 0u);
  EXPECT_LT(v.volume_m3, 0.0);
  EXPECT_TRUE(has_error(v,
                        "mesh is inward-oriented (negative volume; `screen --repair` or `mneedle "
                        "inspect FILE --repair -o fixed.stl` reorients it)"))
      << joined(v);
}

TEST(MeshValidation, InterpenetratingBoxesSelfIntersect) {
  const MeshValidation v = mneedle::validate_mesh(load("self_intersecting.stl"));
  EXPECT_FALSE(v.valid);
  EXPECT_GT(v.self_intersections, 0u);
  EXPECT_EQ(v.border_edges, 0u);
  const std::string expected =
      "mesh self-intersects (" + std::to_string(v.self_intersections) + " intersecting face pairs)";
  EXPECT_TRUE(has_error(v, expected)) << joined(v);
}

TEST(MeshValidation, TouchingApexesMakeANonManifoldVertex) {
  const MeshValidation v = mneedle::validate_mesh(load("non_manifold_vertex.stl"));
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.non_manifold_vertices, 1u);
  EXPECT_TRUE(has_error(v, "mesh is not manifold (1 non-manifold vertex)")) << joined(v);
}

TEST(MeshValidation, EdgeSharedByThreeFacesIsNonManifold) {
  TriangleMesh fin;
  fin.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const MeshValidation v = mneedle::validate_mesh(fin);
  EXPECT_EQ(v.non_manifold_edges, 1u);
  EXPECT_TRUE(has_error(v, "mesh is not manifold (1 edge shared by more than two faces)"))
      << joined(v);
}

TEST(MeshValidation, ZeroAreaSliverIsDegenerate) {
  const MeshValidation v = mneedle::validate_mesh(load("degenerate_face.stl"));
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.degenerate_faces, 1u);
  EXPECT_EQ(v.border_edges, 0u);
  EXPECT_TRUE(has_error(v, "mesh has 1 degenerate (zero-area) face")) << joined(v);
}

TEST(MeshValidation, CavityFacingInwardBoundsAVolume) {
  TriangleMesh hollow;
  add_box(hollow, {0, 0, 0}, {3, 3, 3}, false);
  add_box(hollow, {1, 1, 1}, {2, 2, 2}, true);
  const MeshValidation v = mneedle::validate_mesh(hollow);
  EXPECT_TRUE(v.valid) << joined(v);
  EXPECT_NEAR(v.volume_m3, 26.0, 1e-12);
}

TEST(MeshValidation, CavityFacingOutwardIsInsideOut) {
  TriangleMesh hollow;
  add_box(hollow, {0, 0, 0}, {3, 3, 3}, false);
  add_box(hollow, {1, 1, 1}, {2, 2, 2}, false);
  const MeshValidation v = mneedle::validate_mesh(hollow);
  EXPECT_FALSE(v.valid);
  EXPECT_TRUE(has_error(v, "mesh does not bound a volume (a shell is inside out)")) << joined(v);
}

TEST(MeshValidation, TwoSeparateBodiesAreAnError) {
  // Two needles (or a needle and a stray part) in one file: which one is the needle is a guess.
  TriangleMesh two;
  add_box(two, {0, 0, 0}, {1, 1, 3}, false);
  add_box(two, {2, 0, 0}, {3, 1, 3}, false);
  const MeshValidation v = mneedle::validate_mesh(two);
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.bodies, 2u);
  EXPECT_TRUE(has_error(v,
                        "mesh holds 2 separate bodies; a needle file must hold one (export "
                        "the needle alone)"))
      << joined(v);
}

TEST(MeshValidation, CavityIsNotASecondBody) {
  TriangleMesh hollow;
  add_box(hollow, {0, 0, 0}, {3, 3, 3}, false);
  add_box(hollow, {1, 1, 1}, {2, 2, 2}, true);
  EXPECT_EQ(mneedle::validate_mesh(hollow).bodies, 1u);
}

TEST(MeshValidation, RequireValidMeshNamesSourceAndAllDefects) {
  try {
    mneedle::require_valid_mesh(load("open_box.stl"), "open_box.stl");
    FAIL() << "expected InputError";
  } catch (const mneedle::InputError& error) {
    EXPECT_EQ(std::string(error.what()), "open_box.stl: mesh is not closed (4 border edges)");
  }
  EXPECT_NO_THROW(mneedle::require_valid_mesh(load("pyramid_ascii.stl"), "pyramid_ascii.stl"));
}

TEST(MeshValidation, RequireValidMeshJoinsDefectsWithSemicolons) {
  TriangleMesh mesh = load("one_flipped_face.stl");
  mesh.triangles.pop_back();
  try {
    mneedle::require_valid_mesh(mesh, "x.stl");
    FAIL() << "expected InputError";
  } catch (const mneedle::InputError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind("x.stl: mesh is not closed (3 border edges); ", 0), 0u) << message;
  }
}

TEST(MeshRepair, ValidMeshIsLeftUntouched) {
  TriangleMesh mesh = load("pyramid_ascii.stl");
  const TriangleMesh before = mesh;
  const mneedle::RepairReport report = mneedle::repair_mesh(mesh);
  EXPECT_TRUE(report.changes.empty());
  EXPECT_EQ(mesh.vertices, before.vertices);
  EXPECT_EQ(mesh.triangles, before.triangles);
}

TEST(MeshRepair, AllFlippedMeshIsReorientedOutward) {
  TriangleMesh mesh = load("all_flipped.stl");
  const mneedle::RepairReport report = mneedle::repair_mesh(mesh);
  ASSERT_EQ(report.changes.size(), 1u);
  EXPECT_EQ(report.changes[0], "reoriented 6 faces");
  const MeshValidation v = mneedle::validate_mesh(mesh);
  EXPECT_TRUE(v.valid) << joined(v);
  EXPECT_NEAR(v.volume_m3, 4e-9, 4e-15);
}

TEST(MeshRepair, SingleFlippedFaceIsTurned) {
  TriangleMesh mesh = load("one_flipped_face.stl");
  const mneedle::RepairReport report = mneedle::repair_mesh(mesh);
  ASSERT_EQ(report.changes.size(), 1u);
  EXPECT_EQ(report.changes[0], "reoriented 1 face");
  const MeshValidation v = mneedle::validate_mesh(mesh);
  EXPECT_TRUE(v.valid) << joined(v);
  EXPECT_NEAR(v.volume_m3, 1e-9, 1e-15);
}

TEST(MeshRepair, DegenerateSliverIsCollapsed) {
  TriangleMesh mesh = load("degenerate_face.stl");
  const mneedle::RepairReport report = mneedle::repair_mesh(mesh);
  EXPECT_FALSE(report.changes.empty());
  const MeshValidation v = mneedle::validate_mesh(mesh);
  EXPECT_TRUE(v.valid) << joined(v);
  EXPECT_NEAR(v.volume_m3, 1e-9 / 6.0, 1e-15);  // the unit tetrahedron, in mm
}

TEST(MeshRepair, UnweldedSeamIsClosed) {
  TriangleMesh mesh = load("pyramid_ascii.stl");
  // Give one triangle its own copy of a corner: the seam opens until repair merges it.
  mesh.vertices.push_back(mesh.vertices[mesh.triangles[0][0]]);
  mesh.triangles[0][0] = static_cast<std::uint32_t>(mesh.vertices.size() - 1);
  ASSERT_GT(mneedle::validate_mesh(mesh).border_edges, 0u);
  const mneedle::RepairReport report = mneedle::repair_mesh(mesh);
  EXPECT_FALSE(report.changes.empty());
  const MeshValidation v = mneedle::validate_mesh(mesh);
  EXPECT_TRUE(v.valid) << joined(v);
}

TEST(MeshRepair, OpenMeshStaysInvalid) {
  TriangleMesh mesh = load("open_box.stl");
  mneedle::repair_mesh(mesh);
  const MeshValidation v = mneedle::validate_mesh(mesh);
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.border_edges, 4u);
}

TEST(MeshRepair, SelfIntersectionIsNotRepaired) {
  TriangleMesh mesh = load("self_intersecting.stl");
  mneedle::repair_mesh(mesh);
  EXPECT_GT(mneedle::validate_mesh(mesh).self_intersections, 0u);
}

}  // namespace
