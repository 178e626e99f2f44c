#include "fe/contact_traction.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

// ∫ N_i N_j dA / A on a flat triangle: linear, and quadratic with corners then mid-edges
// 0-1, 1-2, 2-0 (Zienkiewicz & Taylor, The Finite Element Method, vol. 1, the 6-node triangle).
Eigen::Matrix3d linear_mass() {
  Eigen::Matrix3d m;
  m << 2, 1, 1, 1, 2, 1, 1, 1, 2;
  return m / 12.0;
}

Eigen::Matrix<double, 6, 6> quadratic_mass() {
  Eigen::Matrix<double, 6, 6> m;
  m << 6, -1, -1, 0, -4, 0,  //
      -1, 6, -1, 0, 0, -4,   //
      -1, -1, 6, -4, 0, 0,   //
      0, 0, -4, 32, 16, 16,  //
      -4, 0, 0, 16, 32, 16,  //
      0, -4, 0, 16, 16, 32;
  return m / 180.0;
}

Eigen::Vector3d area_vector(const std::vector<Eigen::Vector3d>& p, const std::array<int, 6>& f) {
  const auto& a = p[static_cast<std::size_t>(f[0])];
  const auto& b = p[static_cast<std::size_t>(f[1])];
  const auto& c = p[static_cast<std::size_t>(f[2])];
  return 0.5 * (b - a).cross(c - a);
}

}  // namespace

std::vector<Eigen::Vector3d> recover_traction(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<std::array<int, 6>>& faces,
                                              int face_nodes,
                                              const std::vector<Eigen::Vector3d>& nodal_force) {
  std::vector<Eigen::Vector3d> traction(points.size(), Eigen::Vector3d::Zero());
  if (faces.empty()) return traction;
  // local numbering of the points that lie on a face
  std::vector<int> local(points.size(), -1);
  std::vector<int> global;
  for (const auto& f : faces)
    for (int a = 0; a < face_nodes; ++a) {
      int& l = local[static_cast<std::size_t>(f[static_cast<std::size_t>(a)])];
      if (l < 0) {
        l = static_cast<int>(global.size());
        global.push_back(f[static_cast<std::size_t>(a)]);
      }
    }
  const Eigen::MatrixXd unit =
      face_nodes == 3 ? Eigen::MatrixXd(linear_mass()) : Eigen::MatrixXd(quadratic_mass());
  std::vector<Eigen::Triplet<double>> entries;
  for (const auto& f : faces) {
    const double area = area_vector(points, f).norm();
    for (int a = 0; a < face_nodes; ++a)
      for (int b = 0; b < face_nodes; ++b)
        entries.emplace_back(local[static_cast<std::size_t>(f[static_cast<std::size_t>(a)])],
                             local[static_cast<std::size_t>(f[static_cast<std::size_t>(b)])],
                             area * unit(a, b));
  }
  const auto n = static_cast<Eigen::Index>(global.size());
  Eigen::SparseMatrix<double> mass(n, n);
  mass.setFromTriplets(entries.begin(), entries.end());
  Eigen::MatrixXd force(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    force.row(i) = nodal_force[static_cast<std::size_t>(global[static_cast<std::size_t>(i)])];
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(mass);
  if (solver.info() != Eigen::Success)
    throw SolverError("contact traction: the surface mass matrix is singular (a face of no area)");
  const Eigen::MatrixXd t = solver.solve(force);
  for (Eigen::Index i = 0; i < n; ++i)
    traction[static_cast<std::size_t>(global[static_cast<std::size_t>(i)])] = t.row(i).transpose();
  return traction;
}

std::vector<Eigen::Vector3d> face_normals_at_points(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<Eigen::Vector3d>& reference,
                                                    const std::vector<std::array<int, 6>>& faces,
                                                    int face_nodes) {
  std::vector<Eigen::Vector3d> normal(points.size(), Eigen::Vector3d::Zero());
  for (const auto& f : faces) {
    Eigen::Vector3d a = area_vector(points, f);
    if (area_vector(reference, f).z() < 0.0) a = -a;
    for (int i = 0; i < face_nodes; ++i)
      normal[static_cast<std::size_t>(f[static_cast<std::size_t>(i)])] += a;
  }
  for (auto& n : normal)
    if (n.norm() > 0.0) n.normalize();
  return normal;
}

}  // namespace mneedle::fe
