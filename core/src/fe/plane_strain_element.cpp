// Bilinear plane-strain rectangle and graded grid lines (docs/model.md, "The plane-strain crack").
#include "plane_strain_element.h"

#include <array>
#include <cmath>
#include <sstream>

namespace mneedle::fe {

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

Eigen::Matrix<double, 8, 8> plane_strain_rectangle_stiffness(double hx, double hy, double E,
                                                             double nu) {
  const double lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double mu = E / (2.0 * (1.0 + nu));
  const std::array<double, 4> xi_a{-1, 1, 1, -1}, eta_a{-1, -1, 1, 1};
  auto B_at = [&](double xi, double eta) {
    Eigen::Matrix<double, 3, 8> B = Eigen::Matrix<double, 3, 8>::Zero();
    for (int k = 0; k < 4; ++k) {
      const double dx = 0.25 * xi_a[k] * (1.0 + eta * eta_a[k]) * 2.0 / hx;
      const double dy = 0.25 * eta_a[k] * (1.0 + xi * xi_a[k]) * 2.0 / hy;
      B(0, 2 * k) = dx;
      B(1, 2 * k + 1) = dy;
      B(2, 2 * k) = dy;
      B(2, 2 * k + 1) = dx;
    }
    return B;
  };
  const double detJ = 0.25 * hx * hy;
  Eigen::Matrix3d D_mu = Eigen::Matrix3d::Zero();
  D_mu(0, 0) = D_mu(1, 1) = 2.0 * mu;
  D_mu(2, 2) = mu;
  Eigen::Matrix<double, 8, 8> K = Eigen::Matrix<double, 8, 8>::Zero();
  const double g = 1.0 / std::sqrt(3.0);
  for (double xi : {-g, g})
    for (double eta : {-g, g}) {
      const Eigen::Matrix<double, 3, 8> B = B_at(xi, eta);
      K += B.transpose() * D_mu * B * detJ;
    }
  const Eigen::Matrix<double, 3, 8> B0 = B_at(0.0, 0.0);
  const Eigen::Matrix<double, 1, 8> div = B0.row(0) + B0.row(1);
  K += lambda * div.transpose() * div * (4.0 * detJ);
  return K;
}

void append_graded(std::vector<double>& points, double a, double b, double h, double g) {
  double x = a;
  while (true) {
    if (x + h >= b - 0.5 * h) {
      points.push_back(b);
      return;
    }
    x += h;
    points.push_back(x);
    h *= g;
  }
}

double graded_count(double length, double h, double g) {
  return std::ceil(std::log1p(length * (g - 1.0) / h) / std::log(g));
}

}  // namespace mneedle::fe
