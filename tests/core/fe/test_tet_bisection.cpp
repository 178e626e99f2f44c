#include "fe/tet_bisection.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "mneedle/base/error.h"

namespace {

using mneedle::fe::TetBisection;

// n x n x n unit cells of the box [0, size]^3, each split into its six Kuhn tetrahedra (all with
// the same orientation: a consistently tagged start).
TetBisection kuhn_grid(int n, double size) {
  std::vector<Eigen::Vector3d> nodes;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) nodes.emplace_back(i, j, k);
  for (auto& p : nodes) p *= size / n;
  TetBisection mesh(std::move(nodes));
  auto node = [&](int i, int j, int k) { return i + (n + 1) * (j + (n + 1) * k); };
  constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                       {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& perm : kPermutations) {
          std::array<int, 3> step{};
          std::array<int, 4> path{node(i, j, k), 0, 0, node(i + 1, j + 1, k + 1)};
          for (int s = 1; s <= 2; ++s) {
            step[static_cast<std::size_t>(perm[s - 1])] = 1;
            path[static_cast<std::size_t>(s)] = node(i + step[0], j + step[1], k + step[2]);
          }
          mesh.add_kuhn_tet(path, 0);
        }
  return mesh;
}

double volume(const TetBisection& m, const std::array<int, 4>& t) {
  const auto& p = m.nodes();
  return std::abs((p[t[1]] - p[t[0]]).dot((p[t[2]] - p[t[0]]).cross(p[t[3]] - p[t[0]]))) / 6.0;
}

// Every face is either on the box's boundary or shared by exactly two tetrahedra: no hanging
// node, no overlap (with the volumes summing to the box).
void expect_conforming(const TetBisection& m, double size) {
  std::map<std::array<int, 3>, int> faces;
  double total = 0.0;
  for (const auto& t : m.tets()) {
    EXPECT_GT(volume(m, t), 1e-12 * size * size * size);
    total += volume(m, t);
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> face{};
      int n = 0;
      for (int i = 0; i < 4; ++i)
        if (i != f) face[static_cast<std::size_t>(n++)] = t[static_cast<std::size_t>(i)];
      std::sort(face.begin(), face.end());
      ++faces[face];
    }
  }
  EXPECT_NEAR(total, size * size * size, 1e-12 * size * size * size);
  auto on_boundary = [&](const std::array<int, 3>& f) {
    for (int d = 0; d < 3; ++d) {
      const double c = m.nodes()[static_cast<std::size_t>(f[0])][d];
      if ((c == 0.0 || c == size) && std::all_of(f.begin(), f.end(), [&](int v) {
            return m.nodes()[static_cast<std::size_t>(v)][d] == c;
          }))
        return true;
    }
    return false;
  };
  for (const auto& [face, count] : faces) {
    if (count == 1)
      EXPECT_TRUE(on_boundary(face)) << "a face seen once inside the box: a hanging node";
    else
      EXPECT_EQ(count, 2);
  }
}

TEST(TetBisection, RefiningTowardACornerKeepsTheMeshConforming) {
  TetBisection mesh = kuhn_grid(3, 1.0);
  // Size 1/16 at the origin, growing with the distance: five halvings there, none far away.
  mesh.refine([](const Eigen::Vector3d& p) { return 1.0 / 16.0 + 0.5 * p.norm(); }, 1'000'000);
  EXPECT_GT(mesh.tets().size(), 162U);
  expect_conforming(mesh, 1.0);
}

TEST(TetBisection, ThreeGenerationsGiveTheKuhnTetrahedraOfHalfSizeBoxes) {
  TetBisection mesh = kuhn_grid(2, 1.0);
  mesh.refine([](const Eigen::Vector3d&) { return 0.25; }, 1'000'000);
  // 2^3 cells of size 0.5 become 4^3 of size 0.25: eight times the tetrahedra, each of the
  // same volume (1/6 of its cell), so the shapes of the start repeat.
  ASSERT_EQ(mesh.tets().size(), 6U * 64U);
  for (const auto& t : mesh.tets()) {
    EXPECT_NEAR(volume(mesh, t), 0.25 * 0.25 * 0.25 / 6.0, 1e-15);
    // A Kuhn tetrahedron of a cube of side h: three edges h, two h sqrt 2, one h sqrt 3.
    std::array<double, 6> edges{};
    std::size_t e = 0;
    for (std::size_t a = 0; a < 4; ++a)
      for (std::size_t b = a + 1; b < 4; ++b)
        edges[e++] = (mesh.nodes()[static_cast<std::size_t>(t[a])] -
                      mesh.nodes()[static_cast<std::size_t>(t[b])])
                         .norm();
    std::sort(edges.begin(), edges.end());
    const std::array<double, 6> kuhn = {
        0.25, 0.25, 0.25, 0.25 * std::sqrt(2.0), 0.25 * std::sqrt(2.0), 0.25 * std::sqrt(3.0)};
    // Every coordinate is a multiple of 1/4, exact in binary: only the square roots round.
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(edges[i], kuhn[i], 1e-15);
  }
  expect_conforming(mesh, 1.0);
}

TEST(TetBisection, NodesAreMidpointsOfTheGridSoItsPlanesStay) {
  TetBisection mesh = kuhn_grid(2, 1.0);
  mesh.refine([](const Eigen::Vector3d& p) { return 0.1 + p.z(); }, 1'000'000);
  // The plane x = 0.5 of the grid is still a union of faces: no tetrahedron crosses it.
  for (const auto& t : mesh.tets()) {
    bool below = false, above = false;
    for (int v : t) {
      below = below || mesh.nodes()[static_cast<std::size_t>(v)].x() < 0.5;
      above = above || mesh.nodes()[static_cast<std::size_t>(v)].x() > 0.5;
    }
    EXPECT_FALSE(below && above);
  }
}

TEST(TetBisection, TooManyTetrahedraIsAnInputError) {
  TetBisection mesh = kuhn_grid(1, 1.0);
  EXPECT_THROW(mesh.refine([](const Eigen::Vector3d&) { return 1e-3; }, 10'000),
               mneedle::InputError);
}

}  // namespace
