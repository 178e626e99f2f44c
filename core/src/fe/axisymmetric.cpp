// Axisymmetric total Lagrangian 6-node triangle model and the needle insertion driver.
#include "mneedle/fe/axisymmetric.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include "mneedle/error.h"
#include "mneedle/fe/sparse_solver.h"

namespace mneedle::fe {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kNodes = 6;
constexpr int kDofs = 12;
constexpr int kQuadrature = 6;

using Matrix12 = Eigen::Matrix<double, kDofs, kDofs>;
using Vector12 = Eigen::Matrix<double, kDofs, 1>;
using Matrix4x12 = Eigen::Matrix<double, 4, kDofs>;

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

ShapeValues t6_shape(double xi, double eta) {
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

// Shape data in reference coordinates at one quadrature point; w includes 2 pi r.
struct PointData {
  double N[kNodes];
  double dr[kNodes];
  double dz[kNodes];
  double r;
  double w;
};

std::string format_depth(double depth_m) {
  std::ostringstream s;
  s.precision(4);
  s << depth_m * 1e6 << " um";
  return s.str();
}

}  // namespace

struct AxisymmetricModel::Impl {
  AxisymmetricMesh mesh;
  std::vector<Material> materials;
  bool linear = true;
  std::vector<PointData> points;        // element-major, kQuadrature per element
  Eigen::SparseMatrix<double> pattern;  // full symmetric pattern
  std::vector<int> slots;               // value index of (a, b) for each element, kDofs^2 each
  SparseSolver solver;
  bool analyzed = false;
  int factorizations = 0;

  void precompute_geometry();
  void build_pattern();
  void element(std::size_t e, const Eigen::VectorXd& u, Vector12& f, Matrix12* k,
               double& energy) const;
};

void AxisymmetricModel::Impl::precompute_geometry() {
  points.resize(mesh.elements.size() * kQuadrature);
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    const auto& nodes = mesh.elements[e];
    for (int q = 0; q < kQuadrature; ++q) {
      const ShapeValues s = t6_shape(kRule[q].xi, kRule[q].eta);
      Eigen::Matrix2d J = Eigen::Matrix2d::Zero();  // d(r,z)/d(xi,eta)
      double r = 0.0;
      for (int a = 0; a < kNodes; ++a) {
        const Eigen::Vector2d& X = mesh.nodes[nodes[a]];
        J(0, 0) += X.x() * s.dxi[a];
        J(0, 1) += X.x() * s.deta[a];
        J(1, 0) += X.y() * s.dxi[a];
        J(1, 1) += X.y() * s.deta[a];
        r += X.x() * s.N[a];
      }
      const double det = J.determinant();
      if (!(det > 0.0)) throw SolverError("axisymmetric mesh: element with non-positive area");
      const Eigen::Matrix2d Jinv = J.inverse();
      PointData& p = points[e * kQuadrature + q];
      for (int a = 0; a < kNodes; ++a) {
        p.N[a] = s.N[a];
        p.dr[a] = s.dxi[a] * Jinv(0, 0) + s.deta[a] * Jinv(1, 0);
        p.dz[a] = s.dxi[a] * Jinv(0, 1) + s.deta[a] * Jinv(1, 1);
      }
      p.r = r;
      p.w = 2.0 * kPi * r * det * 0.5 * kRule[q].weight;
    }
  }
}

void AxisymmetricModel::Impl::build_pattern() {
  const auto n = static_cast<Eigen::Index>(2 * mesh.nodes.size());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(mesh.elements.size() * kDofs * kDofs);
  auto dof = [](const std::array<std::uint32_t, 6>& el, int k) {
    return static_cast<int>(2 * el[k / 2] + k % 2);
  };
  for (const auto& el : mesh.elements)
    for (int a = 0; a < kDofs; ++a)
      for (int b = 0; b < kDofs; ++b) triplets.emplace_back(dof(el, a), dof(el, b), 0.0);
  pattern.resize(n, n);
  pattern.setFromTriplets(triplets.begin(), triplets.end());
  pattern.makeCompressed();
  slots.resize(mesh.elements.size() * kDofs * kDofs);
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  for (std::size_t e = 0; e < mesh.elements.size(); ++e)
    for (int a = 0; a < kDofs; ++a)
      for (int b = 0; b < kDofs; ++b) {
        const int row = dof(mesh.elements[e], a), col = dof(mesh.elements[e], b);
        const int* pos = std::lower_bound(inner + outer[col], inner + outer[col + 1], row);
        slots[(e * kDofs + a) * kDofs + b] = static_cast<int>(pos - inner);
      }
}

