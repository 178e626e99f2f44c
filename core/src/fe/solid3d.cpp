#include "mneedle/fe/solid3d.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle::fe {

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

constexpr int kEdgeNodes[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};

struct QuadraturePoint {
  std::array<double, 4> barycentric;
  double weight;  // on the reference tetrahedron of volume 1/6
};

// One point is exact for the constant strain of a 4-node tet; four points (degree 2) integrate
// Bᵀ D B of a 10-node tet exactly.
const std::vector<QuadraturePoint>& quadrature(int node_count) {
  static const std::vector<QuadraturePoint> one{{{0.25, 0.25, 0.25, 0.25}, 1.0 / 6.0}};
  static const std::vector<QuadraturePoint> four = [] {
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    std::vector<QuadraturePoint> points;
    for (int i = 0; i < 4; ++i) {
      std::array<double, 4> l{b, b, b, b};
      l[static_cast<std::size_t>(i)] = a;
      points.push_back({l, 1.0 / 24.0});
    }
    return points;
  }();
  return node_count == 4 ? one : four;
}

// Derivatives of the shape functions with respect to the natural coordinates (L1, L2, L3),
// with L0 = 1 - L1 - L2 - L3; one row per node.
Eigen::MatrixXd natural_gradients(int node_count, const std::array<double, 4>& l) {
  Eigen::MatrixXd by_barycentric = Eigen::MatrixXd::Zero(node_count, 4);  // dN/dL_i
  if (node_count == 4) {
    by_barycentric = Eigen::MatrixXd::Identity(4, 4);
  } else {
    for (int i = 0; i < 4; ++i) by_barycentric(i, i) = 4.0 * l[static_cast<std::size_t>(i)] - 1.0;
    for (int e = 0; e < 6; ++e) {
      const int a = kEdgeNodes[e][0], b = kEdgeNodes[e][1];
      by_barycentric(4 + e, a) = 4.0 * l[static_cast<std::size_t>(b)];
      by_barycentric(4 + e, b) = 4.0 * l[static_cast<std::size_t>(a)];
    }
  }
  Eigen::Matrix<double, 4, 3> chain;
  chain << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return by_barycentric * chain;
}

struct PointKinematics {
  Eigen::MatrixXd gradients;   // dN/dX, one row per node
  double weight_volume = 0.0;  // quadrature weight x det J
  Eigen::Matrix3d F;
};

PointKinematics kinematics(const std::vector<Eigen::Vector3d>& nodes, const Eigen::VectorXd& u,
                           const QuadraturePoint& point) {
  const int n = static_cast<int>(nodes.size());
  const Eigen::MatrixXd natural = natural_gradients(n, point.barycentric);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();  // dX/dxi
  for (int a = 0; a < n; ++a) jacobian += nodes[static_cast<std::size_t>(a)] * natural.row(a);
  const double det = jacobian.determinant();
  if (!(det > 0.0)) throw SolverError("3-D solid: element with non-positive reference volume");
  PointKinematics k;
  k.gradients = natural * jacobian.inverse();
  k.weight_volume = point.weight * det;
  k.F = Eigen::Matrix3d::Identity();
  for (int a = 0; a < n; ++a) k.F += u.segment<3>(3 * a) * k.gradients.row(a);
  return k;
}

Vector6 voigt(const Eigen::Matrix3d& s) {
  Vector6 v;
  v << s(0, 0), s(1, 1), s(2, 2), s(1, 2), s(0, 2), s(0, 1);
  return v;
}

MaterialResponse evaluate_checked(const Material& material, const Eigen::Matrix3d& F,
                                  bool linear_kinematics) {
  if (!linear_kinematics && !(F.determinant() > 0.0))
    throw SolverError("3-D solid: inverted element (det F <= 0)");
  return material.evaluate(F);
}

double von_mises_of(const Eigen::Matrix3d& sigma) {
  const Eigen::Matrix3d deviator = sigma - sigma.trace() / 3.0 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * deviator.cwiseProduct(deviator).sum());
}

