#include "fe/plane_strain_element.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <vector>

namespace mneedle::fe {
namespace {

TEST(PlaneStrainRectangle, RigidMotionsStoreNoEnergyAndEveryOtherModeDoes) {
  const Eigen::Matrix<double, 8, 8> K = plane_strain_rectangle_stiffness(2e-3, 1e-3, 7e3, 0.475);
  EXPECT_LT((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-12 * K.cwiseAbs().maxCoeff());
  // Nodes (0,0), (hx,0), (hx,hy), (0,hy): translations and the rotation (-y, x).
  const std::vector<std::array<double, 2>> xy{{0, 0}, {2e-3, 0}, {2e-3, 1e-3}, {0, 1e-3}};
  Eigen::Matrix<double, 8, 3> rigid;
  for (int k = 0; k < 4; ++k) {
    rigid.row(2 * k) << 1, 0, -xy[k][1];
    rigid.row(2 * k + 1) << 0, 1, xy[k][0];
  }
  EXPECT_LT((K * rigid).cwiseAbs().maxCoeff(), 1e-12 * K.cwiseAbs().maxCoeff());
  // Selective reduced integration keeps the shear part at full order: besides the three rigid
  // motions no zero-energy (hourglass) mode, so exactly three eigenvalues vanish.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 8, 8>> eig(K);
  int zero = 0;
  for (int k = 0; k < 8; ++k) zero += eig.eigenvalues()[k] < 1e-9 * eig.eigenvalues()[7];
  EXPECT_EQ(zero, 3);
}

TEST(PlaneStrainRectangle, UniformStrainGivesTheClosedFormEnergy) {
  // Uniaxial strain e_xx = e (u_x = e x): energy density (lambda + 2 mu) e^2 / 2.
  const double E = 7e3, nu = 0.3, hx = 2e-3, hy = 1e-3, e = 1e-2;
  const Eigen::Matrix<double, 8, 8> K = plane_strain_rectangle_stiffness(hx, hy, E, nu);
  Eigen::Matrix<double, 8, 1> u = Eigen::Matrix<double, 8, 1>::Zero();
  u[2] = u[4] = e * hx;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  EXPECT_NEAR(0.5 * u.dot(K * u) / (0.5 * (lambda + 2 * mu) * e * e * hx * hy), 1.0, 1e-12);
}

TEST(GradedGridLine, SpacingsGrowFromTheFirstAndEndExactlyAtTheEnd) {
  std::vector<double> x{0.0};
  append_graded(x, 0.0, 1.0, 0.01, 1.1);
  ASSERT_GE(x.size(), 3u);
  EXPECT_EQ(x.back(), 1.0);
  EXPECT_NEAR(x[1], 0.01, 1e-15);
  EXPECT_NEAR(x[2] - x[1], 0.011, 1e-15);
  for (std::size_t k = 1; k + 1 < x.size(); ++k)
    EXPECT_GT(x[k + 1] - x[k], 0.5 * (x[k] - x[k - 1]));
  // graded_count bounds what append_graded adds (a mesh is counted before it is built).
  EXPECT_LE(static_cast<double>(x.size() - 1), graded_count(1.0, 0.01, 1.1));
}

}  // namespace
}  // namespace mneedle::fe
