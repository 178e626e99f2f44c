#pragma once
// Private to the axisymmetric model's sources: the 6-node triangle, the model's state and the
// constraint helpers shared by the equilibrium solver, the insertion driver and the output.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "fe/vtu_writer.h"
#include "mneedle/fe/axisymmetric.h"
#include "mneedle/fe/material.h"
#include "mneedle/fe/sparse_solver.h"

namespace mneedle::fe::axi {

constexpr double kPi = 3.14159265358979323846;
constexpr int kNodes = 6;
constexpr int kDofs = 12;
constexpr int kQuadrature = 6;

using Matrix12 = Eigen::Matrix<double, kDofs, kDofs>;
using Vector12 = Eigen::Matrix<double, kDofs, 1>;

// Degree-4 six-point rule on the reference triangle (Dunavant); weights sum to 1.
struct QuadraturePoint {
  double xi, eta, weight;
};
constexpr double kA = 0.445948490915965, kWA = 0.223381589678011;
constexpr double kB = 0.091576213509771, kWB = 0.109951743655322;
constexpr QuadraturePoint kRule[kQuadrature] = {{kA, kA, kWA},         {1 - 2 * kA, kA, kWA},
                                                {kA, 1 - 2 * kA, kWA}, {kB, kB, kWB},
                                                {1 - 2 * kB, kB, kWB}, {kB, 1 - 2 * kB, kWB}};

struct ShapeValues {
  double N[kNodes];
  double dxi[kNodes];
  double deta[kNodes];
};

inline ShapeValues t6_shape(double xi, double eta) {
  const double L1 = 1.0 - xi - eta, L2 = xi, L3 = eta;
  ShapeValues s;
  s.N[0] = L1 * (2 * L1 - 1);
  s.N[1] = L2 * (2 * L2 - 1);
  s.N[2] = L3 * (2 * L3 - 1);
  s.N[3] = 4 * L1 * L2;
  s.N[4] = 4 * L2 * L3;
  s.N[5] = 4 * L3 * L1;
  // dL1 = (-1, -1), dL2 = (1, 0), dL3 = (0, 1).
  s.dxi[0] = -(4 * L1 - 1);
  s.deta[0] = -(4 * L1 - 1);
  s.dxi[1] = 4 * L2 - 1;
  s.deta[1] = 0;
  s.dxi[2] = 0;
  s.deta[2] = 4 * L3 - 1;
  s.dxi[3] = 4 * (L1 - L2);
  s.deta[3] = -4 * L2;
  s.dxi[4] = 4 * L3;
  s.deta[4] = 4 * L2;
  s.dxi[5] = -4 * L3;
  s.deta[5] = 4 * (L1 - L3);
  return s;
}

// Shape data in reference coordinates at one point of an element; w includes 2 pi r.
struct PointData {
  double N[kNodes];
  double dr[kNodes];
  double dz[kNodes];
  double r;
  double w;
};

/// Shape data of element `nodes` at reference point (xi, eta) with weight fraction `weight` of
/// the reference triangle (1 = the whole element). Throws SolverError on a non-positive area.
PointData point_data(const AxisymmetricMesh& mesh, const std::array<std::uint32_t, 6>& nodes,
                     double xi, double eta, double weight);

/// Deformation gradient in cylindrical components (r, theta, z) at a point.
Eigen::Matrix3d deformation_gradient(const PointData& p, const Eigen::VectorXd& u,
                                     const std::array<std::uint32_t, 6>& nodes);

/// Cauchy stress: sigma = F S F^T / J; the small-strain model's S is already its stress.
Eigen::Matrix3d cauchy_stress(const Material& material, const Eigen::Matrix3d& F,
                              MaterialResponse* response);

inline std::string format_depth(double depth_m) {
  std::ostringstream s;
  s.precision(4);
  s << depth_m * 1e6 << " um";
  return s.str();
}

// Zeroes the rows and columns of constrained dofs and puts `diagonal` on their diagonal, so the
// sparsity pattern (and its symbolic factorisation) stays the same for every constraint set.
void constrain(Eigen::SparseMatrix<double>& K, const std::vector<char>& is_constrained,
               double diagonal);

/// The needle's outer outline at `depth_m` in the x-z plane (x = r, tip on the axis at
/// z = -depth) as line segments, cell data none, field data depth_m: part 1 of the collection.
VtuFile needle_profile_vtu(const AxisymmetricNeedle& needle, double depth_m);

}  // namespace mneedle::fe::axi

namespace mneedle::fe {

struct AxisymmetricModel::Impl {
  AxisymmetricMesh mesh;
  std::vector<MaterialParameters> parameters;
  std::vector<Material> materials;
  bool linear = true;
  std::vector<axi::PointData> points;   // element-major, kQuadrature per element
  Eigen::SparseMatrix<double> pattern;  // full symmetric pattern
  std::vector<int> slots;               // value index of (a, b) for each element, kDofs^2 each
  SparseSolver solver;
  bool analyzed = false;
  bool has_factor = false;                 // the solver holds a usable factorisation
  std::vector<char> factored_constraints;  // constrained dofs of that factorisation
  int factorizations = 0;
  // A solve took a step along a shifted tangent (past a bifurcation): every later solve may take
  // NewtonOptions::max_descent_iterations, the path settling onto the stable branch.
  bool bifurcated = false;
  bool factor_shifted = false;  // the factorisation held is of a shifted tangent
  double shift = 1e-6;          // the last shift that made the tangent positive definite
  // Crack-face pairs {inner, outer} held by an augmented Lagrangian when closed
  // (AxisymmetricModel::set_face_pairs): penalty, state and multiplier per pair, and the value
  // slots of (inner_r, inner_r), (outer_r, outer_r), (inner_r, outer_r), (outer_r, inner_r).
  std::vector<std::array<std::uint32_t, 2>> face_pairs;
  Eigen::VectorXd pair_penalty, pair_multiplier;
  std::vector<char> pair_closed;
  std::vector<std::array<int, 4>> pair_slots;

  // The stress criterion's balls (AxisymmetricModel::peak_averaged_max_principal_stress), built
  // once per averaging length, layer and search radius: the sub-points of the layer's elements
  // within reach and, per centre, each sub-point's weight 2 pi r dA x the fraction of its ring
  // inside the ball. Only the stresses change from call to call. A cache in a const method: a
  // model is used by one thread at a time.
  struct StressBalls {
    double length = 0.0;
    double radius = -1.0;
    int layer = -1;
    std::vector<std::size_t> element;   // per sub-point
    std::vector<axi::PointData> point;  // per sub-point
    std::vector<double> centre_r;       // per centre (nodes of the layer, r <= radius)
    std::vector<std::size_t> start;     // per centre + 1: its entries
    std::vector<std::uint32_t> source;  // per entry: the sub-point
    std::vector<double> weight;         // per entry
  };
  mutable StressBalls balls;

  void precompute_geometry();
  void build_pattern();
  void element(std::size_t e, const Eigen::VectorXd& u, axi::Vector12& f, axi::Matrix12* k,
               double& energy) const;
};

}  // namespace mneedle::fe