// Fixed-size element kernel: no heap allocation per element, the assembly's inner loop.
template <int N>
struct FixedTet {
  using Nodes = std::array<Eigen::Vector3d, N>;
  using Displacement = Eigen::Matrix<double, 3 * N, 1>;
  using Stiffness = Eigen::Matrix<double, 3 * N, 3 * N>;
  using Gradients = Eigen::Matrix<double, N, 3>;
  using StrainMatrix = Eigen::Matrix<double, 6, 3 * N>;
};

template <int N>
const std::vector<typename FixedTet<N>::Gradients>& natural_gradients_at_points() {
  static const std::vector<typename FixedTet<N>::Gradients> table = [] {
    std::vector<typename FixedTet<N>::Gradients> t;
    for (const QuadraturePoint& point : quadrature(N))
      t.push_back(natural_gradients(N, point.barycentric));
    return t;
  }();
  return table;
}

template <int N>
void fixed_tet_response(const typename FixedTet<N>::Nodes& nodes,
                        const typename FixedTet<N>::Displacement& u, const Material& material,
                        bool linear_kinematics, typename FixedTet<N>::Stiffness* stiffness,
                        typename FixedTet<N>::Displacement* force, double* energy) {
  using Gradients = typename FixedTet<N>::Gradients;
  if (stiffness) stiffness->setZero();
  force->setZero();
  *energy = 0.0;
  const auto& points = quadrature(N);
  const auto& natural_table = natural_gradients_at_points<N>();
  for (std::size_t q = 0; q < points.size(); ++q) {
    const Gradients& natural = natural_table[q];
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
    for (int a = 0; a < N; ++a) jacobian += nodes[static_cast<std::size_t>(a)] * natural.row(a);
    const double det = jacobian.determinant();
    if (!(det > 0.0)) throw SolverError("3-D solid: element with non-positive reference volume");
    const Gradients g = natural * jacobian.inverse();
    const double wv = points[q].weight * det;
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    for (int a = 0; a < N; ++a) F += u.template segment<3>(3 * a) * g.row(a);
    const MaterialResponse m = evaluate_checked(material, F, linear_kinematics);
    const Eigen::Matrix3d Fb = linear_kinematics ? Eigen::Matrix3d::Identity() : F;
    // Rows of δE (Voigt, engineering shear) per nodal displacement; F = I: small-strain B.
    typename FixedTet<N>::StrainMatrix b;
    for (int a = 0; a < N; ++a)
      for (int i = 0; i < 3; ++i) {
        const int c = 3 * a + i;
        b(0, c) = Fb(i, 0) * g(a, 0);
        b(1, c) = Fb(i, 1) * g(a, 1);
        b(2, c) = Fb(i, 2) * g(a, 2);
        b(3, c) = Fb(i, 1) * g(a, 2) + Fb(i, 2) * g(a, 1);
        b(4, c) = Fb(i, 0) * g(a, 2) + Fb(i, 2) * g(a, 0);
        b(5, c) = Fb(i, 0) * g(a, 1) + Fb(i, 1) * g(a, 0);
      }
    force->noalias() += wv * (b.transpose() * voigt(m.S));
    *energy += wv * m.energy_density;
    if (!stiffness) continue;
    const Eigen::Matrix<double, 6, 3 * N> cb = m.C * b;
    stiffness->noalias() += wv * (b.transpose() * cb);
    if (linear_kinematics) continue;
    // Initial-stress (geometric) stiffness: (∇N_a · S ∇N_b) I.
    const Eigen::Matrix<double, N, N> geometric = g * m.S * g.transpose();
    for (int a = 0; a < N; ++a)
      for (int c = 0; c < N; ++c)
        for (int i = 0; i < 3; ++i) (*stiffness)(3 * a + i, 3 * c + i) += wv * geometric(a, c);
  }
}

}  // namespace

namespace {
template <int N>
TetResponse dispatch_tet_response(const std::vector<Eigen::Vector3d>& nodes,
                                  const Eigen::VectorXd& u, const Material& material,
                                  bool linear_kinematics) {
  typename FixedTet<N>::Nodes fixed_nodes;
  std::copy(nodes.begin(), nodes.end(), fixed_nodes.begin());
  typename FixedTet<N>::Stiffness k;
  typename FixedTet<N>::Displacement f;
  TetResponse r;
  fixed_tet_response<N>(fixed_nodes, u, material, linear_kinematics, &k, &f, &r.energy);
  r.stiffness = k;
  r.force = f;
  return r;
}
}  // namespace

