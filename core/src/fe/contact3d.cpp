#include "fe/contact3d.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace mneedle::fe {

namespace {

// Dunavant's 6-point rule (degree 4) on a triangle: barycentric coordinates and weights that sum
// to one.
struct TrianglePoint {
  std::array<double, 3> l;
  double weight;
};
const std::array<TrianglePoint, 6>& dunavant6() {
  static const std::array<TrianglePoint, 6> rule = [] {
    const double a = 0.445948490915965, wa = 0.223381589678011;
    const double b = 0.091576213509771, wb = 0.109951743655322;
    return std::array<TrianglePoint, 6>{{{{a, a, 1 - 2 * a}, wa},
                                         {{a, 1 - 2 * a, a}, wa},
                                         {{1 - 2 * a, a, a}, wa},
                                         {{b, b, 1 - 2 * b}, wb},
                                         {{b, 1 - 2 * b, b}, wb},
                                         {{1 - 2 * b, b, b}, wb}}};
  }();
  return rule;
}

// The face split into its four midpoint sub-triangles, each with the 6-point rule: 24 points
// resolve the contact edge to a quarter of the face size (the footprint of a flat punch).
std::vector<TrianglePoint> face_rule() {
  const std::array<Eigen::Vector3d, 6> v = {
      Eigen::Vector3d(1, 0, 0),     Eigen::Vector3d(0, 1, 0),     Eigen::Vector3d(0, 0, 1),
      Eigen::Vector3d(0.5, 0.5, 0), Eigen::Vector3d(0, 0.5, 0.5), Eigen::Vector3d(0.5, 0, 0.5)};
  constexpr int kSub[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
  std::vector<TrianglePoint> points;
  for (const auto& sub : kSub)
    for (const TrianglePoint& p : dunavant6()) {
      const Eigen::Vector3d l = p.l[0] * v[static_cast<std::size_t>(sub[0])] +
                                p.l[1] * v[static_cast<std::size_t>(sub[1])] +
                                p.l[2] * v[static_cast<std::size_t>(sub[2])];
      points.push_back({{l.x(), l.y(), l.z()}, 0.25 * p.weight});
    }
  return points;
}

// 3-node (linear) or 6-node (quadratic: corners, then midsides 01, 12, 20) face shape functions.
std::array<double, 6> face_shape(const std::array<double, 3>& l, int count) {
  std::array<double, 6> n{};
  if (count == 3) return {l[0], l[1], l[2], 0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    n[static_cast<std::size_t>(i)] =
        l[static_cast<std::size_t>(i)] * (2.0 * l[static_cast<std::size_t>(i)] - 1.0);
    n[static_cast<std::size_t>(3 + i)] =
        4.0 * l[static_cast<std::size_t>(i)] * l[static_cast<std::size_t>((i + 1) % 3)];
  }
  return n;
}

// Plane-strain modulus of the top layer; hyperelastic layers without E use 3 μ = 6 (c10 + c01).
double top_modulus(const TetMesh& mesh) {
  const MaterialParameters& m = mesh.layers.front().material;
  const double E = m.E > 0.0 ? m.E : 6.0 * (m.c10 + m.c01);
  const double nu = m.E > 0.0 ? m.nu : 0.45;
  return E / (1.0 - nu * nu);
}

}  // namespace

FrictionlessContact::FrictionlessContact(const TetMesh& mesh, const std::vector<Needle3d>& needles,
                                         const std::vector<NeedleShape>* shapes,
                                         const std::vector<double>& reach)
    : shapes_(shapes), reach_(reach) {
  face_nodes_ = mesh.order == 1 ? 3 : 6;
  for (const Needle3d& needle : needles) axes_.emplace_back(needle.x, needle.y);
  const double modulus = top_modulus(mesh);
  const std::vector<TrianglePoint> rule = face_rule();
  for (const auto& face : mesh.top_faces) {
    std::array<Eigen::Vector3d, 3> corner;
    for (int i = 0; i < 3; ++i)
      corner[static_cast<std::size_t>(i)] =
          mesh.nodes[static_cast<std::size_t>(face[static_cast<std::size_t>(i)])];
    const Eigen::Vector3d centre = (corner[0] + corner[1] + corner[2]) / 3.0;
    const double circumradius = std::max(
        {(corner[0] - centre).norm(), (corner[1] - centre).norm(), (corner[2] - centre).norm()});
    int nearest = -1;
    double nearest_distance = 0.0;
    for (std::size_t n = 0; n < axes_.size(); ++n) {
      const double distance = (centre.head<2>() - axes_[n]).norm();
      if (distance - circumradius > reach_[n]) continue;
      if (nearest < 0 || distance < nearest_distance) {
        nearest = static_cast<int>(n);
        nearest_distance = distance;
      }
    }
    if (nearest < 0) continue;
    const double area = 0.5 * (corner[1] - corner[0]).cross(corner[2] - corner[0]).norm();
    const double size = std::sqrt(2.0 * area);
    for (const TrianglePoint& q : rule) {
      ContactPoint point;
      std::copy(face.begin(), face.end(), point.nodes.begin());
      point.shape = face_shape(q.l, face_nodes_);
      point.reference = q.l[0] * corner[0] + q.l[1] * corner[1] + q.l[2] * corner[2];
      point.weight = q.weight * area;
      point.penalty = kPenaltyFactor * modulus / size;
      point.needle = nearest;
      points_.push_back(point);
    }
    for (int a = 0; a < face_nodes_; ++a) nodes_.push_back(face[static_cast<std::size_t>(a)]);
  }
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
}

std::vector<ContactPointState> FrictionlessContact::evaluate(
    double depth, const std::function<Eigen::Vector3d(int)>& displacement_of) const {
  std::vector<ContactPointState> states(points_.size());
  for (std::size_t q = 0; q < points_.size(); ++q) {
    const ContactPoint& point = points_[q];
    Eigen::Vector3d x = point.reference;
    for (int a = 0; a < face_nodes_; ++a)
      x += point.shape[static_cast<std::size_t>(a)] *
           displacement_of(point.nodes[static_cast<std::size_t>(a)]);
    const auto n = static_cast<std::size_t>(point.needle);
    const Eigen::Vector3d local = x - Eigen::Vector3d(axes_[n].x(), axes_[n].y(), -depth);
    // Far outside the needle's reach and carrying no multiplier: no pressure, skip the query.
    if (point.multiplier == 0.0 && (local.head<2>().norm() > reach_[n] || local.z() < -1e-12))
      continue;
    const NeedleShape& shape = (*shapes_)[n];
    ContactPointState& state = states[q];
    // The needle moves along -z, so tissue inside it entered through the face the downward ray
    // leaves by, and tissue below it meets the face the upward ray reaches: the gap is measured
    // to that face's plane along its normal (not to the nearest face, which near a punch rim is
    // the side wall and would push the trapped tissue sideways).
    const bool inside = shape.contains(local);
    Eigen::Vector3d hit, normal;
    if (shape.vertical_hit(local, inside, &hit, &normal)) {
      state.normal = normal;
      state.penetration = normal.dot(hit - local);
    } else {
      const Eigen::Vector3d closest = shape.closest_point(local, &normal);
      const double distance = (closest - local).norm();
      state.normal = distance > 0.0
                         ? Eigen::Vector3d((inside ? closest - local : local - closest) / distance)
                         : normal;
      state.penetration = inside ? distance : -distance;
    }
    state.traction = std::max(0.0, point.multiplier + point.penalty * state.penetration);
  }
  return states;
}

void FrictionlessContact::set_multipliers(const std::vector<double>& multipliers) {
  for (std::size_t q = 0; q < points_.size(); ++q) points_[q].multiplier = multipliers[q];
}

double FrictionlessContact::update_multipliers(const std::vector<ContactPointState>& states) {
  double largest = 0.0;
  for (std::size_t q = 0; q < points_.size(); ++q) {
    ContactPoint& point = points_[q];
    const double updated = states[q].traction;
    largest = std::max(largest, std::abs(updated - point.multiplier) * point.weight);
    point.multiplier = updated;
  }
  return largest;
}

void FrictionlessContact::for_each_force(
    const std::vector<ContactPointState>& states,
    const std::function<void(int, const Eigen::Vector3d&)>& add) const {
  for (std::size_t q = 0; q < points_.size(); ++q) {
    if (states[q].traction <= 0.0) continue;
    const ContactPoint& point = points_[q];
    const Eigen::Vector3d force = point.weight * states[q].traction * states[q].normal;
    for (int a = 0; a < face_nodes_; ++a)
      add(point.nodes[static_cast<std::size_t>(a)],
          point.shape[static_cast<std::size_t>(a)] * force);
  }
}

void FrictionlessContact::for_each_tangent(
    const std::vector<ContactPointState>& states,
    const std::function<void(int, int, const Eigen::Matrix3d&)>& add) const {
  for (std::size_t q = 0; q < points_.size(); ++q) {
    if (states[q].traction <= 0.0) continue;
    const ContactPoint& point = points_[q];
    const Eigen::Matrix3d nn =
        point.weight * point.penalty * states[q].normal * states[q].normal.transpose();
    for (int a = 0; a < face_nodes_; ++a)
      for (int b = 0; b < face_nodes_; ++b)
        add(point.nodes[static_cast<std::size_t>(a)], point.nodes[static_cast<std::size_t>(b)],
            point.shape[static_cast<std::size_t>(a)] * point.shape[static_cast<std::size_t>(b)] *
                nn);
  }
}

}  // namespace mneedle::fe
