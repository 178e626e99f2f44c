#include "plugin_glue.h"

#include <gtest/gtest.h>

#include <new>
#include <stdexcept>
#include <string>
#include <vector>

namespace mneedle::shape_kit {
namespace {

TEST(ShapeKitPluginGlue, ExceptionsBecomeStatusesAndMessages) {
  char message[64] = "";
  EXPECT_EQ(guarded(message, sizeof message,
                    []() -> mneedle_status { throw ParameterError("bore too wide"); }),
            MNEEDLE_STATUS_INVALID_PARAMETER);
  EXPECT_STREQ(message, "bore too wide");
  EXPECT_EQ(guarded(message, sizeof message, []() -> mneedle_status { throw std::bad_alloc(); }),
            MNEEDLE_STATUS_OUT_OF_MEMORY);
  EXPECT_EQ(guarded(message, sizeof message, []() -> mneedle_status { throw 42; }),
            MNEEDLE_STATUS_INTERNAL_ERROR);
  EXPECT_STREQ(message, "unknown error");
}

TEST(ShapeKitPluginGlue, MessagesAreTruncatedToTheBuffer) {
  char message[5];
  write_message(message, sizeof message, "a long message");
  EXPECT_STREQ(message, "a lo");
}

TEST(ShapeKitPluginGlue, TubeParametersRefuseABoreAsWideAsTheDiameter) {
  const double ok[] = {230e-6, 1e-3, 90e-6, 64};
  EXPECT_DOUBLE_EQ(read_tube_parameters(ok).bore_radius_m, 45e-6);
  const double bad[] = {230e-6, 1e-3, 230e-6, 64};
  EXPECT_THROW(read_tube_parameters(bad), ParameterError);
}

struct Buffers {
  std::vector<double> vertices;
  std::vector<std::uint32_t> triangles;
};

mneedle_status allocate(mneedle_mesh_sink* sink, std::size_t nv, std::size_t nt) {
  auto* b = static_cast<Buffers*>(sink->host_data);
  b->vertices.resize(3 * nv);
  b->triangles.resize(3 * nt);
  sink->vertices = b->vertices.data();
  sink->triangles = b->triangles.data();
  return MNEEDLE_STATUS_OK;
}

TEST(ShapeKitPluginGlue, EmitMeshFillsTheHostBuffers) {
  MeshBuilder mesh(1e-9);
  mesh.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  Buffers buffers;
  mneedle_mesh_sink sink{&buffers, allocate, nullptr, nullptr};
  ASSERT_EQ(emit_mesh(mesh, &sink), MNEEDLE_STATUS_OK);
  EXPECT_EQ(buffers.vertices, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  EXPECT_EQ(buffers.triangles, (std::vector<std::uint32_t>{0, 1, 2}));
}

}  // namespace
}  // namespace mneedle::shape_kit
