#include "fe/field_output3d.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "fe/contact_traction.h"
#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

constexpr std::uint8_t kTriangle = 5, kTet4 = 10, kTet10 = 24;

VtuArray vector_array(const std::string& name, const std::vector<Eigen::Vector3d>& values) {
  VtuArray a{name, 3, {}, {}};
  a.float64.reserve(3 * values.size());
  for (const auto& v : values) a.float64.insert(a.float64.end(), {v.x(), v.y(), v.z()});
  return a;
}

VtuArray depth_array(double depth_m) {
  return {"depth_m", 1, {depth_m}, {}};
}

// A positive-volume ordering of the mirror image of a cell: swap corners 1 and 2 (and their
// mid-edges for TET10, VTK order 01 12 20 03 13 23).
std::vector<int> mirrored_order(std::uint8_t type) {
  if (type == kTet4) return {0, 2, 1, 3};
  if (type == kTet10) return {0, 2, 1, 3, 6, 5, 4, 7, 9, 8};
  if (type == kTriangle) return {0, 2, 1};
  throw SolverError("VTU reflection: cell type " + std::to_string(type) + " not supported");
}

}  // namespace

std::vector<std::int64_t> reflect_across(VtuFile& f, int axis, const std::string& plane_sum) {
  const std::size_t points = f.points_m.size();
  double extent = 0.0;
  for (const auto& p : f.points_m) extent = std::max(extent, std::abs(p[axis]));
  const double on_plane = 1e-12 * extent;  // the mesh generator puts plane nodes at exactly 0
  std::vector<std::int64_t> image(points);
  std::vector<char> plane(points, 0);
  for (std::size_t i = 0; i < points; ++i) {
    if (std::abs(f.points_m[i][axis]) <= on_plane) {
      plane[i] = 1;
      image[i] = static_cast<std::int64_t>(i);
      continue;
    }
    image[i] = static_cast<std::int64_t>(f.points_m.size());
    Eigen::Vector3d p = f.points_m[i];
    p[axis] = -p[axis];
    f.points_m.push_back(p);
  }
  for (VtuArray& a : f.point_data) {
    const bool sum = a.name == plane_sum;
    const auto c = static_cast<std::size_t>(a.components);
    auto& v = a.float64;
    if (!a.int32.empty()) continue;  // no integer point arrays are written
    for (std::size_t i = 0; i < points; ++i) {
      if (!plane[i]) {
        for (std::size_t k = 0; k < c; ++k) {
          const double copy = v[i * c + k];
          v.push_back(copy);
        }
        if (c == 3) v[v.size() - 3 + static_cast<std::size_t>(axis)] *= -1.0;
      } else if (c == 3) {
        if (sum)
          for (std::size_t k = 0; k < 3; ++k) v[i * 3 + k] *= 2.0;
        v[i * 3 + static_cast<std::size_t>(axis)] = 0.0;
      } else if (sum) {
        v[i] *= 2.0;
      }
    }
  }
  const std::size_t cells = f.types.size();
  for (std::size_t e = 0; e < cells; ++e) {
    const std::size_t begin = e == 0 ? 0 : static_cast<std::size_t>(f.offsets[e - 1]);
    for (int a : mirrored_order(f.types[e]))
      f.connectivity.push_back(
          image[static_cast<std::size_t>(f.connectivity[begin + static_cast<std::size_t>(a)])]);
    f.offsets.push_back(static_cast<std::int64_t>(f.connectivity.size()));
    f.types.push_back(f.types[e]);
  }
  for (VtuArray& a : f.cell_data) {
    // (a range of a vector may not be inserted into itself: copy first)
    if (a.int32.empty()) {
      const std::vector<double> copy = a.float64;
      a.float64.insert(a.float64.end(), copy.begin(), copy.end());
    } else {
      const std::vector<std::int32_t> copy = a.int32;
      a.int32.insert(a.int32.end(), copy.begin(), copy.end());
    }
  }
  return image;
}

