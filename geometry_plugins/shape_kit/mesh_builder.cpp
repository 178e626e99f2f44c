#include <charconv>
#include <cmath>
#include <cstdio>

#include "shape_kit.h"

namespace mneedle::shape_kit {

namespace {

Point3 minus(Point3 a, Point3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}

Point3 cross(Point3 a, Point3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

double norm(Point3 a) {
  return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
}

}  // namespace

MeshBuilder::MeshBuilder(double weld_tolerance_m) : tolerance_(weld_tolerance_m) {
  if (!(weld_tolerance_m > 0)) throw std::invalid_argument("weld tolerance must be positive");
}

MeshBuilder::Key MeshBuilder::key_of(Point3 p) const {
  return {std::llround(p.x / tolerance_), std::llround(p.y / tolerance_),
          std::llround(p.z / tolerance_)};
}

std::uint32_t MeshBuilder::vertex(Point3 p) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    throw std::runtime_error("non-finite vertex coordinate");
  }
  const auto [kx, ky, kz] = key_of(p);
  // Two copies of one point may round into neighbouring cells: look around.
  for (long long dx = -1; dx <= 1; ++dx) {
    for (long long dy = -1; dy <= 1; ++dy) {
      for (long long dz = -1; dz <= 1; ++dz) {
        const auto found = index_.find({kx + dx, ky + dy, kz + dz});
        if (found != index_.end() && norm(minus(vertices_[found->second], p)) <= tolerance_) {
          return found->second;
        }
      }
    }
  }
  const auto id = static_cast<std::uint32_t>(vertices_.size());
  vertices_.push_back(p);
  index_.emplace(Key{kx, ky, kz}, id);
  return id;
}

void MeshBuilder::add_triangle(Point3 a, Point3 b, Point3 c) {
  const std::uint32_t ia = vertex(a), ib = vertex(b), ic = vertex(c);
  if (ia == ib || ib == ic || ia == ic) return;
  const Point3 &pa = vertices_[ia], &pb = vertices_[ib], &pc = vertices_[ic];
  const double twice_area = norm(cross(minus(pb, pa), minus(pc, pa)));
  if (twice_area <= tolerance_ * tolerance_) return;
  triangles_.push_back({ia, ib, ic});
}

void MeshBuilder::add_convex_polygon(const std::vector<Point3>& polygon) {
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    add_triangle(polygon[0], polygon[i], polygon[i + 1]);
  }
}

void MeshBuilder::flip() {
  for (auto& t : triangles_) std::swap(t[1], t[2]);
}

double MeshBuilder::signed_volume() const {
  double six_volume = 0;
  for (const auto& t : triangles_) {
    const Point3 &a = vertices_[t[0]], &b = vertices_[t[1]], &c = vertices_[t[2]];
    const Point3 bc = cross(b, c);
    six_volume += a.x * bc.x + a.y * bc.y + a.z * bc.z;
  }
  return six_volume / 6.0;
}

int segment_count(double value) {
  if (!std::isfinite(value) || value != std::floor(value) || value < 3) {
    // The range (each shape's declared minimum, 8 for the built-in ones) is the host's check.
    // The shortest text that reads back as the value: a hair off a whole number shows.
    char got[32];
    const auto end = std::to_chars(got, got + sizeof got - 1, value).ptr;
    *end = '\0';
    throw ParameterError(std::string("resolution must be a whole number of segments, got ") + got);
  }
  return static_cast<int>(value);
}

}  // namespace mneedle::shape_kit
