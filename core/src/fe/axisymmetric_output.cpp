// Derived fields of the axisymmetric model: stresses, the averaged tip stress, VTU files and the
// ring-cracked copy of a mesh.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "axisymmetric_internal.h"
#include "fe/vtu_writer.h"
#include "mneedle/base/error.h"
#include "mneedle/fe/axisymmetric.h"

namespace mneedle::fe {

using namespace axi;

namespace {

double von_mises_of(const Eigen::Matrix3d& s) {
  const Eigen::Matrix3d dev = s - s.trace() / 3.0 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * dev.squaredNorm());
}

// Largest eigenvalue of a Cauchy stress with the axisymmetric structure: the (r, z) block and
// the hoop component are decoupled.
double max_principal(const Eigen::Matrix3d& s) {
  const double mean = 0.5 * (s(0, 0) + s(2, 2));
  const double radius = std::hypot(0.5 * (s(0, 0) - s(2, 2)), s(0, 2));
  return std::max(mean + radius, s(1, 1));
}

// Subdivision of the reference triangle into n^2 equal triangles: their centroids.
std::vector<Eigen::Vector2d> sub_centroids(int n) {
  std::vector<Eigen::Vector2d> out;
  const double h = 1.0 / n;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n - i; ++j) {
      out.emplace_back((i + 1.0 / 3.0) * h, (j + 1.0 / 3.0) * h);
      if (i + j < n - 1) out.emplace_back((i + 2.0 / 3.0) * h, (j + 2.0 / 3.0) * h);
    }
  return out;
}

// The fraction of the ring through reference point x = (r, z) that lies within `length` of the
// 3-D point at (r_c, theta = 0, z_c): the ring's points at angle phi are r^2 + r_c^2 -
// 2 r r_c cos(phi) + (z - z_c)^2 from it squared, so those with cos(phi) >= c are inside, a
// fraction acos(c) / pi. Weighting a sub-triangle's 2 pi r dA by it makes the mean one over a
// ball, as the 3-D probe's, where a disc in (r, z) would be a torus round the axis.
double ring_fraction_in_ball(const Eigen::Vector2d& x, const Eigen::Vector2d& centre,
                             double length) {
  const double r = x.x(), rc = centre.x(), dz = x.y() - centre.y();
  const double reach2 = length * length;
  if (r <= 0.0 || rc <= 0.0) return r * r + rc * rc + dz * dz <= reach2 ? 1.0 : 0.0;
  const double c = (r * r + rc * rc + dz * dz - reach2) / (2.0 * r * rc);
  if (c >= 1.0) return 0.0;
  if (c <= -1.0) return 1.0;
  return std::acos(c) / std::numbers::pi;
}

}  // namespace

const std::vector<MaterialParameters>& AxisymmetricModel::layer_materials() const {
  return impl_->parameters;
}

std::vector<double> AxisymmetricModel::von_mises(const Eigen::VectorXd& u) const {
  const Impl& m = *impl_;
  std::vector<double> out(m.mesh.elements.size(), 0.0);
  for (std::size_t e = 0; e < out.size(); ++e) {
    const Material& material = m.materials[m.mesh.element_layer[e]];
    for (int q = 0; q < kQuadrature; ++q) {
      const PointData& p = m.points[e * kQuadrature + q];
      const Eigen::Matrix3d F = deformation_gradient(p, u, m.mesh.elements[e]);
      out[e] += kRule[q].weight * von_mises_of(cauchy_stress(material, F, nullptr));
    }
  }
  return out;
}

std::vector<double> AxisymmetricModel::energy_density(const Eigen::VectorXd& u) const {
  const Impl& m = *impl_;
  std::vector<double> out(m.mesh.elements.size(), 0.0);
  for (std::size_t e = 0; e < out.size(); ++e) {
    const Material& material = m.materials[m.mesh.element_layer[e]];
    for (int q = 0; q < kQuadrature; ++q) {
      const PointData& p = m.points[e * kQuadrature + q];
      const Eigen::Matrix3d F = deformation_gradient(p, u, m.mesh.elements[e]);
      out[e] += kRule[q].weight * material.evaluate(F).energy_density;
    }
  }
  return out;
}