TetResponse tet_response(const std::vector<Eigen::Vector3d>& nodes, const Eigen::VectorXd& u,
                         const Material& material, bool linear_kinematics) {
  if (nodes.size() == 4) return dispatch_tet_response<4>(nodes, u, material, linear_kinematics);
  if (nodes.size() == 10) return dispatch_tet_response<10>(nodes, u, material, linear_kinematics);
  throw SolverError("3-D solid: a tetrahedron has 4 or 10 nodes");
}

Eigen::Matrix3d tet_cauchy_stress(const std::vector<Eigen::Vector3d>& nodes,
                                  const Eigen::VectorXd& u, const Material& material,
                                  bool linear_kinematics) {
  const QuadraturePoint centroid{{0.25, 0.25, 0.25, 0.25}, 1.0 / 6.0};
  const PointKinematics k = kinematics(nodes, u, centroid);
  const MaterialResponse m = evaluate_checked(material, k.F, linear_kinematics);
  if (linear_kinematics) return m.S;
  return k.F * m.S * k.F.transpose() / k.F.determinant();
}

double tet_von_mises(const std::vector<Eigen::Vector3d>& nodes, const Eigen::VectorXd& u,
                     const Material& material, bool linear_kinematics) {
  return von_mises_of(tet_cauchy_stress(nodes, u, material, linear_kinematics));
}

SolidModel::SolidModel(const TetMesh& mesh) : mesh_(&mesh) {
  for (const TissueLayer& layer : mesh.layers)
    linear_ = linear_ && layer.material.model == MaterialModel::Linear;
  for (const TissueLayer& layer : mesh.layers) {
    MaterialParameters parameters = layer.material;
    if (!linear_ && parameters.model == MaterialModel::Linear)
      parameters.model = MaterialModel::StVenantKirchhoff;
    layer_materials_.emplace_back(parameters);
  }
  // Node adjacency restricted to the lower triangle (neighbour >= node), sorted.
  const int node_count = static_cast<int>(mesh.nodes.size());
  const int per_element = mesh.nodes_per_element();
  std::vector<std::vector<int>> lower(static_cast<std::size_t>(node_count));
  for (const auto& element : mesh.elements)
    for (int a = 0; a < per_element; ++a)
      for (int b = 0; b < per_element; ++b) {
        const int na = element[static_cast<std::size_t>(a)],
                  nb = element[static_cast<std::size_t>(b)];
        if (na >= nb) lower[static_cast<std::size_t>(nb)].push_back(na);
      }
  set_adjacency(lower);
}

void SolidModel::set_adjacency(std::vector<std::vector<int>>& lower) {
  adjacency_start_.assign(lower.size() + 1, 0);
  adjacency_.clear();
  for (std::size_t node = 0; node < lower.size(); ++node) {
    auto& list = lower[node];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    adjacency_start_[node + 1] = adjacency_start_[node] + static_cast<int>(list.size());
    adjacency_.insert(adjacency_.end(), list.begin(), list.end());
  }
}

void SolidModel::couple_nodes(const std::vector<std::array<int, 2>>& pairs) {
  const int node_count = static_cast<int>(mesh_->nodes.size());
  std::vector<std::vector<int>> lower(static_cast<std::size_t>(node_count));
  for (int node = 0; node < node_count; ++node)
    lower[static_cast<std::size_t>(node)].assign(
        adjacency_.begin() + adjacency_start_[static_cast<std::size_t>(node)],
        adjacency_.begin() + adjacency_start_[static_cast<std::size_t>(node) + 1]);
  for (const auto& [a, b] : pairs) {
    if (a < 0 || b < 0 || a >= node_count || b >= node_count)
      throw InputError("3-D solid: coupled node out of range");
    lower[static_cast<std::size_t>(std::min(a, b))].push_back(std::max(a, b));
  }
  set_adjacency(lower);
}