// Internal force and tangent of one element. Components (r, theta, z) map to material indices
// (0, 1, 2); the axisymmetric Voigt subset is rr, tt, zz, rz = material Voigt 0, 1, 2, 4.
void AxisymmetricModel::Impl::element(std::size_t e, const Eigen::VectorXd& u, Vector12& f,
                                      Matrix12* k, double& energy) const {
  static constexpr int kVoigt[4] = {0, 1, 2, 4};
  const auto& nodes = mesh.elements[e];
  const Material& material = materials[mesh.element_layer[e]];
  const bool small_strain = material.is_linear();
  double ur[kNodes], uz[kNodes];
  for (int a = 0; a < kNodes; ++a) {
    ur[a] = u[2 * nodes[a]];
    uz[a] = u[2 * nodes[a] + 1];
  }
  f.setZero();
  if (k) k->setZero();
  for (int q = 0; q < kQuadrature; ++q) {
    const PointData& p = points[e * kQuadrature + q];
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int a = 0; a < kNodes; ++a) {
      F(0, 0) += p.dr[a] * ur[a];
      F(0, 2) += p.dz[a] * ur[a];
      F(2, 0) += p.dr[a] * uz[a];
      F(2, 2) += p.dz[a] * uz[a];
      F(1, 1) += p.N[a] * ur[a] / p.r;
    }
    if (!small_strain && !(F(1, 1) * (F(0, 0) * F(2, 2) - F(0, 2) * F(2, 0)) > 0.0))
      throw SolverError("inverted element in layer " + std::to_string(mesh.element_layer[e]));
    const MaterialResponse m = material.evaluate(F);
    // Small strain: B at the reference state and no geometric stiffness.
    const Eigen::Matrix3d Fb = small_strain ? Eigen::Matrix3d::Identity() : F;
    Matrix4x12 B;
    for (int a = 0; a < kNodes; ++a) {
      const int c = 2 * a;
      B(0, c) = Fb(0, 0) * p.dr[a];
      B(0, c + 1) = Fb(2, 0) * p.dr[a];
      B(1, c) = Fb(1, 1) * p.N[a] / p.r;
      B(1, c + 1) = 0.0;
      B(2, c) = Fb(0, 2) * p.dz[a];
      B(2, c + 1) = Fb(2, 2) * p.dz[a];
      B(3, c) = Fb(0, 0) * p.dz[a] + Fb(0, 2) * p.dr[a];
      B(3, c + 1) = Fb(2, 0) * p.dz[a] + Fb(2, 2) * p.dr[a];
    }
    const Eigen::Vector4d S(m.S(0, 0), m.S(1, 1), m.S(2, 2), m.S(0, 2));
    f.noalias() += p.w * B.transpose() * S;
    energy += p.w * m.energy_density;
    if (!k) continue;
    Eigen::Matrix4d C;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) C(i, j) = m.C(kVoigt[i], kVoigt[j]);
    k->noalias() += p.w * B.transpose() * C * B;
    if (small_strain) continue;
    for (int a = 0; a < kNodes; ++a)
      for (int b = 0; b < kNodes; ++b) {
        const double g = S(0) * p.dr[a] * p.dr[b] + S(2) * p.dz[a] * p.dz[b] +
                         S(3) * (p.dr[a] * p.dz[b] + p.dz[a] * p.dr[b]);
        (*k)(2 * a, 2 * b) += p.w * (g + S(1) * p.N[a] * p.N[b] / (p.r * p.r));
        (*k)(2 * a + 1, 2 * b + 1) += p.w * g;
      }
  }
}

AxisymmetricModel::AxisymmetricModel(AxisymmetricMesh mesh,
                                     const std::vector<MaterialParameters>& layer_materials)
    : impl_(std::make_unique<Impl>()) {
  impl_->mesh = std::move(mesh);
  for (const MaterialParameters& p : layer_materials) impl_->materials.emplace_back(p);
  for (int layer : impl_->mesh.element_layer)
    if (layer < 0 || layer >= static_cast<int>(impl_->materials.size()))
      throw InputError("axisymmetric model: element layer " + std::to_string(layer) +
                       " has no material");
  for (const Material& m : impl_->materials) impl_->linear = impl_->linear && m.is_linear();
  impl_->precompute_geometry();
  impl_->build_pattern();
}

AxisymmetricModel::~AxisymmetricModel() = default;
AxisymmetricModel::AxisymmetricModel(AxisymmetricModel&&) noexcept = default;
AxisymmetricModel& AxisymmetricModel::operator=(AxisymmetricModel&&) noexcept = default;

const AxisymmetricMesh& AxisymmetricModel::mesh() const {
  return impl_->mesh;
}
std::size_t AxisymmetricModel::dof_count() const {
  return 2 * impl_->mesh.nodes.size();
}
bool AxisymmetricModel::is_linear() const {
  return impl_->linear;
}
int AxisymmetricModel::factorization_count() const {
  return impl_->factorizations;
}

