#pragma once
// The needle mesh as a plain value type. CGAL stays inside .cpp files: this header is
// included everywhere and must stay cheap to compile.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace mneedle {

using Vec3 = std::array<double, 3>;
using Triangle = std::array<std::uint32_t, 3>;

/// A triangle mesh with shared vertices, coordinates in metres.
/// In the needle frame the tip is at the origin, the body along +z and insertion is toward -z.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;
};

struct BoundingBox {
  Vec3 min{};
  Vec3 max{};
};

BoundingBox bounding_box(const TriangleMesh& mesh);

/// Signed enclosed volume (divergence theorem); positive for a closed, outward-oriented mesh.
double signed_volume(const TriangleMesh& mesh);

double surface_area(const TriangleMesh& mesh);

/// SHA-256 (hex) of the mesh as it is in memory: its vertices (x, y, z as little-endian IEEE
/// doubles, metres) followed by its triangles (three little-endian uint32 each). Two meshes with
/// the same digest are the same needle to the last bit (docs/cli.md, "Provenance").
std::string mesh_sha256(const TriangleMesh& mesh);

}  // namespace mneedle
