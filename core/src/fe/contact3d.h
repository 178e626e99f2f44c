#pragma once
// PRIVATE to mneedle::core: frictionless contact between the tissue's top surface and rigid
// needles, enforced at surface quadrature points by an augmented Lagrangian (docs/model.md,
// "3-D frictionless contact"). Point-wise pressures avoid the negative corner loads and the
// chattering active set of node-to-surface constraints on 6-node faces.

#include <Eigen/Core>
#include <array>
#include <functional>
#include <vector>

#include "fe/needle_shape.h"
#include "mneedle/fe/indentation3d.h"

namespace mneedle::fe {

/// One quadrature point of a top face: traction t = max(0, λ + ε p) along the needle's outward
/// normal n, p the penetration (signed distance inside the needle, m).
struct ContactPoint {
  std::array<int, 6> nodes{};     ///< face nodes (3 or 6 used)
  std::array<double, 6> shape{};  ///< face shape functions at the point
  Eigen::Vector3d reference;      ///< reference position (z = 0)
  double weight = 0.0;            ///< reference area carried by the point (m^2)
  double penalty = 0.0;           ///< ε (Pa/m)
  double multiplier = 0.0;        ///< λ (Pa), updated between solves (Uzawa)
  int needle = 0;                 ///< nearest needle (horizontal distance)
};

/// State of one point at a displacement: p, n, traction.
struct ContactPointState {
  double penetration = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double traction = 0.0;  ///< Pa, >= 0
};

class FrictionlessContact {
 public:
  /// Quadrature points on the top faces within `reach` of each needle's axis; the penalty of a
  /// point is kPenaltyFactor E* / h (E* of layer 0, h the face size).
  FrictionlessContact(const TetMesh& mesh, const std::vector<Needle3d>& needles,
                      const std::vector<NeedleShape>* shapes, const std::vector<double>& reach);

  const std::vector<ContactPoint>& points() const { return points_; }
  /// Nodes of the contact faces, sorted.
  const std::vector<int>& nodes() const { return nodes_; }
  int face_nodes() const { return face_nodes_; }

  /// Point states at tip depth `depth` with nodal displacement `displacement_of(node)`.
  std::vector<ContactPointState> evaluate(
      double depth, const std::function<Eigen::Vector3d(int)>& displacement_of) const;
  void set_multipliers(const std::vector<double>& multipliers);
  /// Uzawa update λ ← max(0, λ + ε p); returns the largest change of λ·weight (N).
  double update_multipliers(const std::vector<ContactPointState>& states);
  /// Nodal forces of the needle on the tissue: add(node, force).
  void for_each_force(const std::vector<ContactPointState>& states,
                      const std::function<void(int, const Eigen::Vector3d&)>& add) const;
  /// Contact tangent d(force on tissue)/du = -Σ w ε N_a N_b n nᵀ (curvature of the needle
  /// surface neglected): add(node_a, node_b, block) with the block of +Σ w ε N_a N_b n nᵀ.
  void for_each_tangent(const std::vector<ContactPointState>& states,
                        const std::function<void(int, int, const Eigen::Matrix3d&)>& add) const;

 private:
  const std::vector<NeedleShape>* shapes_;
  std::vector<Eigen::Vector2d> axes_;  // needle (x, y)
  std::vector<double> reach_;
  std::vector<ContactPoint> points_;
  std::vector<int> nodes_;
  int face_nodes_ = 3;
};

/// ε = kPenaltyFactor E* / h: stiff enough that the Uzawa loop converges in a few updates, soft
/// enough to leave the tangent well conditioned.
inline constexpr double kPenaltyFactor = 100.0;

}  // namespace mneedle::fe