Eigen::VectorXd AxisymmetricModel::internal_force(const Eigen::VectorXd& u, double* energy,
                                                  Eigen::SparseMatrix<double>* tangent) const {
  const Impl& m = *impl_;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dof_count()));
  if (tangent) {
    *tangent = m.pattern;
    std::fill(tangent->valuePtr(), tangent->valuePtr() + tangent->nonZeros(), 0.0);
  }
  double total_energy = 0.0;
  Vector12 fe;
  Matrix12 ke;
  for (std::size_t e = 0; e < m.mesh.elements.size(); ++e) {
    m.element(e, u, fe, tangent ? &ke : nullptr, total_energy);
    const auto& nodes = m.mesh.elements[e];
    for (int a = 0; a < kDofs; ++a) f[2 * nodes[a / 2] + a % 2] += fe[a];
    if (!tangent) continue;
    double* values = tangent->valuePtr();
    const int* slot = &m.slots[e * kDofs * kDofs];
    for (int a = 0; a < kDofs; ++a)
      for (int b = 0; b < kDofs; ++b) values[slot[a * kDofs + b]] += ke(a, b);
  }
  if (energy) *energy = total_energy;
  return f;
}

namespace {

// Zeroes the rows and columns of constrained dofs and puts `diagonal` on their diagonal, so the
// sparsity pattern (and its symbolic factorisation) stays the same for every constraint set.
void constrain(Eigen::SparseMatrix<double>& K, const std::vector<char>& is_constrained,
               double diagonal) {
  for (int col = 0; col < K.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
      if (is_constrained[it.row()] || is_constrained[col])
        it.valueRef() = it.row() == col ? diagonal : 0.0;
}

double free_norm(const Eigen::VectorXd& v, const std::vector<char>& is_constrained) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!is_constrained[i]) sum += v[i] * v[i];
  return std::sqrt(sum);
}

double constrained_norm(const Eigen::VectorXd& v, const std::vector<char>& is_constrained) {
  double sum = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (is_constrained[i]) sum += v[i] * v[i];
  return std::sqrt(sum);
}

}  // namespace

Equilibrium AxisymmetricModel::solve(const std::vector<std::uint32_t>& prescribed_dofs,
                                     const Eigen::VectorXd& prescribed_values,
                                     const Eigen::VectorXd& start, const NewtonOptions& options) {
  Impl& m = *impl_;
  const auto n = static_cast<Eigen::Index>(dof_count());
  std::vector<char> is_constrained(static_cast<std::size_t>(n), 0);
  Eigen::VectorXd remaining = Eigen::VectorXd::Zero(n);  // prescribed increment still to apply
  Equilibrium eq;
  eq.displacement = start;
  for (std::size_t i = 0; i < prescribed_dofs.size(); ++i) {
    is_constrained[prescribed_dofs[i]] = 1;
    remaining[prescribed_dofs[i]] =
        prescribed_values[static_cast<Eigen::Index>(i)] - start[prescribed_dofs[i]];
  }
  Eigen::SparseMatrix<double> K;
  double previous_residual = std::numeric_limits<double>::infinity();
  double before_previous = std::numeric_limits<double>::infinity();
  bool factorized = false;
  for (int iteration = 0;; ++iteration) {
    // Modified Newton: keep this solve's factorisation while the residual falls fast.
    const bool reuse = options.modified_newton && factorized && iteration >= 2 &&
                       previous_residual < 0.25 * before_previous;
    eq.reaction = internal_force(eq.displacement, &eq.strain_energy_J, reuse ? nullptr : &K);
    const double residual = free_norm(eq.reaction, is_constrained);
    const double reference = std::max(constrained_norm(eq.reaction, is_constrained), 1e-30);
    const bool applied = remaining.lpNorm<Eigen::Infinity>() == 0.0;
    // Round-off floor: once the residual is small and stops falling, more iterations are noise.
    const bool stagnated = iteration >= 2 && residual <= options.stagnation_tolerance * reference &&
                           residual > 0.5 * previous_residual;
    before_previous = previous_residual;
    previous_residual = residual;
    if (applied && (residual <= options.residual_tolerance * reference || stagnated ||
                    (m.linear && iteration > 0))) {
      eq.newton_iterations = iteration;
      return eq;
    }
    if (iteration >= options.max_iterations)
      throw SolverError("Newton did not converge in " + std::to_string(iteration) +
                        " iterations (relative residual " + std::to_string(residual / reference) +
                        ")");
    Eigen::VectorXd rhs;
    if (reuse) {
      rhs = -eq.reaction;
      for (Eigen::Index i = 0; i < n; ++i)
        if (is_constrained[i]) rhs[i] = 0.0;
    } else {
      // rhs_free = -R - K_fc * du_c; rhs_c = diagonal * du_c.
      rhs = -eq.reaction - K * remaining;
      const double diagonal = K.diagonal().cwiseAbs().mean();
      for (Eigen::Index i = 0; i < n; ++i)
        if (is_constrained[i]) rhs[i] = diagonal * remaining[i];
      constrain(K, is_constrained, diagonal);
      if (!m.analyzed) {
        m.solver.analyze(K);
        m.analyzed = true;
      }
      m.solver.factorize(K);
      ++m.factorizations;
      if (!m.solver.ok()) throw SolverError("singular stiffness matrix");
      factorized = true;
    }
    const Eigen::VectorXd step = m.solver.solve(rhs);
    if (!step.allFinite()) throw SolverError("singular stiffness matrix (non-finite solution)");
    // Backtracking line search on the free residual once the prescribed values are in place.
    double alpha = 1.0;
    if (applied && !m.linear) {
      for (int trial = 0; trial < 8; ++trial, alpha *= 0.5) {
        try {
          const Eigen::VectorXd r =
              internal_force(eq.displacement + alpha * step, nullptr, nullptr);
          if (free_norm(r, is_constrained) < residual) break;
        } catch (const SolverError&) {
          // An inverted element at the full step: try a shorter one.
        }
      }
    }
    eq.displacement += alpha * step;
    remaining.setZero();
  }
}

