#include "mneedle/needle/mesh.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "mneedle/base/provenance.h"

namespace mneedle {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

}  // namespace

BoundingBox bounding_box(const TriangleMesh& mesh) {
  BoundingBox box;
  if (mesh.vertices.empty()) return box;
  const double inf = std::numeric_limits<double>::infinity();
  box.min = {inf, inf, inf};
  box.max = {-inf, -inf, -inf};
  for (const Vec3& p : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      box.min[k] = std::min(box.min[k], p[k]);
      box.max[k] = std::max(box.max[k], p[k]);
    }
  }
  return box;
}

double signed_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    six_v += dot(a, cross(b, c));
  }
  return six_v / 6.0;
}

double surface_area(const TriangleMesh& mesh) {
  double twice_area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3 n = cross(sub(mesh.vertices[t[1]], a), sub(mesh.vertices[t[2]], a));
    twice_area += std::sqrt(dot(n, n));
  }
  return twice_area / 2.0;
}

std::string mesh_sha256(const TriangleMesh& mesh) {
  static_assert(std::endian::native == std::endian::little, "the digest's bytes are little-endian");
  std::string bytes;
  bytes.reserve(mesh.vertices.size() * sizeof(Vec3) + mesh.triangles.size() * sizeof(Triangle));
  for (const Vec3& v : mesh.vertices)
    bytes.append(reinterpret_cast<const char*>(v.data()), sizeof(Vec3));
  for (const Triangle& t : mesh.triangles)
    bytes.append(reinterpret_cast<const char*>(t.data()), sizeof(Triangle));
  return sha256_hex(bytes);
}

}  // namespace mneedle