double AxisymmetricModel::averaged_max_principal_stress(const Eigen::VectorXd& u,
                                                        const Eigen::Vector2d& point_m,
                                                        double length_m, int layer) const {
  if (!(length_m > 0.0)) throw InputError("stress average: length must be > 0 m");
  const Impl& m = *impl_;
  // Elements wholly inside the ball use their quadrature rule; cut ones a 64-triangle
  // subdivision (midpoint rule per sub-triangle) that resolves the ball's edge to h/8.
  static const std::vector<Eigen::Vector2d> kSub = sub_centroids(8);
  double weighted = 0.0, volume = 0.0;
  for (std::size_t e = 0; e < m.mesh.elements.size(); ++e) {
    if (m.mesh.element_layer[e] != layer) continue;
    const auto& nodes = m.mesh.elements[e];
    double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
    Eigen::Vector2d lo = m.mesh.nodes[nodes[0]], hi = lo;
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector2d& X = m.mesh.nodes[nodes[a]];
      lo = lo.cwiseMin(X);
      hi = hi.cwiseMax(X);
      farthest = std::max(farthest, (X - point_m).norm());
    }
    nearest = (point_m.cwiseMax(lo).cwiseMin(hi) - point_m).norm();
    if (nearest > length_m) continue;
    const Material& material = m.materials[layer];
    auto add = [&](const PointData& p) {
      const Eigen::Matrix3d F = deformation_gradient(p, u, nodes);
      weighted += p.w * max_principal(cauchy_stress(material, F, nullptr));
      volume += p.w;
    };
    if (farthest <= length_m) {
      for (int q = 0; q < kQuadrature; ++q) add(m.points[e * kQuadrature + q]);
      continue;
    }
    for (const Eigen::Vector2d& c : kSub) {
      const PointData p = point_data(m.mesh, nodes, c.x(), c.y(), 1.0 / kSub.size());
      Eigen::Vector2d X = Eigen::Vector2d::Zero();
      for (int a = 0; a < kNodes; ++a) X += p.N[a] * m.mesh.nodes[nodes[a]];
      if ((X - point_m).norm() <= length_m) add(p);
    }
  }
  return volume > 0.0 ? weighted / volume : 0.0;
}