// ------------------------------------------------------------------------------------------
// Insertion driver.

namespace {

// A captured surface node: where and at which depth the needle reached it (sticking contact).
struct Capture {
  Eigen::Vector2d point;
  double depth;
};

struct ContactState {
  std::map<std::uint32_t, Capture> captured;  // node -> capture
};

// Height of the needle's lower surface at radius r when its tip is at depth d, minus the node's
// height: negative when the node is inside the needle.
double gap(const AxisymmetricNeedle& needle, double depth, const Eigen::Vector2d& position) {
  return -depth + needle.lowest_height_at(position.x()) - position.y();
}

// Captures every candidate node that entered the needle between (d0, u0) and (d1, u1), at the
// linearly interpolated crossing. Returns how many were added.
int capture_new_nodes(const AxisymmetricNeedle& needle,
                      const std::vector<std::uint32_t>& candidates, const AxisymmetricMesh& mesh,
                      double d0, const Eigen::VectorXd& u0, double d1, const Eigen::VectorXd& u1,
                      ContactState& state) {
  int added = 0;
  for (std::uint32_t node : candidates) {
    if (state.captured.count(node)) continue;
    const Eigen::Vector2d X = mesh.nodes[node];
    const Eigen::Vector2d p0 = X + Eigen::Vector2d(u0[2 * node], u0[2 * node + 1]);
    const Eigen::Vector2d p1 = X + Eigen::Vector2d(u1[2 * node], u1[2 * node + 1]);
    const double g1 = gap(needle, d1, p1);
    if (!(g1 < 0.0)) continue;
    const double g0 = gap(needle, d0, p0);
    const double t = std::isfinite(g0) && g0 > 0.0 ? g0 / (g0 - g1) : 0.0;
    state.captured[node] = Capture{p0 + t * (p1 - p0), d0 + t * (d1 - d0)};
    ++added;
  }
  return added;
}

Eigen::Vector2d captured_displacement(const AxisymmetricMesh& mesh, std::uint32_t node,
                                      const Capture& c, double depth) {
  return c.point + Eigen::Vector2d(0.0, -(depth - c.depth)) - mesh.nodes[node];
}

// Projected contact area: the annulus between the innermost and outermost captured surface
// nodes, each extended half-way to its free neighbour and clipped to the needle's section.
double contact_area(const AxisymmetricMesh& mesh, const AxisymmetricNeedle& needle,
                    const ContactState& state, const Eigen::VectorXd& u) {
  const auto& surface = mesh.surface_nodes;
  int first = -1, last = -1;
  for (int i = 0; i < static_cast<int>(surface.size()); ++i)
    if (state.captured.count(surface[i])) {
      if (first < 0) first = i;
      last = i;
    }
  if (first < 0) return 0.0;
  auto radius = [&](int i) { return mesh.nodes[surface[i]].x() + u[2 * surface[i]]; };
  double outer = radius(last);
  if (last + 1 < static_cast<int>(surface.size()))
    outer = std::min(0.5 * (outer + radius(last + 1)), needle.max_radius());
  double inner = first == 0 ? 0.0 : radius(first);
  if (first > 0) inner = std::max(0.5 * (inner + radius(first - 1)), needle.bore_radius_m);
  return kPi * std::max(outer * outer - inner * inner, 0.0);
}

std::vector<std::uint32_t> reachable_surface_nodes(const AxisymmetricMesh& mesh,
                                                   const AxisymmetricNeedle& needle, double depth) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t node : mesh.surface_nodes)
    if (needle.lowest_height_at(mesh.nodes[node].x()) <= depth) out.push_back(node);
  return out;
}

InsertionStep make_step(double depth, double force, double area, double energy, int iterations,
                        int contacts) {
  InsertionStep s;
  s.depth_m = depth;
  s.force_N = force;
  s.contact_area_m2 = area;
  s.contact_pressure_Pa = area > 0.0 ? force / area : 0.0;
  s.strain_energy_J = energy;
  s.newton_iterations = iterations;
  s.contact_nodes = contacts;
  return s;
}

