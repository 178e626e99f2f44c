// Axisymmetric total Lagrangian 6-node triangle model: geometry, assembly and equilibrium.
#include "mneedle/fe/axisymmetric.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "axisymmetric_internal.h"
#include "mneedle/base/error.h"

namespace mneedle::fe {

using namespace axi;

namespace axi {

PointData point_data(const AxisymmetricMesh& mesh, const std::array<std::uint32_t, 6>& nodes,
                     double xi, double eta, double weight) {
  const ShapeValues s = t6_shape(xi, eta);
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
  PointData p;
  for (int a = 0; a < kNodes; ++a) {
    p.N[a] = s.N[a];
    p.dr[a] = s.dxi[a] * Jinv(0, 0) + s.deta[a] * Jinv(1, 0);
    p.dz[a] = s.dxi[a] * Jinv(0, 1) + s.deta[a] * Jinv(1, 1);
  }
  p.r = r;
  p.w = 2.0 * kPi * r * det * 0.5 * weight;
  return p;
}

Eigen::Matrix3d deformation_gradient(const PointData& p, const Eigen::VectorXd& u,
                                     const std::array<std::uint32_t, 6>& nodes) {
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (int a = 0; a < kNodes; ++a) {
    const double ur = u[2 * nodes[a]], uz = u[2 * nodes[a] + 1];
    F(0, 0) += p.dr[a] * ur;
    F(0, 2) += p.dz[a] * ur;
    F(2, 0) += p.dr[a] * uz;
    F(2, 2) += p.dz[a] * uz;
    F(1, 1) += p.N[a] * ur / p.r;
  }
  return F;
}

Eigen::Matrix3d cauchy_stress(const Material& material, const Eigen::Matrix3d& F,
                              MaterialResponse* response) {
  const MaterialResponse m = material.evaluate(F);
  if (response) *response = m;
  if (material.is_linear()) return m.S;
  return F * m.S * F.transpose() / F.determinant();
}

void constrain(Eigen::SparseMatrix<double>& K, const std::vector<char>& is_constrained,
               double diagonal) {
  for (int col = 0; col < K.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
      if (is_constrained[it.row()] || is_constrained[col])
        it.valueRef() = it.row() == col ? diagonal : 0.0;
}

}  // namespace axi

void AxisymmetricModel::Impl::precompute_geometry() {
  points.resize(mesh.elements.size() * kQuadrature);
  for (std::size_t e = 0; e < mesh.elements.size(); ++e)
    for (int q = 0; q < kQuadrature; ++q)
      points[e * kQuadrature + q] =
          point_data(mesh, mesh.elements[e], kRule[q].xi, kRule[q].eta, kRule[q].weight);
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
  for (const auto& [in, out] : face_pairs) {
    triplets.emplace_back(2 * in, 2 * out, 0.0);
    triplets.emplace_back(2 * out, 2 * in, 0.0);
  }
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
  const auto slot = [&](std::uint32_t row, std::uint32_t col) {
    const int* pos =
        std::lower_bound(inner + outer[col], inner + outer[col + 1], static_cast<int>(row));
    return static_cast<int>(pos - inner);
  };
  pair_slots.clear();
  for (const auto& [in, out] : face_pairs)
    pair_slots.push_back({slot(2 * in, 2 * in), slot(2 * out, 2 * out), slot(2 * in, 2 * out),
                          slot(2 * out, 2 * in)});
}

// Internal force and tangent of one element. Components (r, theta, z) map to material indices
// (0, 1, 2); the axisymmetric Voigt subset is rr, tt, zz, rz = material Voigt 0, 1, 2, 4.
void AxisymmetricModel::Impl::element(std::size_t e, const Eigen::VectorXd& u, Vector12& f,
                                      Matrix12* k, double& energy) const {
  static constexpr int kVoigt[4] = {0, 1, 2, 4};
  const auto& nodes = mesh.elements[e];
  const Material& material = materials[mesh.element_layer[e]];
  const bool small_strain = material.is_linear();
  f.setZero();
  if (k) k->setZero();
  for (int q = 0; q < kQuadrature; ++q) {
    const PointData& p = points[e * kQuadrature + q];
    const Eigen::Matrix3d F = deformation_gradient(p, u, nodes);
    if (!small_strain && !(F(1, 1) * (F(0, 0) * F(2, 2) - F(0, 2) * F(2, 0)) > 0.0))
      throw SolverError("inverted element in layer " + std::to_string(mesh.element_layer[e]));
    const MaterialResponse m = material.evaluate(F);
    // Small strain: B at the reference state and no geometric stiffness.
    const Eigen::Matrix3d Fb = small_strain ? Eigen::Matrix3d::Identity() : F;
    Eigen::Matrix<double, 4, kDofs> B;
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
  impl_->parameters = layer_materials;
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
  // Closed crack-face pairs: the radial force lambda + k g on the outer node and its opposite on
  // the inner one, g = u_r(outer) - u_r(inner); their energy is not strain energy and is left out.
  for (std::size_t p = 0; p < m.face_pairs.size(); ++p) {
    if (!m.pair_closed[p]) continue;
    const auto [in, out] = m.face_pairs[p];
    const auto i = static_cast<Eigen::Index>(p);
    const double k = m.pair_penalty[i];
    const double t = m.pair_multiplier[i] + k * (u[2 * out] - u[2 * in]);
    f[2 * out] += t;
    f[2 * in] -= t;
    if (!tangent) continue;
    double* values = tangent->valuePtr();
    values[m.pair_slots[p][0]] += k;
    values[m.pair_slots[p][1]] += k;
    values[m.pair_slots[p][2]] -= k;
    values[m.pair_slots[p][3]] -= k;
  }
  if (energy) *energy = total_energy;
  return f;
}

void AxisymmetricModel::set_face_pairs(std::vector<std::array<std::uint32_t, 2>> pairs) {
  Impl& m = *impl_;
  for (const auto& pair : pairs)
    for (std::uint32_t node : pair)
      if (node >= m.mesh.nodes.size())
        throw InputError("axisymmetric model: crack-face pair names node " + std::to_string(node) +
                         " of " + std::to_string(m.mesh.nodes.size()));
  m.face_pairs = std::move(pairs);
  const auto count = static_cast<Eigen::Index>(m.face_pairs.size());
  m.pair_closed.assign(m.face_pairs.size(), 0);
  m.pair_multiplier = Eigen::VectorXd::Zero(count);
  m.build_pattern();
  m.analyzed = m.has_factor = false;
  // Penalty: kFacePenalty times the pair's mean radial stiffness in the reference state, so the
  // multiplier update removes all but ~1 / kFacePenalty of an overlap per round.
  Eigen::SparseMatrix<double> K;
  internal_force(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dof_count())), nullptr, &K);
  m.pair_penalty.resize(count);
  for (Eigen::Index p = 0; p < count; ++p) {
    const auto [in, out] = m.face_pairs[static_cast<std::size_t>(p)];
    m.pair_penalty[p] = kFacePenalty * 0.5 * (K.coeff(2 * in, 2 * in) + K.coeff(2 * out, 2 * out));
  }
}

void AxisymmetricModel::set_pair_state(std::vector<char> closed, Eigen::VectorXd multipliers) {
  Impl& m = *impl_;
  if (closed.size() != m.face_pairs.size() ||
      multipliers.size() != static_cast<Eigen::Index>(m.face_pairs.size()))
    throw InputError("axisymmetric model: pair state for " + std::to_string(closed.size()) +
                     " pairs, the model has " + std::to_string(m.face_pairs.size()));
  // Another closed set is another stiffness: the factorisation cannot be reused.
  if (closed != m.pair_closed) m.has_factor = false;
  m.pair_closed = std::move(closed);
  m.pair_multiplier = std::move(multipliers);
}

Eigen::VectorXd AxisymmetricModel::pair_forces(const Eigen::VectorXd& u) const {
  const Impl& m = *impl_;
  Eigen::VectorXd t = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m.face_pairs.size()));
  for (std::size_t p = 0; p < m.face_pairs.size(); ++p)
    if (m.pair_closed[p]) {
      const auto i = static_cast<Eigen::Index>(p);
      t[i] = m.pair_multiplier[i] +
             m.pair_penalty[i] * (u[2 * m.face_pairs[p][1]] - u[2 * m.face_pairs[p][0]]);
    }
  return t;
}