double AxisymmetricModel::peak_averaged_max_principal_stress(const Eigen::VectorXd& u,
                                                             double search_radius_m,
                                                             double length_m, int layer) const {
  if (!(length_m > 0.0)) throw InputError("stress average: length must be > 0 m");
  if (!(search_radius_m >= 0.0)) throw InputError("stress average: search radius must be >= 0 m");
  const Impl& m = *impl_;
  Impl::StressBalls& b = m.balls;
  if (b.length != length_m || b.layer != layer || b.radius < search_radius_m) {
    // Built for half as far again, so that a search radius growing with the depth rebuilds the
    // balls a few times per insertion, not at every step.
    b = Impl::StressBalls{};
    b.length = length_m;
    b.layer = layer;
    b.radius = 1.5 * search_radius_m;
    static const std::vector<Eigen::Vector2d> kSub = sub_centroids(4);
    struct SubPoint {
      Eigen::Vector2d x;
      double weight;
      std::uint32_t index;
    };
    std::vector<SubPoint> points;
    std::vector<char> centre(m.mesh.nodes.size(), 0);
    for (std::size_t e = 0; e < m.mesh.elements.size(); ++e) {
      if (m.mesh.element_layer[e] != layer) continue;
      const auto& nodes = m.mesh.elements[e];
      double r_min = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) r_min = std::min(r_min, m.mesh.nodes[nodes[a]].x());
      if (r_min > b.radius + length_m) continue;
      for (const Eigen::Vector2d& c : kSub) {
        const PointData p = point_data(m.mesh, nodes, c.x(), c.y(), 1.0 / kSub.size());
        Eigen::Vector2d X = Eigen::Vector2d::Zero();
        for (int a = 0; a < kNodes; ++a) X += p.N[a] * m.mesh.nodes[nodes[a]];
        points.push_back({X, p.w, static_cast<std::uint32_t>(b.point.size())});
        b.element.push_back(e);
        b.point.push_back(p);
      }
      for (std::uint32_t n : nodes)
        if (m.mesh.nodes[n].x() <= b.radius) centre[n] = 1;
    }
    // Sub-points sorted by r: each centre scans the band |r - r_c| <= length_m.
    std::sort(points.begin(), points.end(),
              [](const SubPoint& p, const SubPoint& q) { return p.x.x() < q.x.x(); });
    b.start.push_back(0);
    for (std::size_t n = 0; n < centre.size(); ++n) {
      if (!centre[n]) continue;
      const Eigen::Vector2d& c = m.mesh.nodes[n];
      auto it = std::lower_bound(points.begin(), points.end(), c.x() - length_m,
                                 [](const SubPoint& p, double r) { return p.x.x() < r; });
      for (; it != points.end() && it->x.x() <= c.x() + length_m; ++it) {
        const double fraction = ring_fraction_in_ball(it->x, c, length_m);
        if (fraction <= 0.0) continue;
        b.source.push_back(it->index);
        b.weight.push_back(fraction * it->weight);
      }
      b.centre_r.push_back(c.x());
      b.start.push_back(b.source.size());
    }
  }
  const Material& material = m.materials[layer];
  std::vector<double> stress(b.point.size());
  for (std::size_t i = 0; i < b.point.size(); ++i) {
    const Eigen::Matrix3d F = deformation_gradient(b.point[i], u, m.mesh.elements[b.element[i]]);
    stress[i] = max_principal(cauchy_stress(material, F, nullptr));
  }
  double best = 0.0;
  bool found = false;
  for (std::size_t k = 0; k < b.centre_r.size(); ++k) {
    if (b.centre_r[k] > search_radius_m) continue;
    double weighted = 0.0, volume = 0.0;
    for (std::size_t j = b.start[k]; j < b.start[k + 1]; ++j) {
      weighted += b.weight[j] * stress[b.source[j]];
      volume += b.weight[j];
    }
    if (!(volume > 0.0)) continue;
    const double mean = weighted / volume;
    if (!found || mean > best) best = mean;
    found = true;
  }
  return best;
}

VtuFile axi::needle_profile_vtu(const AxisymmetricNeedle& needle, double depth_m) {
  VtuFile f;
  f.points_m.emplace_back(0.0, 0.0, -depth_m);  // the tip on the axis
  for (std::size_t i = 0; i < needle.heights_m.size(); ++i)
    f.points_m.emplace_back(needle.radii_m[i], 0.0, needle.heights_m[i] - depth_m);
  for (std::size_t i = 0; i + 1 < f.points_m.size(); ++i) {
    f.connectivity.insert(f.connectivity.end(),
                          {static_cast<std::int64_t>(i), static_cast<std::int64_t>(i + 1)});
    f.offsets.push_back(static_cast<std::int64_t>(f.connectivity.size()));
    f.types.push_back(3);  // VTK_LINE
  }
  f.field_data = {{"depth_m", 1, {depth_m}, {}}};
  return f;
}

