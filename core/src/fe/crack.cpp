#include "mneedle/fe/crack.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unordered_map>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle::fe {

namespace {

constexpr int kEdgeNodes[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};

int local_edge(int a, int b) {
  for (int e = 0; e < 6; ++e)
    if ((kEdgeNodes[e][0] == a && kEdgeNodes[e][1] == b) ||
        (kEdgeNodes[e][0] == b && kEdgeNodes[e][1] == a))
      return e;
  return -1;
}

// The face of `element` opposite corner `opposite`: 3 corners, then (order 2) the midside nodes
// of the edges (c0 c1), (c1 c2), (c2 c0).
std::array<int, 6> face_nodes(const std::array<int, 10>& element, int opposite, int order) {
  std::array<int, 3> local{};
  int n = 0;
  for (int i = 0; i < 4; ++i)
    if (i != opposite) local[static_cast<std::size_t>(n++)] = i;
  std::array<int, 6> face{};
  face.fill(-1);
  for (int i = 0; i < 3; ++i) face[static_cast<std::size_t>(i)] = element[local[i]];
  if (order == 2)
    for (int i = 0; i < 3; ++i)
      face[static_cast<std::size_t>(3 + i)] =
          element[static_cast<std::size_t>(4 + local_edge(local[i], local[(i + 1) % 3]))];
  return face;
}

std::uint64_t sorted_key(std::array<int, 3> f) {
  std::sort(f.begin(), f.end());
  return (static_cast<std::uint64_t>(f[0]) << 42) | (static_cast<std::uint64_t>(f[1]) << 21) |
         static_cast<std::uint64_t>(f[2]);
}

std::array<int, 3> corners_of(const std::array<int, 6>& face) {
  return {face[0], face[1], face[2]};
}
std::array<int, 3> midsides_of(const std::array<int, 6>& face) {
  return {face[3], face[4], face[5]};
}

// Faces match only when every node matches: a quadratic face whose corners are shared but whose
// midside node was doubled is open.
void link_neighbours(TetMesh& mesh) {
  std::unordered_map<std::uint64_t, int> open_faces;
  open_faces.reserve(mesh.elements.size() * 2);
  mesh.neighbours.assign(mesh.elements.size(), {-1, -1, -1, -1});
  for (std::size_t t = 0; t < mesh.elements.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::array<int, 6> face = face_nodes(mesh.elements[t], f, mesh.order);
      const std::uint64_t key = sorted_key(corners_of(face));
      auto it = open_faces.find(key);
      if (it == open_faces.end()) {
        open_faces.emplace(key, static_cast<int>(t) * 4 + f);
        continue;
      }
      const int other = it->second / 4, other_face = it->second % 4;
      open_faces.erase(it);
      if (mesh.order == 2) {
        const auto mine = face_nodes(mesh.elements[t], f, 2);
        const auto theirs =
            face_nodes(mesh.elements[static_cast<std::size_t>(other)], other_face, 2);
        if (sorted_key(midsides_of(mine)) != sorted_key(midsides_of(theirs))) continue;
      }
      mesh.neighbours[t][static_cast<std::size_t>(f)] = other;
      mesh.neighbours[static_cast<std::size_t>(other)][static_cast<std::size_t>(other_face)] =
          static_cast<int>(t);
    }
}

// Same rule as the generator: an unmatched face with every corner on z = 0.
void collect_top_faces(TetMesh& mesh) {
  mesh.top_faces.clear();
  for (std::size_t t = 0; t < mesh.elements.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      if (mesh.neighbours[t][static_cast<std::size_t>(f)] >= 0) continue;
      const std::array<int, 6> face = face_nodes(mesh.elements[t], f, mesh.order);
      if (std::all_of(face.begin(), face.begin() + 3, [&](int node) {
            return mesh.nodes[static_cast<std::size_t>(node)].z() == 0.0;
          }))
        mesh.top_faces.push_back(face);
    }
}

std::string describe(const PlanarCrack& crack) {
  char text[160];
  std::snprintf(text, sizeof text, "crack plane through (%g, %g, %g) m with normal (%g, %g, %g)",
                crack.origin_m.x(), crack.origin_m.y(), crack.origin_m.z(), crack.normal.x(),
                crack.normal.y(), crack.normal.z());
  return text;
}

void validate(const TetMesh& mesh, const PlanarCrack& crack, double tolerance) {
  const bool finite = crack.origin_m.allFinite() && crack.normal.allFinite();
  if (!finite || !(crack.depth_m > 0.0) || !std::isfinite(crack.depth_m))
    throw InputError("crack: depth must be positive and origin and normal finite");
  const double length = crack.normal.norm();
  if (!(length > 0.0) || std::abs(crack.normal.z()) > 1e-9 * length)
    throw InputError("crack: normal must be a non-zero horizontal vector (crack plane vertical)");
  if (std::abs(crack.origin_m.z()) > tolerance)
    throw InputError("crack: origin must lie on the undeformed surface z = 0");
  if (mesh.nodes.empty() || mesh.elements.empty()) throw InputError("crack: empty mesh");
}

struct PlaneFace {
  std::array<int, 6> nodes;
  bool in_crack = false;
};

// Every face lying in the plane (listed once) and whether its centroid is inside the half-disc.
std::vector<PlaneFace> plane_faces(const TetMesh& mesh, const std::vector<char>& on_plane,
                                   const PlanarCrack& crack, const Eigen::Vector3d& normal) {
  std::unordered_map<std::uint64_t, int> seen;
  std::vector<PlaneFace> faces;
  for (const auto& element : mesh.elements)
    for (int f = 0; f < 4; ++f) {
      const std::array<int, 6> face = face_nodes(element, f, mesh.order);
      if (!std::all_of(face.begin(), face.begin() + 3,
                       [&](int node) { return on_plane[static_cast<std::size_t>(node)] != 0; }))
        continue;
      if (!seen.emplace(sorted_key(corners_of(face)), static_cast<int>(faces.size())).second)
        continue;
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int i = 0; i < 3; ++i) centroid += mesh.nodes[static_cast<std::size_t>(face[i])] / 3.0;
      Eigen::Vector3d offset = centroid - crack.origin_m;
      offset -= normal * normal.dot(offset);
      faces.push_back({face, centroid.z() < 0.0 && offset.norm() < crack.depth_m});
    }
  return faces;
}