void require_finite(const InsertionStep& s) {
  if (!std::isfinite(s.force_N) || !std::isfinite(s.strain_energy_J) ||
      !std::isfinite(s.contact_pressure_Pa))
    throw SolverError("non-finite result at depth " + format_depth(s.depth_m));
}

// Dirichlet set of the clamped boundary, the symmetry axis and the captured nodes at depth d.
void boundary_conditions(const AxisymmetricMesh& mesh, const ContactState& state, double depth,
                         std::vector<std::uint32_t>& dofs, Eigen::VectorXd& values) {
  std::map<std::uint32_t, double> fixed;
  for (std::uint32_t node : mesh.fixed_nodes) {
    fixed[2 * node] = 0.0;
    fixed[2 * node + 1] = 0.0;
  }
  for (std::uint32_t node : mesh.axis_nodes) fixed[2 * node] = 0.0;
  for (const auto& [node, capture] : state.captured) {
    const Eigen::Vector2d u = captured_displacement(mesh, node, capture, depth);
    if (mesh.nodes[node].x() > 0.0) fixed[2 * node] = u.x();
    fixed[2 * node + 1] = u.y();
  }
  dofs.clear();
  values.resize(static_cast<Eigen::Index>(fixed.size()));
  Eigen::Index i = 0;
  for (const auto& [dof, value] : fixed) {
    dofs.push_back(dof);
    values[i++] = value;
  }
}

double needle_force(const ContactState& state, const Eigen::VectorXd& reaction) {
  double force = 0.0;
  for (const auto& entry : state.captured) force -= reaction[2 * entry.first + 1];
  return force;
}

// Nonlinear insertion: Newton at every sub-step, adaptive step length.
InsertionResult insert_nonlinear(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                                 const InsertionOptions& options) {
  const AxisymmetricMesh& mesh = model.mesh();
  const std::vector<std::uint32_t> candidates =
      reachable_surface_nodes(mesh, needle, options.depth_m);
  InsertionResult result;
  ContactState state;
  Equilibrium current;
  current.displacement = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.dof_count()));
  current.reaction = current.displacement;
  double depth = 0.0;
  const double interval = options.depth_m / options.output_steps;
  double step = interval;
  const double min_step = 1e-5 * options.depth_m;
  std::vector<std::uint32_t> dofs;
  Eigen::VectorXd values;
  for (int k = 1; k <= options.output_steps; ++k) {
    const double target = options.depth_m * k / options.output_steps;
    int iterations = 0;
    while (depth < target * (1.0 - 1e-12)) {
      step = std::min(step, target - depth);
      const double next = depth + step;
      ContactState trial_state = state;
      int trial_iterations = 0;
      std::string failure;
      Equilibrium trial;
      try {
        boundary_conditions(mesh, trial_state, next, dofs, values);
        trial = model.solve(dofs, values, current.displacement, options.newton);
        trial_iterations += trial.newton_iterations;
        for (int round = 0; round < 50; ++round) {
          if (capture_new_nodes(needle, candidates, mesh, depth, current.displacement, next,
                                trial.displacement, trial_state) == 0)
            break;
          boundary_conditions(mesh, trial_state, next, dofs, values);
          trial = model.solve(dofs, values, trial.displacement, options.newton);
          trial_iterations += trial.newton_iterations;
        }
      } catch (const SolverError& e) {
        failure = e.what();
      }
      if (!failure.empty()) {
        step *= 0.5;
        if (step < min_step)
          throw SolverError("axisymmetric insertion stopped at depth " + format_depth(depth) +
                            ": " + failure);
        continue;
      }
      depth = next;
      current = std::move(trial);
      state = std::move(trial_state);
      iterations += trial_iterations;
      if (trial_iterations <= 6) step = std::min(step * 1.5, interval);
    }
    const double force = needle_force(state, current.reaction);
    const double area = contact_area(mesh, needle, state, current.displacement);
    result.steps.push_back(make_step(depth, force, area, current.strain_energy_J, iterations,
                                     static_cast<int>(state.captured.size())));
    require_finite(result.steps.back());
  }
  return result;
}