void AxisymmetricModel::write_vtu(const std::string& path, const Eigen::VectorXd& u, double depth_m,
                                  const std::string& comment) const {
  const Impl& m = *impl_;
  const AxisymmetricMesh& mesh = m.mesh;
  VtuFile f;
  f.comment = comment;
  // The (r, z) plane drawn as the x-z plane of a 3-D file.
  for (const auto& p : mesh.nodes) f.points_m.emplace_back(p.x(), 0.0, p.y());
  // VTK_QUADRATIC_TRIANGLE: corners, then mid-edges 0-1, 1-2, 2-0 (our order).
  for (const auto& e : mesh.elements) {
    for (std::uint32_t node : e) f.connectivity.push_back(node);
    f.offsets.push_back(static_cast<std::int64_t>(f.connectivity.size()));
    f.types.push_back(22);
  }
  VtuArray displacement{"displacement_m", 3, {}, {}};
  for (Eigen::Index i = 0; i + 1 < u.size(); i += 2)
    displacement.float64.insert(displacement.float64.end(), {u(i), 0.0, u(i + 1)});
  // principal stresses of the element's mean Cauchy stress (σ_θθ is one of them)
  VtuArray principal{"principal_stress_Pa", 3, {}, {}};
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    const Material& material = m.materials[mesh.element_layer[e]];
    Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
    for (int q = 0; q < kQuadrature; ++q) {
      const Eigen::Matrix3d F =
          deformation_gradient(m.points[e * kQuadrature + q], u, mesh.elements[e]);
      mean += kRule[q].weight * cauchy_stress(material, F, nullptr);
    }
    const Eigen::Vector3d values =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mean, Eigen::EigenvaluesOnly).eigenvalues();
    principal.float64.insert(principal.float64.end(), {values(2), values(1), values(0)});
  }
  VtuArray layer{"layer", 1, {}, {}};
  layer.int32.assign(mesh.element_layer.begin(), mesh.element_layer.end());
  f.point_data = {displacement};
  f.cell_data = {{"von_mises_Pa", 1, von_mises(u), {}},
                 principal,
                 {"energy_density_J_per_m3", 1, energy_density(u), {}},
                 layer};
  f.field_data = {{"depth_m", 1, {depth_m}, {}}, {"axisymmetric", 1, {}, {1}}};
  fe::write_vtu(path, f);
}

AxisymmetricMesh crack_axisymmetric_mesh(const AxisymmetricMesh& mesh, double radius_m,
                                         double depth_m, double* area_m2,
                                         std::vector<std::array<std::uint32_t, 2>>* face_pairs) {
  if (!(radius_m > 0.0) || !(depth_m > 0.0))
    throw InputError("ring crack: radius and depth must be > 0 m");
  double extent = 0.0;
  for (const Eigen::Vector2d& X : mesh.nodes) extent = std::max(extent, X.cwiseAbs().maxCoeff());
  const double tol = 1e-9 * extent;
  auto on_line = [&](const Eigen::Vector2d& X) {
    return std::abs(X.x() - radius_m) <= tol && X.y() <= tol && X.y() >= -depth_m - tol;
  };
  auto describe = [&] {
    return "ring crack at r = " + format_depth(radius_m) + ", depth " + format_depth(depth_m);
  };
  bool front = false;
  std::map<std::uint32_t, std::uint32_t> copy;  // crack-face node -> its outer copy
  AxisymmetricMesh out = mesh;
  for (std::uint32_t n = 0; n < mesh.nodes.size(); ++n) {
    if (!on_line(mesh.nodes[n])) continue;
    if (mesh.nodes[n].y() <= -depth_m + tol) {
      front = true;
      continue;
    }
    copy[n] = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.push_back(mesh.nodes[n]);
  }
  if (!front || copy.empty())
    throw InputError(describe() + ": the mesh has no node column there reaching that depth");
  // Each element on the line goes wholly to one side; the outer ones take the copies.
  std::size_t faces = 0;
  for (auto& e : out.elements) {
    double inner = 0.0, outer = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double dr = mesh.nodes[e[a]].x() - radius_m;
      inner = std::min(inner, dr);
      outer = std::max(outer, dr);
    }
    const bool touches = std::any_of(e.begin(), e.end(), [&](auto n) { return copy.count(n); });
    if (!touches) continue;
    if (inner < -tol && outer > tol)
      throw InputError(describe() + ": an element straddles the crack line");
    if (outer <= tol) continue;
    int on = 0;
    for (auto& n : e) {
      const auto it = copy.find(n);
      if (it != copy.end()) n = it->second, ++on;
    }
    faces += on >= 2;
  }
  if (faces == 0) throw InputError(describe() + ": no element edge lies on the crack line");
  // The outer copy of the surface node is not a contact node: the needle presses the inside of
  // the ring. (Holding that corner of the outer wedge with the needle would pin one node of a
  // free corner, whose energy vanishes under refinement, and G would not converge.)
  if (area_m2) *area_m2 = 2.0 * kPi * radius_m * depth_m;
  if (face_pairs)
    for (const auto& [inner, outer] : copy) face_pairs->push_back({inner, outer});
  return out;
}

}  // namespace mneedle::fe