Eigen::VectorXd AxisymmetricModel::pair_penalties() const {
  return impl_->pair_penalty;
}

namespace {

// SparseSolver's backend when the matrix was not positive definite.
const std::string kIndefinite = "eigen-simplicial-ldlt";

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
  // Modified Newton: a factorisation (of this solve or an earlier one with the same constrained
  // dofs) is kept while the residual falls at least fourfold per iteration.
  const bool same_constraints = m.has_factor && m.factored_constraints == is_constrained;
  Eigen::SparseMatrix<double> K;
  double previous_residual = std::numeric_limits<double>::infinity();
  Eigen::VectorXd cached;  // internal force at the accepted line-search point
  double cached_energy = 0.0;
  // The potential energy the descent steps lower: the strain energy plus the closed crack-face
  // pairs' augmented-Lagrangian term (lambda g + k g^2 / 2, g their radial gap).
  auto potential = [&](const Eigen::VectorXd& u, double strain_energy) {
    double total = strain_energy;
    for (std::size_t p = 0; p < m.face_pairs.size(); ++p) {
      if (!m.pair_closed[p]) continue;
      const auto i = static_cast<Eigen::Index>(p);
      const double gap = u[2 * m.face_pairs[p][1]] - u[2 * m.face_pairs[p][0]];
      total += m.pair_multiplier[i] * gap + 0.5 * m.pair_penalty[i] * gap * gap;
    }
    return total;
  };
  for (int iteration = 0;; ++iteration) {
    const bool applied = remaining.lpNorm<Eigen::Infinity>() == 0.0;
    const bool may_reuse = options.modified_newton && applied && m.has_factor &&
                           (same_constraints || m.factored_constraints == is_constrained);
    if (cached.size() == n) {
      eq.reaction = std::move(cached);
      eq.strain_energy_J = cached_energy;
      cached.resize(0);
    } else {
      eq.reaction = internal_force(eq.displacement, &eq.strain_energy_J, may_reuse ? nullptr : &K);
    }
    const double residual = free_norm(eq.reaction, is_constrained);
    const double reference = std::max(constrained_norm(eq.reaction, is_constrained), 1e-30);
    // Round-off floor: once the residual is small and stops falling, more iterations are noise.
    const bool stagnated = iteration >= 2 && residual <= options.stagnation_tolerance * reference &&
                           residual > 0.5 * previous_residual;
    const bool fast = residual < 0.25 * previous_residual;
    if (applied && (residual <= options.residual_tolerance * reference || stagnated ||
                    (m.linear && iteration > 0))) {
      eq.newton_iterations = iteration;
      return eq;
    }
    if (iteration >= (m.bifurcated ? options.max_descent_iterations : options.max_iterations))
      throw SolverError("Newton did not converge in " + std::to_string(iteration) +
                        " iterations (relative residual " + std::to_string(residual / reference) +
                        ")");
    previous_residual = residual;
    // Reuse on the first iteration of a solve, and afterwards while it converges fast.
    const bool reuse = may_reuse && (iteration == 0 || fast);
    Eigen::VectorXd rhs;
    if (reuse) {
      rhs = -eq.reaction;
      for (Eigen::Index i = 0; i < n; ++i)
        if (is_constrained[i]) rhs[i] = 0.0;
    } else {
      if (K.nonZeros() == 0 || may_reuse) internal_force(eq.displacement, nullptr, &K);
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
      m.has_factor = false;
      m.solver.factorize(K);
      ++m.factorizations;
      m.factor_shifted = false;
      if (!m.linear && applied && (!m.solver.ok() || m.solver.backend() == kIndefinite)) {
        // Past a bifurcation (docs/model.md, "Solver"): the free diagonal raised by sigma of
        // itself, from a sixteenth of the last shift that worked (1e-6 at first) up fourfold,
        // until the factorisation is positive definite.
        const Eigen::VectorXd diagonal_k = K.diagonal();
        double sigma = std::max(1e-9, m.shift / 16.0);
        for (int attempt = 0; attempt < 20; ++attempt, sigma *= 4.0) {
          for (Eigen::Index i = 0; i < n; ++i)
            if (!is_constrained[i])
              K.coeffRef(i, i) = diagonal_k[i] + sigma * std::abs(diagonal_k[i]);
          m.solver.factorize(K);
          ++m.factorizations;
          if (m.solver.ok() && m.solver.backend() != kIndefinite) {
            m.factor_shifted = true;
            m.shift = sigma;
            break;
          }
        }
        if (!m.factor_shifted) {  // back to the indefinite tangent itself
          for (Eigen::Index i = 0; i < n; ++i) K.coeffRef(i, i) = diagonal_k[i];
          m.solver.factorize(K);
          ++m.factorizations;
        }
      }
      if (!m.solver.ok()) throw SolverError("singular stiffness matrix");
      m.has_factor = true;
      m.factored_constraints = is_constrained;
      K.resize(0, 0);
    }
    const Eigen::VectorXd step = m.solver.solve(rhs);
    if (!step.allFinite()) throw SolverError("singular stiffness matrix (non-finite solution)");
    // Backtracking line search once the prescribed values are in place: on the free residual,
    // or after a shifted factorisation on the potential energy (a step toward the stable branch
    // raises the residual before it lowers it).
    double alpha = 1.0;
    if (applied && !m.linear) {
      const double start_potential = potential(eq.displacement, eq.strain_energy_J);
      for (int trial = 0; trial < 8; ++trial, alpha *= 0.5) {
        try {
          double energy = 0.0;
          const Eigen::VectorXd trial_u = eq.displacement + alpha * step;
          Eigen::VectorXd r = internal_force(trial_u, &energy, nullptr);
          const bool better = m.factor_shifted ? potential(trial_u, energy) < start_potential
                                               : free_norm(r, is_constrained) < residual;
          if (better) {
            cached = std::move(r);
            cached_energy = energy;
            m.bifurcated = m.bifurcated || m.factor_shifted;
            break;
          }
        } catch (const OutOfMemoryError&) {
          throw;
        } catch (const SolverError&) {
          // An inverted element at the full step: try a shorter one.
        }
      }
      if (cached.size() != n) alpha = std::ldexp(1.0, -8);
    }
    eq.displacement += alpha * step;
    remaining.setZero();
  }
}

}  // namespace mneedle::fe