// Linear insertion: one factorisation, the stiffness condensed onto the reachable surface dofs
// (Schur complement S); every depth is then a small dense solve.
class CondensedSurface {
 public:
  CondensedSurface(AxisymmetricModel& model, const std::vector<std::uint32_t>& candidates)
      : candidates_(candidates) {
    const AxisymmetricMesh& mesh = model.mesh();
    for (std::uint32_t node : candidates) {
      index_[node] = static_cast<int>(dofs_.size());
      dofs_.push_back(2 * node);
      dofs_.push_back(2 * node + 1);
    }
    const auto n = static_cast<Eigen::Index>(model.dof_count());
    std::vector<char> constrained(static_cast<std::size_t>(n), 0);
    for (std::uint32_t node : mesh.fixed_nodes)
      constrained[2 * node] = constrained[2 * node + 1] = 1;
    for (std::uint32_t node : mesh.axis_nodes) constrained[2 * node] = 1;
    axis_fixed_.assign(dofs_.size(), 0);
    for (std::size_t j = 0; j < dofs_.size(); ++j) {
      if (constrained[dofs_[j]]) axis_fixed_[j] = 1;  // u_r on the axis stays zero
      constrained[dofs_[j]] = 1;
    }
    Eigen::SparseMatrix<double> K;
    model.internal_force(Eigen::VectorXd::Zero(n), nullptr, &K);
    const Eigen::SparseMatrix<double> K_full = K;
    const double diagonal = K.diagonal().cwiseAbs().mean();
    constrain(K, constrained, diagonal);
    SparseSolver solver;
    solver.analyze(K);
    solver.factorize(K);
    if (!solver.ok()) throw SolverError("singular stiffness matrix at depth 0");
    const auto m = static_cast<Eigen::Index>(dofs_.size());
    // Column j: free-dof response to a unit displacement of candidate dof j.
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(n, m);
    for (Eigen::Index j = 0; j < m; ++j) unit(dofs_[j], j) = 1.0;
    Eigen::MatrixXd rhs = -(K_full * unit);
    for (Eigen::Index i = 0; i < n; ++i)
      if (constrained[i]) rhs.row(i).setZero();
    Eigen::MatrixXd response = solver.solve_many(rhs) + unit;
    const Eigen::MatrixXd forces = K_full * response;
    S_.resize(m, m);
    for (Eigen::Index i = 0; i < m; ++i) S_.row(i) = forces.row(dofs_[i]);
    S_ = 0.5 * (S_ + S_.transpose());
  }

  const std::vector<std::uint32_t>& dofs() const { return dofs_; }

  // Candidate displacements and forces with the captured nodes prescribed and the rest free.
  void solve(const AxisymmetricMesh& mesh, const ContactState& state, double depth,
             Eigen::VectorXd& u, Eigen::VectorXd& f) const {
    const auto m = static_cast<Eigen::Index>(dofs_.size());
    std::vector<char> prescribed(static_cast<std::size_t>(m), 0);
    u = Eigen::VectorXd::Zero(m);
    for (Eigen::Index j = 0; j < m; ++j) prescribed[j] = axis_fixed_[j];
    for (const auto& [node, capture] : state.captured) {
      const Eigen::Vector2d d = captured_displacement(mesh, node, capture, depth);
      const int j = index_.at(node);
      prescribed[j] = prescribed[j + 1] = 1;
      u[j] = axis_fixed_[j] ? 0.0 : d.x();
      u[j + 1] = d.y();
    }
    std::vector<Eigen::Index> free, fixed;
    for (Eigen::Index j = 0; j < m; ++j) (prescribed[j] ? fixed : free).push_back(j);
    if (!free.empty()) {
      Eigen::MatrixXd S_ff(free.size(), free.size());
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(free.size()));
      for (std::size_t a = 0; a < free.size(); ++a) {
        for (std::size_t b = 0; b < free.size(); ++b) S_ff(a, b) = S_(free[a], free[b]);
        for (Eigen::Index c : fixed) rhs[a] -= S_(free[a], c) * u[c];
      }
      const Eigen::VectorXd uf = S_ff.ldlt().solve(rhs);
      for (std::size_t a = 0; a < free.size(); ++a) u[free[a]] = uf[a];
    }
    f = S_ * u;
  }

  // Frictionless: the active nodes lie on the needle's profile (one linear constraint each,
  // free to slide along it); minimise the condensed energy with Lagrange multipliers.
  void solve_frictionless(const AxisymmetricMesh& mesh, const AxisymmetricNeedle& needle,
                          double depth, const std::map<std::uint32_t, double>& slopes,
                          Eigen::VectorXd& u, Eigen::VectorXd& f) const {
    const auto m = static_cast<Eigen::Index>(dofs_.size());
    std::vector<std::pair<Eigen::Index, std::uint32_t>> rows;
    Eigen::Index count = 0;
    for (Eigen::Index j = 0; j < m; ++j) count += axis_fixed_[j];
    count += static_cast<Eigen::Index>(slopes.size());
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(count, m);
    Eigen::VectorXd c = Eigen::VectorXd::Zero(count);
    Eigen::Index row = 0;
    for (Eigen::Index j = 0; j < m; ++j)
      if (axis_fixed_[j]) G(row++, j) = 1.0;
    for (const auto& [node, slope] : slopes) {
      // Profile segment z = -d + h0 + slope (r - r0) through the node's section.
      const int j = index_.at(node);
      const Eigen::Vector2d X = mesh.nodes[node];
      const double h_at_X = needle.lowest_height_at(X.x());
      const double level = std::isfinite(h_at_X) ? -depth + h_at_X : -depth;
      G(row, j) = -slope;
      G(row, j + 1) = 1.0;
      c[row] = level - X.y();
      ++row;
    }
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(m + count, m + count);
    kkt.topLeftCorner(m, m) = S_;
    kkt.topRightCorner(m, count) = G.transpose();
    kkt.bottomLeftCorner(count, m) = G;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + count);
    rhs.tail(count) = c;
    const Eigen::VectorXd x = kkt.fullPivLu().solve(rhs);
    u = x.head(m);
    f = S_ * u;
  }

  int index_of(std::uint32_t node) const { return index_.at(node); }

  // Full-length displacement vector holding only the candidates' values (for capture tests).
  Eigen::VectorXd scatter(const Eigen::VectorXd& u, std::size_t n) const {
    Eigen::VectorXd full = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < dofs_.size(); ++j) full[dofs_[j]] = u[static_cast<Eigen::Index>(j)];
    return full;
  }

 private:
  std::vector<std::uint32_t> candidates_;
  std::vector<std::uint32_t> dofs_;
  std::vector<char> axis_fixed_;
  std::map<std::uint32_t, int> index_;
  Eigen::MatrixXd S_;
};