Eigen::SparseMatrix<double> SolidModel::empty_stiffness() const {
  // Written in compressed form directly (column 3 node + j holds rows 3 m + i for each sorted
  // lower neighbour m of the node: the pattern scatter() relies on); inserting entry by entry
  // took a sixth of the set-up of a skin run.
  const int n = dof_count();
  Eigen::SparseMatrix<double> k(n, n);
  k.resizeNonZeros(static_cast<Eigen::Index>(9 * adjacency_.size()));
  int* outer = k.outerIndexPtr();
  int* inner = k.innerIndexPtr();
  int entry = 0;
  for (int node = 0; node * 3 < n; ++node)
    for (int j = 0; j < 3; ++j) {
      outer[3 * node + j] = entry;
      for (int p = adjacency_start_[static_cast<std::size_t>(node)];
           p < adjacency_start_[static_cast<std::size_t>(node) + 1]; ++p)
        for (int i = 0; i < 3; ++i)
          inner[entry++] = 3 * adjacency_[static_cast<std::size_t>(p)] + i;
    }
  outer[n] = entry;
  std::fill(k.valuePtr(), k.valuePtr() + entry, 0.0);
  return k;
}

std::vector<Eigen::Vector3d> SolidModel::element_nodes(int element) const {
  const auto& ids = mesh_->elements[static_cast<std::size_t>(element)];
  std::vector<Eigen::Vector3d> nodes;
  for (int a = 0; a < mesh_->nodes_per_element(); ++a)
    nodes.push_back(mesh_->nodes[static_cast<std::size_t>(ids[static_cast<std::size_t>(a)])]);
  return nodes;
}

Eigen::VectorXd SolidModel::element_displacement(int element, const Eigen::VectorXd& u) const {
  const auto& ids = mesh_->elements[static_cast<std::size_t>(element)];
  const int n = mesh_->nodes_per_element();
  Eigen::VectorXd ue(3 * n);
  for (int a = 0; a < n; ++a)
    ue.segment<3>(3 * a) = u.segment<3>(3 * ids[static_cast<std::size_t>(a)]);
  return ue;
}

template <typename ElementMatrix>
void SolidModel::scatter(int element, const ElementMatrix& ke,
                         Eigen::SparseMatrix<double>* k) const {
  const auto& ids = mesh_->elements[static_cast<std::size_t>(element)];
  const int n = mesh_->nodes_per_element();
  double* values = k->valuePtr();
  const auto* outer = k->outerIndexPtr();
  for (int b = 0; b < n; ++b) {
    const int nb = ids[static_cast<std::size_t>(b)];
    const auto first = adjacency_.begin() + adjacency_start_[static_cast<std::size_t>(nb)];
    const auto last = adjacency_.begin() + adjacency_start_[static_cast<std::size_t>(nb) + 1];
    for (int a = 0; a < n; ++a) {
      const int na = ids[static_cast<std::size_t>(a)];
      if (na < nb) continue;
      const int rank = static_cast<int>(std::lower_bound(first, last, na) - first);
      for (int j = 0; j < 3; ++j) {
        double* column = values + outer[3 * nb + j] + 3 * rank;
        for (int i = 0; i < 3; ++i) column[i] += ke(3 * a + i, 3 * b + j);
      }
    }
  }
}

double SolidModel::assemble(const Eigen::VectorXd& u, Eigen::SparseMatrix<double>* stiffness,
                            Eigen::VectorXd* internal_force) const {
  return mesh_->order == 1 ? assemble_fixed<4>(u, stiffness, internal_force)
                           : assemble_fixed<10>(u, stiffness, internal_force);
}

