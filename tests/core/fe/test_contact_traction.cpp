#include "fe/contact_traction.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <vector>

namespace {

using mneedle::fe::recover_traction;
using Points = std::vector<Eigen::Vector3d>;
using Faces = std::vector<std::array<int, 6>>;

// Two quadratic triangles over the square [0, L]^2 at z = 0 (corners, then mid-edges 01 12 20).
struct Patch {
  Points points;
  Faces faces;
};

Patch quadratic_square(double L) {
  Patch p;
  p.points = {{0, 0, 0},     {L, 0, 0},         {L, L, 0},     {0, L, 0},    {L / 2, 0, 0},
              {L, L / 2, 0}, {L / 2, L / 2, 0}, {L / 2, L, 0}, {0, L / 2, 0}};
  p.faces = {{0, 1, 2, 4, 5, 6}, {0, 2, 3, 6, 7, 8}};
  return p;
}

// The 6-node triangle's shape functions at barycentric (l0, l1, l2).
std::array<double, 6> t6(double l0, double l1, double l2) {
  return {l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
          4 * l0 * l1,       4 * l1 * l2,       4 * l2 * l0};
}

// Consistent nodal forces f_i = ∫ N_i t dA by a degree-4 rule (Dunavant 1985, 6 points), which
// integrates N_i times a linear t exactly: independent of the mass matrix under test.
Points nodal_forces(const Patch& p, const auto& traction) {
  static const std::array<std::array<double, 3>, 6> kPoints{
      {{0.108103018168070, 0.445948490915965, 0.445948490915965},
       {0.445948490915965, 0.108103018168070, 0.445948490915965},
       {0.445948490915965, 0.445948490915965, 0.108103018168070},
       {0.816847572980459, 0.091576213509771, 0.091576213509771},
       {0.091576213509771, 0.816847572980459, 0.091576213509771},
       {0.091576213509771, 0.091576213509771, 0.816847572980459}}};
  static const std::array<double, 6> kWeights{0.223381589678011, 0.223381589678011,
                                              0.223381589678011, 0.109951743655322,
                                              0.109951743655322, 0.109951743655322};
  Points f(p.points.size(), Eigen::Vector3d::Zero());
  for (const auto& face : p.faces) {
    const Eigen::Vector3d a = p.points[face[0]], b = p.points[face[1]], c = p.points[face[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    for (std::size_t q = 0; q < 6; ++q) {
      const auto& l = kPoints[q];
      const Eigen::Vector3d x = l[0] * a + l[1] * b + l[2] * c;
      const auto n = t6(l[0], l[1], l[2]);
      for (int i = 0; i < 6; ++i) f[face[i]] += kWeights[q] * area * n[i] * traction(x);
    }
  }
  return f;
}

// A traction the shape functions represent (linear in x and y) comes back exactly at the
// nodes: the mass matrix is the one the consistent forces were integrated with.
TEST(ContactTraction, LinearTractionOnQuadraticFacesIsRecoveredExactly) {
  const double L = 2e-4;
  const Patch p = quadratic_square(L);
  auto t = [&](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(1e3 * x.y() / L, -2e3, -5e4 * (1.0 + x.x() / L - 0.5 * x.y() / L));
  };
  const Points recovered = recover_traction(p.points, p.faces, 6, nodal_forces(p, t));
  for (std::size_t i = 0; i < p.points.size(); ++i)
    EXPECT_LT((recovered[i] - t(p.points[i])).norm(), 1e-9 * 5e4) << "node " << i;
}

// Partition of unity: the recovered traction integrates to the sum of the nodal forces, for
// any forces (here a single nodal force at a midside node).
TEST(ContactTraction, RecoveredTractionCarriesTheWholeForce) {
  const double L = 1e-4;
  const Patch p = quadratic_square(L);
  Points force(p.points.size(), Eigen::Vector3d::Zero());
  force[6] = {0.0, 0.0, -1e-3};
  const Points t = recover_traction(p.points, p.faces, 6, force);
  // ∫ t_h dA = Σ_j t_j ∫ N_j dA: corners integrate to 0, mid-edges to A/3 on each face
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const auto& face : p.faces)
    for (int i = 3; i < 6; ++i) total += t[face[i]] * (0.5 * L * L) / 3.0;
  EXPECT_NEAR(total.z(), -1e-3, 1e-15);
}

TEST(ContactTraction, UniformPressureOnLinearFacesIsRecoveredExactly) {
  const double L = 1e-4;
  const Points points{{0, 0, 0}, {L, 0, 0}, {L, L, 0}, {0, L, 0}};
  const Faces faces{{0, 1, 2, -1, -1, -1}, {0, 2, 3, -1, -1, -1}};
  // a uniform traction's consistent forces: A/3 of each triangle to each of its corners
  const double third = 0.5 * L * L / 3.0, p = 2e4;
  Points force(4, Eigen::Vector3d::Zero());
  for (const auto& f : faces)
    for (int i = 0; i < 3; ++i) force[f[i]].z() -= p * third;
  const Points t = recover_traction(points, faces, 3, force);
  for (const auto& ti : t) EXPECT_NEAR(ti.z(), -p, 1e-9 * p);
  const Points normal = mneedle::fe::face_normals_at_points(points, points, faces, 3);
  for (const auto& n : normal) EXPECT_NEAR(n.z(), 1.0, 1e-15);
  // Turned 120 degrees about x (past vertical, as the wall under a sharp tip can be): the normal
  // turns with the face, (0, -sin 120, cos 120), instead of being flipped back towards +z.
  Points turned = points;
  for (auto& q : turned) q = Eigen::Vector3d(q.x(), -0.5 * q.y(), std::sqrt(0.75) * q.y());
  const Points after = mneedle::fe::face_normals_at_points(turned, points, faces, 3);
  EXPECT_NEAR(after[0].y(), -std::sqrt(0.75), 1e-12);
  EXPECT_NEAR(after[0].z(), -0.5, 1e-12);
}

TEST(ContactTraction, NoFacesGiveZeroEverywhere) {
  const Points t = recover_traction({{0, 0, 0}}, {}, 6, {{1, 2, 3}});
  EXPECT_EQ(t[0], Eigen::Vector3d::Zero());
}

}  // namespace