// Straddling elements near the crack mean the plane is not made of mesh faces there.
void require_grid_plane(const TetMesh& mesh, const std::vector<double>& distance, double tolerance,
                        const PlanarCrack& crack, const Eigen::Vector3d& normal) {
  for (const auto& element : mesh.elements) {
    bool above = false, below = false;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      const double d = distance[static_cast<std::size_t>(element[i])];
      above = above || d > tolerance;
      below = below || d < -tolerance;
      centroid += 0.25 * mesh.nodes[static_cast<std::size_t>(element[i])];
    }
    if (!above || !below) continue;
    Eigen::Vector3d offset = centroid - crack.origin_m;
    offset -= normal * normal.dot(offset);
    if (offset.norm() < crack.depth_m)
      throw InputError("crack: " + describe(crack) +
                       " is not a grid plane of the tissue mesh (elements straddle it); put the "
                       "needle axis on a grid line");
  }
}

}  // namespace

TetMesh crack_mesh(const TetMesh& mesh, const PlanarCrack& crack, double* area_m2,
                   std::vector<int>* original_node) {
  Eigen::Vector3d lo = mesh.nodes.empty() ? Eigen::Vector3d::Zero() : mesh.nodes.front();
  Eigen::Vector3d hi = lo;
  for (const auto& p : mesh.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double tolerance = 1e-9 * std::max((hi - lo).norm(), crack.depth_m);
  validate(mesh, crack, tolerance);
  const Eigen::Vector3d normal = crack.normal.normalized();

  std::vector<double> distance(mesh.nodes.size());
  std::vector<char> on_plane(mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    distance[n] = normal.dot(mesh.nodes[n] - crack.origin_m);
    on_plane[n] = std::abs(distance[n]) <= tolerance ? 1 : 0;
  }
  require_grid_plane(mesh, distance, tolerance, crack, normal);
  const std::vector<PlaneFace> faces = plane_faces(mesh, on_plane, crack, normal);

  // A node opens when every plane face around it is cracked: crack-front nodes (and midside
  // nodes of front edges) touch an intact plane face and stay shared; mouth nodes on z = 0 open.
  const int per_face = mesh.order == 2 ? 6 : 3;
  std::vector<int> plane_count(mesh.nodes.size(), 0), crack_count(mesh.nodes.size(), 0);
  for (const PlaneFace& face : faces)
    for (int i = 0; i < per_face; ++i) {
      const auto node = static_cast<std::size_t>(face.nodes[static_cast<std::size_t>(i)]);
      ++plane_count[node];
      if (face.in_crack) ++crack_count[node];
    }
  TetMesh cracked = mesh;
  std::vector<int> copy_of(mesh.nodes.size(), -1);
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (crack_count[n] == 0 || crack_count[n] != plane_count[n]) continue;
    copy_of[n] = static_cast<int>(cracked.nodes.size());
    cracked.nodes.push_back(mesh.nodes[n]);
    cracked.fixed.push_back(mesh.fixed[n]);
  }
  double area = 0.0;
  for (const PlaneFace& face : faces) {
    if (!face.in_crack) continue;
    const bool opens =
        std::any_of(face.nodes.begin(), face.nodes.begin() + per_face,
                    [&](int node) { return copy_of[static_cast<std::size_t>(node)] >= 0; });
    if (!opens) continue;
    const auto& a = mesh.nodes[static_cast<std::size_t>(face.nodes[0])];
    const auto& b = mesh.nodes[static_cast<std::size_t>(face.nodes[1])];
    const auto& c = mesh.nodes[static_cast<std::size_t>(face.nodes[2])];
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  if (area == 0.0)
    throw InputError("crack: no mesh face lies on the " + describe(crack) + " within depth " +
                     std::to_string(crack.depth_m) + " m (crack smaller than the elements there?)");

  // The elements on the positive side of the plane take the copies.
  const int per_element = mesh.nodes_per_element();
  for (auto& element : cracked.elements) {
    double side = 0.0;
    for (int i = 0; i < 4; ++i) side += distance[static_cast<std::size_t>(element[i])];
    if (side <= 0.0) continue;
    for (int a = 0; a < per_element; ++a) {
      const int copy = copy_of[static_cast<std::size_t>(element[static_cast<std::size_t>(a)])];
      if (copy >= 0) element[static_cast<std::size_t>(a)] = copy;
    }
  }
  link_neighbours(cracked);
  collect_top_faces(cracked);
  if (area_m2) *area_m2 = area;
  if (original_node) {
    original_node->resize(cracked.nodes.size());
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
      (*original_node)[n] = static_cast<int>(n);
      if (copy_of[n] >= 0)
        (*original_node)[static_cast<std::size_t>(copy_of[n])] = static_cast<int>(n);
    }
  }
  return cracked;
}

Eigen::Vector3d crack_origin_under(const TetMesh& mesh, const Eigen::Vector2d& axis_m,
                                   const Eigen::Vector2d& tip_m) {
  const bool grid_plane = std::any_of(mesh.nodes.begin(), mesh.nodes.end(),
                                      [&](const Eigen::Vector3d& p) { return p.x() == tip_m.x(); });
  return {grid_plane ? tip_m.x() : axis_m.x(), axis_m.y(), 0.0};
}

}  // namespace mneedle::fe