template <int N>
double SolidModel::assemble_fixed(const Eigen::VectorXd& u, Eigen::SparseMatrix<double>* stiffness,
                                  Eigen::VectorXd* internal_force) const {
  if (stiffness)
    std::fill(stiffness->valuePtr(), stiffness->valuePtr() + stiffness->nonZeros(), 0.0);
  if (internal_force) internal_force->setZero(dof_count());
  double energy = 0.0;
  typename FixedTet<N>::Nodes nodes;
  typename FixedTet<N>::Displacement ue, fe;
  typename FixedTet<N>::Stiffness ke;
  for (int e = 0; e < static_cast<int>(mesh_->elements.size()); ++e) {
    const auto& ids = mesh_->elements[static_cast<std::size_t>(e)];
    for (int a = 0; a < N; ++a) {
      const int node = ids[static_cast<std::size_t>(a)];
      nodes[static_cast<std::size_t>(a)] = mesh_->nodes[static_cast<std::size_t>(node)];
      ue.template segment<3>(3 * a) = u.segment<3>(3 * node);
    }
    const Material& material = layer_materials_[static_cast<std::size_t>(
        mesh_->element_layer[static_cast<std::size_t>(e)])];
    double element_energy = 0.0;
    fixed_tet_response<N>(nodes, ue, material, linear_, stiffness ? &ke : nullptr, &fe,
                          &element_energy);
    energy += element_energy;
    if (stiffness) scatter(e, ke, stiffness);
    if (!internal_force) continue;
    for (int a = 0; a < N; ++a)
      internal_force->segment<3>(3 * ids[static_cast<std::size_t>(a)]) +=
          fe.template segment<3>(3 * a);
  }
  return energy;
}

void SolidModel::add_block(int row, int column, const Eigen::Matrix3d& block,
                           Eigen::SparseMatrix<double>* stiffness) const {
  const auto first = adjacency_.begin() + adjacency_start_[static_cast<std::size_t>(column)];
  const auto last = adjacency_.begin() + adjacency_start_[static_cast<std::size_t>(column) + 1];
  const auto found = std::lower_bound(first, last, row);
  if (row < column || found == last || *found != row)
    throw SolverError("3-D solid: contact block outside the stiffness pattern");
  const int rank = static_cast<int>(found - first);
  double* values = stiffness->valuePtr();
  const auto* outer = stiffness->outerIndexPtr();
  for (int j = 0; j < 3; ++j) {
    double* entries = values + outer[3 * column + j] + 3 * rank;
    for (int i = 0; i < 3; ++i) entries[i] += block(i, j);
  }
}

double SolidModel::strain_energy(const Eigen::VectorXd& u) const {
  return assemble(u, nullptr, nullptr);
}

std::vector<double> SolidModel::von_mises(const Eigen::VectorXd& u) const {
  std::vector<double> result;
  for (int e = 0; e < static_cast<int>(mesh_->elements.size()); ++e)
    result.push_back(tet_von_mises(element_nodes(e), element_displacement(e, u),
                                   layer_materials_[static_cast<std::size_t>(
                                       mesh_->element_layer[static_cast<std::size_t>(e)])],
                                   linear_));
  return result;
}

std::vector<Eigen::Matrix3d> SolidModel::cauchy_stress(const Eigen::VectorXd& u) const {
  std::vector<Eigen::Matrix3d> result;
  result.reserve(mesh_->elements.size());
  for (int e = 0; e < static_cast<int>(mesh_->elements.size()); ++e)
    result.push_back(tet_cauchy_stress(element_nodes(e), element_displacement(e, u),
                                       layer_materials_[static_cast<std::size_t>(
                                           mesh_->element_layer[static_cast<std::size_t>(e)])],
                                       linear_));
  return result;
}

std::vector<double> SolidModel::energy_density(const Eigen::VectorXd& u) const {
  std::vector<double> result;
  for (int e = 0; e < static_cast<int>(mesh_->elements.size()); ++e) {
    const auto nodes = element_nodes(e);
    const Material& material = layer_materials_[static_cast<std::size_t>(
        mesh_->element_layer[static_cast<std::size_t>(e)])];
    const TetResponse r = tet_response(nodes, element_displacement(e, u), material, linear_);
    const double volume =
        (nodes[1] - nodes[0]).dot((nodes[2] - nodes[0]).cross(nodes[3] - nodes[0])) / 6.0;
    result.push_back(r.energy / volume);
  }
  return result;
}

void apply_dirichlet(Eigen::SparseMatrix<double>* lower, const std::vector<char>& constrained) {
  for (int column = 0; column < lower->outerSize(); ++column)
    for (Eigen::SparseMatrix<double>::InnerIterator it(*lower, column); it; ++it) {
      const bool hit = constrained[static_cast<std::size_t>(it.row())] ||
                       constrained[static_cast<std::size_t>(column)];
      if (hit) it.valueRef() = it.row() == column ? 1.0 : 0.0;
    }
}

}  // namespace mneedle::fe