VtuFile tissue_vtu(const TissueStep3d& s, double depth_m) {
  const TetMesh& mesh = *s.mesh;
  const std::size_t n = mesh.nodes.size();
  VtuFile f;
  f.points_m = mesh.nodes;
  const int npe = mesh.nodes_per_element();
  for (const auto& e : mesh.elements) {
    for (int a = 0; a < npe; ++a) f.connectivity.push_back(e[static_cast<std::size_t>(a)]);
    f.offsets.push_back(static_cast<std::int64_t>(f.connectivity.size()));
    f.types.push_back(npe == 4 ? kTet4 : kTet10);
  }
  std::vector<Eigen::Vector3d> u(n), force(n, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) u[i] = s.u.segment<3>(3 * static_cast<Eigen::Index>(i));
  // Contact faces: top faces with a node a needle touches. Their nodes' internal forces are the
  // needle's (a free node's is zero to the solver's tolerance).
  std::vector<std::array<int, 6>> faces;
  const int face_nodes = npe == 4 ? 3 : 6;
  for (const auto& face : mesh.top_faces) {
    bool touched = false;
    for (int a = 0; a < face_nodes; ++a)
      touched =
          touched || s.in_contact[static_cast<std::size_t>(face[static_cast<std::size_t>(a)])];
    if (!touched) continue;
    faces.push_back(face);
    for (int a = 0; a < face_nodes; ++a) {
      const auto node = static_cast<std::size_t>(face[static_cast<std::size_t>(a)]);
      force[node] = s.internal_force.segment<3>(3 * static_cast<Eigen::Index>(node));
    }
  }
  f.point_data = {vector_array("displacement_m", u), vector_array("contact_force_N", force)};

  VtuArray von_mises{"von_mises_Pa", 1, {}, {}}, principal{"principal_stress_Pa", 3, {}, {}};
  for (const Eigen::Matrix3d& sigma : s.stress) {
    const Eigen::Matrix3d deviator = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
    von_mises.float64.push_back(std::sqrt(1.5 * deviator.cwiseProduct(deviator).sum()));
    const Eigen::Vector3d values =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(sigma, Eigen::EigenvaluesOnly).eigenvalues();
    principal.float64.insert(principal.float64.end(), {values(2), values(1), values(0)});
  }
  VtuArray layer{"layer", 1, {}, {}};
  layer.int32.assign(mesh.element_layer.begin(), mesh.element_layer.end());
  f.cell_data = {von_mises, principal, {"energy_density_J_per_m3", 1, s.energy_density, {}}, layer};
  f.field_data = {depth_array(depth_m)};

  // The whole block first (the symmetry reaction on a mirror plane is not the needle's: the
  // reflection drops it), then the traction on the whole contact surface, so that it is the
  // full model's to round-off.
  auto reflect = [&](int axis) {
    const std::vector<std::int64_t> image = reflect_across(f, axis, "contact_force_N");
    const std::size_t count = faces.size();
    for (std::size_t k = 0; k < count; ++k) {
      std::array<int, 6> mirrored = faces[k];
      for (int a = 0; a < face_nodes; ++a)
        mirrored[static_cast<std::size_t>(a)] = static_cast<int>(
            image[static_cast<std::size_t>(faces[k][static_cast<std::size_t>(a)])]);
      faces.push_back(mirrored);
    }
  };
  if (mesh.mirror_y0) reflect(1);
  if (mesh.mirror_x0) reflect(0);
  const std::size_t whole = f.points_m.size();
  std::vector<Eigen::Vector3d> current(whole), whole_force(whole);
  const auto& uu = f.point_data[0].float64;
  const auto& ff = f.point_data[1].float64;
  for (std::size_t i = 0; i < whole; ++i) {
    current[i] = f.points_m[i] + Eigen::Vector3d(uu[3 * i], uu[3 * i + 1], uu[3 * i + 2]);
    whole_force[i] = Eigen::Vector3d(ff[3 * i], ff[3 * i + 1], ff[3 * i + 2]);
  }
  // A contact face crushed to no area leaves M singular: the file then carries no traction (zero),
  // rather than losing the whole run after its solve; the forces are still there.
  std::vector<Eigen::Vector3d> traction(whole, Eigen::Vector3d::Zero());
  try {
    traction = recover_traction(current, faces, face_nodes, whole_force);
  } catch (const SolverError&) {
  }
  const std::vector<Eigen::Vector3d> normal =
      face_normals_at_points(current, f.points_m, faces, face_nodes);
  std::vector<double> pressure(whole, 0.0);
  for (std::size_t i = 0; i < whole; ++i) pressure[i] = -traction[i].dot(normal[i]);
  f.point_data.push_back(vector_array("contact_traction_Pa", traction));
  f.point_data.push_back({"contact_pressure_Pa", 1, pressure, {}});
  return f;
}

VtuFile needles_vtu(const std::vector<Needle3d>& needles, double depth_m) {
  VtuFile f;
  VtuArray index{"needle", 1, {}, {}};
  for (std::size_t k = 0; k < needles.size(); ++k) {
    const Needle3d& needle = needles[k];
    const auto first = static_cast<std::int64_t>(f.points_m.size());
    for (const Vec3& v : needle.mesh.vertices)
      f.points_m.emplace_back(v[0] + needle.x, v[1] + needle.y, v[2] - depth_m);
    for (const Triangle& t : needle.mesh.triangles) {
      for (std::uint32_t node : t) f.connectivity.push_back(first + node);
      f.offsets.push_back(static_cast<std::int64_t>(f.connectivity.size()));
      f.types.push_back(kTriangle);
      index.int32.push_back(static_cast<std::int32_t>(k));
    }
  }
  f.cell_data = {index};
  f.field_data = {depth_array(depth_m)};
  return f;
}

}  // namespace mneedle::fe