InsertionResult insert_linear(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                              const InsertionOptions& options) {
  const AxisymmetricMesh& mesh = model.mesh();
  const std::vector<std::uint32_t> candidates =
      reachable_surface_nodes(mesh, needle, options.depth_m);
  InsertionResult result;
  result.factorizations = 1;
  if (candidates.empty()) {
    for (int k = 1; k <= options.output_steps; ++k)
      result.steps.push_back(make_step(options.depth_m * k / options.output_steps, 0, 0, 0, 0, 0));
    return result;
  }
  const CondensedSurface surface(model, candidates);
  const std::size_t n = model.dof_count();
  ContactState state;
  Eigen::VectorXd previous = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  double depth = 0.0;
  // Sub-steps only refine where captures happen; the solve itself is exact at any depth.
  constexpr int kSubsteps = 4;
  const int total = options.output_steps * kSubsteps;
  Eigen::VectorXd u, f;
  for (int k = 1; k <= total; ++k) {
    const double next = options.depth_m * k / total;
    int solves = 0;
    for (int round = 0; round < 1000; ++round) {
      surface.solve(mesh, state, next, u, f);
      ++solves;
      if (capture_new_nodes(needle, candidates, mesh, depth, previous, next, surface.scatter(u, n),
                            state) == 0)
        break;
    }
    depth = next;
    previous = surface.scatter(u, n);
    if (k % kSubsteps != 0) continue;
    double force = 0.0;
    for (const auto& entry : state.captured) {
      const auto it = std::find(surface.dofs().begin(), surface.dofs().end(), 2 * entry.first + 1);
      force -= f[it - surface.dofs().begin()];
    }
    const double energy = 0.5 * u.dot(f);
    const double area = contact_area(mesh, needle, state, previous);
    result.steps.push_back(
        make_step(depth, force, area, energy, solves, static_cast<int>(state.captured.size())));
    require_finite(result.steps.back());
  }
  return result;
}

// Linear frictionless insertion: active set on the condensed surface; each depth solved
// independently (elastic, no history), starting from the previous active set.
InsertionResult insert_linear_frictionless(AxisymmetricModel& model,
                                           const AxisymmetricNeedle& needle,
                                           const InsertionOptions& options) {
  const AxisymmetricMesh& mesh = model.mesh();
  const std::vector<std::uint32_t> candidates =
      reachable_surface_nodes(mesh, needle, options.depth_m);
  InsertionResult result;
  result.factorizations = 1;
  if (candidates.empty()) throw InputError("frictionless contact: the needle reaches no node");
  const CondensedSurface surface(model, candidates);
  // Slope dh/dr of the profile where a node sits (0 on a flat face).
  auto slope_at = [&needle](double r) {
    const auto& R = needle.radii_m;
    const auto& H = needle.heights_m;
    if (R.empty() || r <= R.front()) return 0.0;
    for (std::size_t i = 1; i < R.size(); ++i)
      if (r <= R[i] && R[i] > R[i - 1]) return (H[i] - H[i - 1]) / (R[i] - R[i - 1]);
    return 0.0;
  };
  std::map<std::uint32_t, double> active;
  Eigen::VectorXd u, f;
  for (int k = 1; k <= options.output_steps; ++k) {
    const double depth = options.depth_m * k / options.output_steps;
    int solves = 0;
    for (bool changed = true; changed && solves < 200;) {
      changed = false;
      surface.solve_frictionless(mesh, needle, depth, active, u, f);
      ++solves;
      // Release the node pulled hardest (tensile normal force), else add penetrating nodes.
      std::uint32_t worst = 0;
      double worst_pull = 0.0;
      for (const auto& [node, slope] : active) {
        const int j = surface.index_of(node);
        const double pull = -slope * f[j] + f[j + 1];  // along the profile's upward normal
        if (pull > worst_pull) worst = node, worst_pull = pull;
      }
      if (worst_pull > 1e-12 * std::max(1.0, f.norm())) {
        active.erase(worst);
        changed = true;
        continue;
      }
      for (std::uint32_t node : candidates) {
        if (active.count(node)) continue;
        const int j = surface.index_of(node);
        const Eigen::Vector2d p = mesh.nodes[node] + Eigen::Vector2d(u[j], u[j + 1]);
        if (gap(needle, depth, p) < -1e-12 * options.depth_m) {
          active[node] = slope_at(mesh.nodes[node].x());
          changed = true;
        }
      }
    }
    double force = 0.0;
    ContactState state;
    Eigen::VectorXd full = surface.scatter(u, model.dof_count());
    for (const auto& entry : active) {
      force -= f[surface.index_of(entry.first) + 1];
      state.captured[entry.first] = Capture{Eigen::Vector2d::Zero(), 0.0};
    }
    const double area = contact_area(mesh, needle, state, full);
    result.steps.push_back(
        make_step(depth, force, area, 0.5 * u.dot(f), solves, static_cast<int>(active.size())));
    require_finite(result.steps.back());
  }
  return result;
}
}  // namespace

