#include "mneedle/needle/mesh_io.h"

#include <gtest/gtest.h>

#include <optional>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/needle/mesh.h"
#include "needle_shapes.h"

namespace {

using mneedle::InputError;
using mneedle::TriangleMesh;

constexpr double kMillimetre = 1e-3;
// The crafted pyramid: base 2 x 2 mm, height 3 mm, apex at (0.5, 0.25, 1) mm.
constexpr double kPyramidVolume = 4e-9;                            // m^3
const double kPyramidArea = (4.0 + 4.0 * std::sqrt(10.0)) * 1e-6;  // m^2

std::filesystem::path asset(const std::string& name) {
  return std::filesystem::path(MNEEDLE_TEST_ASSETS) / "meshes" / name;
}

std::string load_error(const std::filesystem::path& file) {
  try {
    mneedle::load_mesh(file, kMillimetre);
  } catch (const InputError& error) {
    return error.what();
  }
  return "(no error)";
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

void expect_pyramid(const TriangleMesh& mesh) {
  EXPECT_EQ(mesh.vertices.size(), 5u) << "vertices must be welded";
  EXPECT_EQ(mesh.triangles.size(), 6u);
  EXPECT_NEAR(mneedle::signed_volume(mesh), kPyramidVolume, 1e-6 * kPyramidVolume);
  EXPECT_NEAR(mneedle::surface_area(mesh), kPyramidArea, 1e-6 * kPyramidArea);
  const mneedle::BoundingBox box = mneedle::bounding_box(mesh);
  EXPECT_NEAR(box.min[2], 1e-3, 1e-12);
  EXPECT_NEAR(box.max[2], 4e-3, 1e-12);
}

std::filesystem::path temporary_file(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("mneedle_test_mesh_io_" +
          std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" + name);
}

TEST(MeshIo, AsciiStlLoadsWeldedInMetres) {
  expect_pyramid(mneedle::load_mesh(asset("pyramid_ascii.stl"), kMillimetre));
}

TEST(MeshIo, BinaryStlLoadsWeldedInMetres) {
  expect_pyramid(mneedle::load_mesh(asset("pyramid_binary.stl"), kMillimetre));
}

TEST(MeshIo, ObjQuadFacesAreTriangulated) {
  expect_pyramid(mneedle::load_mesh(asset("pyramid.obj"), kMillimetre));
}

TEST(MeshIo, AsciiPlyLoads) {
  expect_pyramid(mneedle::load_mesh(asset("pyramid_ascii.ply"), kMillimetre));
}

TEST(MeshIo, BinaryPlyLoads) {
  expect_pyramid(mneedle::load_mesh(asset("pyramid_binary.ply"), kMillimetre));
}

TEST(MeshIo, OffLoads) {
  expect_pyramid(mneedle::load_mesh(asset("pyramid.off"), kMillimetre));
}

TEST(MeshIo, UnitScaleMultipliesCoordinates) {
  const TriangleMesh in_um = mneedle::load_mesh(asset("pyramid_ascii.stl"), 1e-6);
  const TriangleMesh in_m = mneedle::load_mesh(asset("pyramid_ascii.stl"), 1.0);
  EXPECT_NEAR(mneedle::signed_volume(in_um), 4e-18, 4e-24);
  EXPECT_NEAR(mneedle::signed_volume(in_m), 4.0, 4e-6);
  EXPECT_NEAR(mneedle::bounding_box(in_um).max[2], 4e-6, 1e-15);
}

TEST(MeshIo, NonPositiveUnitScaleIsRejected) {
  EXPECT_THROW(mneedle::load_mesh(asset("pyramid_ascii.stl"), 0.0), InputError);
  EXPECT_THROW(mneedle::load_mesh(asset("pyramid_ascii.stl"), -1e-3), InputError);
  EXPECT_THROW(mneedle::load_mesh(asset("pyramid_ascii.stl"), NAN), InputError);
}

TEST(MeshIo, MissingFileIsNamed) {
  const std::string message = load_error(asset("no_such_file.stl"));
  EXPECT_TRUE(starts_with(message, asset("no_such_file.stl").string() + ": ")) << message;
  EXPECT_TRUE(contains(message, "file not found")) << message;
}

TEST(MeshIo, PlyFaceIndexOutOfRangeIsAnErrorNotACrash) {
  // assimp's post-processing read past the vertex list on these (SIGSEGV) before its own
  // validation step was switched on.
  for (const char* name :
       {"bad_index_ascii.ply", "negative_index_ascii.ply", "bad_index_binary.ply"}) {
    const std::string message = load_error(asset(name));
    EXPECT_TRUE(starts_with(message, asset(name).string() + ": ")) << message;
    EXPECT_TRUE(contains(message, "refers to vertex")) << message;
  }
}

TEST(MeshIo, OffFaceWithTooFewIndicesIsAnErrorInTheFilesTerms) {
  // assimp's validation says "aiMesh::mFaces[0].mIndices is nullptr": its own structures.
  const std::filesystem::path file = temporary_file("short_face.off");
  std::ofstream(file) << "OFF\n3 1 0\n0 0 0\n1 0 0\n";  // the face and a vertex missing
  const std::string message = load_error(file);
  std::filesystem::remove(file);
  EXPECT_TRUE(starts_with(message, file.string() + ": ")) << message;
  EXPECT_FALSE(contains(message, "aiMesh")) << message;
}

TEST(MeshIo, DeclaredUnitIsReadFromTheHeaderOrSolidLine) {
  const auto file = temporary_file("declared_unit.stl");
  mneedle::write_stl_binary(mneedle::load_mesh(asset("pyramid_binary.stl"), kMillimetre), file,
                            1e-6, "mneedle generate cone unit=um");
  EXPECT_EQ(mneedle::declared_length_unit(file), std::optional<std::string>("um"));
  EXPECT_NEAR(mneedle::bounding_box(mneedle::load_mesh(file, 1e-6)).max[2], 4e-3, 1e-9);
  std::filesystem::remove(file);
  EXPECT_EQ(mneedle::declared_length_unit(std::filesystem::path(MNEEDLE_TEST_ASSETS) / "scenes" /
                                          "tiny_needle.stl"),
            std::optional<std::string>("mm"));
  EXPECT_FALSE(mneedle::declared_length_unit(asset("pyramid_ascii.stl")).has_value());
}

TEST(MeshIo, ZeroByteFileIsEmpty) {
  const std::string message = load_error(asset("zero_bytes.stl"));
  EXPECT_TRUE(starts_with(message, asset("zero_bytes.stl").string() + ": ")) << message;
  EXPECT_TRUE(contains(message, "file is empty (0 bytes)")) << message;
}

TEST(MeshIo, SolidWithoutFacetsIsEmptyMesh) {
  const std::string message = load_error(asset("empty_solid.stl"));
  EXPECT_TRUE(starts_with(message, asset("empty_solid.stl").string() + ": ")) << message;
  EXPECT_TRUE(contains(message, "mesh is empty (no triangles)")) << message;
}

TEST(MeshIo, TruncatedBinaryStlReportsSizes) {
  const std::string message = load_error(asset("truncated_binary.stl"));
  EXPECT_TRUE(starts_with(message, asset("truncated_binary.stl").string() + ": ")) << message;
  EXPECT_TRUE(contains(message,
                       "truncated binary STL (header declares 6 triangles = 384 bytes, "
                       "file has 364 bytes)"))
      << message;
}

TEST(MeshIo, TextFileWithUnknownExtensionIsUnsupported) {
  const std::string message = load_error(asset("not_a_mesh.txt"));
  EXPECT_TRUE(starts_with(message, asset("not_a_mesh.txt").string() + ": ")) << message;
  EXPECT_TRUE(contains(message, "unsupported mesh format '.txt'")) << message;
}

TEST(MeshIo, TextFileNamedStlIsNotAMesh) {
  const std::string message = load_error(asset("not_a_mesh.stl"));
  EXPECT_TRUE(starts_with(message, asset("not_a_mesh.stl").string() + ": ")) << message;
  EXPECT_TRUE(contains(message, "not a mesh")) << message;
}

TEST(MeshIo, NanInAsciiStlIsReportedWithLine) {
  const std::string message = load_error(asset("nan_vertex_ascii.stl"));
  // The third vertex of the pyramid is first used in triangle 2 (lines 10-16), as vertex 2.
  EXPECT_TRUE(starts_with(message, asset("nan_vertex_ascii.stl").string() + ":")) << message;
  EXPECT_TRUE(contains(message, "non-finite coordinate 'nan'")) << message;
}

TEST(MeshIo, NanInBinaryStlIsReportedWithTriangle) {
  const std::string message = load_error(asset("nan_vertex_binary.stl"));
  EXPECT_TRUE(starts_with(message, asset("nan_vertex_binary.stl").string() + ": ")) << message;
  EXPECT_TRUE(contains(message, "1 non-finite vertex coordinate(s) (first in triangle 3)"))
      << message;
}

TEST(MeshIo, NanInObjIsReported) {
  const std::filesystem::path file = temporary_file("nan.obj");
  std::ofstream(file)
      << "v 0 0 0\nv 1 0 0\nv 0 NaN 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const std::string message = load_error(file);
  std::filesystem::remove(file);
  EXPECT_TRUE(contains(message, "nan.obj:3: non-finite coordinate 'NaN'")) << message;
}

TEST(MeshIo, OverflowingCoordinateIsReported) {
  const std::filesystem::path file = temporary_file("huge.obj");
  std::ofstream(file)
      << "v 0 0 0\nv 1e300 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const std::string message = load_error(file);
  std::filesystem::remove(file);
  EXPECT_TRUE(contains(message, "non-finite vertex coordinate")) << message;
}

TEST(MeshIo, WriteThenReadRoundTripsTheMesh) {
  const TriangleMesh original = mneedle::load_mesh(asset("pyramid_ascii.stl"), kMillimetre);
  const std::filesystem::path file = temporary_file("round_trip.stl");
  mneedle::write_stl_binary(original, file, 1e-6);
  EXPECT_EQ(std::filesystem::file_size(file), 84u + 50u * original.triangles.size());
  const TriangleMesh read_back = mneedle::load_mesh(file, 1e-6);
  std::filesystem::remove(file);
  ASSERT_EQ(read_back.triangles.size(), original.triangles.size());
  ASSERT_EQ(read_back.vertices.size(), original.vertices.size());
  for (std::size_t t = 0; t < original.triangles.size(); ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      const mneedle::Vec3& a = original.vertices[original.triangles[t][corner]];
      const mneedle::Vec3& b = read_back.vertices[read_back.triangles[t][corner]];
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-6 * 4e-3);  // float precision
    }
  }
  EXPECT_NEAR(mneedle::signed_volume(read_back), kPyramidVolume, 1e-6 * kPyramidVolume);
}

TEST(MeshIo, VerticesMicrometresApartStayApartInAFileInMetres) {
  // A 2 um-radius, 64-sided cylinder (vertices 0.2 um apart) written in metres: assimp's own
  // vertex join used an absolute 1e-5 file units, 10 um here, and fused the ring into a
  // non-manifold knot. The weld must be exact, whatever the file's unit.
  mneedle::test::ShapeOptions o;
  o.radius = 2e-6;
  o.length = 20e-6;
  const TriangleMesh original = mneedle::test::cylinder(o);
  for (double unit : {1.0, 1e-3, 1e-6}) {
    const std::filesystem::path file = temporary_file("tiny_cylinder.stl");
    mneedle::write_stl_binary(original, file, unit);
    const TriangleMesh read_back = mneedle::load_mesh(file, unit);
    std::filesystem::remove(file);
    EXPECT_EQ(read_back.vertices.size(), original.vertices.size()) << unit;
    EXPECT_EQ(read_back.triangles.size(), original.triangles.size()) << unit;
    // float32 coordinates: the volume to 1e-6 relative (a few ulps of 2^-24 per coordinate).
    EXPECT_NEAR(mneedle::signed_volume(read_back), mneedle::signed_volume(original),
                1e-6 * mneedle::signed_volume(original))
        << unit;
  }
}

TEST(MeshIo, HeaderStartingWithSolidIsAltered) {
  const TriangleMesh original = mneedle::load_mesh(asset("pyramid_binary.stl"), kMillimetre);
  const std::filesystem::path file = temporary_file("solid_header.stl");
  mneedle::write_stl_binary(original, file, kMillimetre, "solid by name");
  std::ifstream in(file, std::ios::binary);
  std::string start(5, '\0');
  in.read(start.data(), 5);
  EXPECT_NE(start, "solid");
  expect_pyramid(mneedle::load_mesh(file, kMillimetre));
  std::filesystem::remove(file);
}

TEST(MeshIo, UnwritablePathIsNamed) {
  const TriangleMesh original = mneedle::load_mesh(asset("pyramid_binary.stl"), kMillimetre);
  const std::filesystem::path file = asset("no_such_dir/out.stl");
  EXPECT_THROW(mneedle::write_stl_binary(original, file, kMillimetre), InputError);
}

}  // namespace