InsertionResult insert_needle(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                              const InsertionOptions& options) {
  if (!(options.depth_m > 0.0)) throw InputError("insertion depth must be > 0 m");
  if (options.output_steps < 1) throw InputError("insertion needs at least one output step");
  const bool frictionless = options.contact == ContactMode::Frictionless;
  if (frictionless && !model.is_linear())
    throw InputError(
        "axisymmetric solver: frictionless contact needs linear layers for now; use sticking");
  const auto start = std::chrono::steady_clock::now();
  const int before = model.factorization_count();
  InsertionResult result = frictionless        ? insert_linear_frictionless(model, needle, options)
                           : model.is_linear() ? insert_linear(model, needle, options)
                                               : insert_nonlinear(model, needle, options);
  if (!model.is_linear()) result.factorizations = model.factorization_count() - before;
  result.nodes = model.mesh().nodes.size();
  result.elements = model.mesh().elements.size();
  result.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

AxisymmetricMeshOptions mesh_options_for(const AxisymmetricProblem& problem) {
  const AxisymmetricNeedle& needle = problem.needle;
  // Contact radius scale: the needle's section where it crosses the undeformed surface.
  double a = needle.max_radius();
  for (std::size_t i = 1; i < needle.heights_m.size(); ++i)
    if (problem.depth_m < needle.heights_m[i]) {
      const double t = (problem.depth_m - needle.heights_m[i - 1]) /
                       (needle.heights_m[i] - needle.heights_m[i - 1]);
      a = needle.radii_m[i - 1] + t * (needle.radii_m[i] - needle.radii_m[i - 1]);
      break;
    }
  a = std::max(a, 1e-3 * problem.depth_m);
  int per_radius = 8;
  double growth = 1.3;
  if (problem.fidelity == Fidelity::Fast) per_radius = 4, growth = 1.45;
  if (problem.fidelity == Fidelity::Fine) per_radius = 16, growth = 1.2;
  AxisymmetricMeshOptions o;
  o.radius_m = problem.radius_m;
  o.h_m = std::min(a / per_radius, problem.radius_m);
  o.fine_radius_m = 2.0 * a;
  o.fine_depth_m = problem.depth_m + a;
  o.growth = growth;
  o.max_size_m = problem.radius_m / 8.0;
  o.radial_breaks_m = {needle.bore_radius_m, needle.max_radius()};
  // The flat face edge must be a node column; a sampled profile adds no further breaks.
  if (!needle.radii_m.empty()) o.radial_breaks_m.push_back(needle.radii_m.front());
  return o;
}

InsertionResult simulate_axisymmetric(const AxisymmetricProblem& problem) {
  const auto start = std::chrono::steady_clock::now();
  AxisymmetricMesh mesh = make_axisymmetric_mesh(problem.layers, mesh_options_for(problem));
  std::vector<MaterialParameters> materials;
  for (const AxisymmetricLayer& l : problem.layers) materials.push_back(l.material);
  AxisymmetricModel model(std::move(mesh), materials);
  const double mesh_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  InsertionOptions options;
  options.depth_m = problem.depth_m;
  options.contact = problem.contact;
  options.output_steps = problem.output_steps > 0             ? problem.output_steps
                         : problem.fidelity == Fidelity::Fast ? 10
                         : problem.fidelity == Fidelity::Fine ? 40
                                                              : 20;
  InsertionResult result = insert_needle(model, problem.needle, options);
  result.mesh_seconds = mesh_seconds;
  return result;
}

}  // namespace mneedle::fe
