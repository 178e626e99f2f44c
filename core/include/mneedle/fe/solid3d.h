#pragma once
// 3-D solid elements (4- and 10-node tetrahedra), total Lagrangian, and the assembled model of a
// tissue mesh: internal force, consistent tangent and strain energy for a displacement field.

#include <Eigen/Core>
#include <Eigen/Sparse>
#include <array>
#include <vector>

#include "mneedle/fe/material.h"
#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::fe {

/// Element of `nodes` (4 or 10 reference positions, VTK order) with displacement `u` (3 per node,
/// node-major). linear_kinematics: small-strain B matrix and the material's small-strain law
/// (K = ∫ Bᵀ D B dV, paper A eq. 5); otherwise total Lagrangian with Green–Lagrange strain.
struct TetResponse {
  Eigen::MatrixXd stiffness;  ///< consistent tangent dF_int/du (N/m)
  Eigen::VectorXd force;      ///< internal nodal forces (N)
  double energy = 0.0;        ///< strain energy (J)
};
TetResponse tet_response(const std::vector<Eigen::Vector3d>& nodes, const Eigen::VectorXd& u,
                         const Material& material, bool linear_kinematics);

/// Von Mises stress (Pa) at the element centroid: Cauchy stress from S and F.
/// Cauchy stress (Pa) of the element at its centroid.
Eigen::Matrix3d tet_cauchy_stress(const std::vector<Eigen::Vector3d>& nodes,
                                  const Eigen::VectorXd& u, const Material& material,
                                  bool linear_kinematics);
double tet_von_mises(const std::vector<Eigen::Vector3d>& nodes, const Eigen::VectorXd& u,
                     const Material& material, bool linear_kinematics);

/// Assembled solid model of a tissue mesh. Three displacement unknowns per node (node-major).
/// If every layer is linear the model uses small-strain kinematics throughout; otherwise linear
/// layers become St Venant–Kirchhoff with the same E and nu (the geometrically exact extension).
/// Only the lower triangle of the stiffness is filled (full 3x3 blocks on the diagonal).
class SolidModel {
 public:
  explicit SolidModel(const TetMesh& mesh);

  int dof_count() const { return 3 * static_cast<int>(mesh_->nodes.size()); }
  bool is_linear() const { return linear_; }
  const TetMesh& mesh() const { return *mesh_; }

  /// Lower-triangle sparse matrix with the model's fixed pattern and zero values.
  Eigen::SparseMatrix<double> empty_stiffness() const;
  /// Adds the blocks coupling each pair of nodes to the pattern (two nodes that share no
  /// element: a crack's opposite faces held in contact), so that add_block() may write them.
  /// Matrices from empty_stiffness() before the call do not have them.
  void couple_nodes(const std::vector<std::array<int, 2>>& pairs);
  /// Fills `stiffness` (from empty_stiffness()) and the internal force; returns strain energy.
  /// Throws SolverError for an inverted element.
  double assemble(const Eigen::VectorXd& u, Eigen::SparseMatrix<double>* stiffness,
                  Eigen::VectorXd* internal_force) const;
  double strain_energy(const Eigen::VectorXd& u) const;
  /// Adds `block` at rows of node `row`, columns of node `column` (row >= column, both in one
  /// element, or coupled by couple_nodes) of a matrix from empty_stiffness(): for contact terms
  /// on top of the tangent.
  void add_block(int row, int column, const Eigen::Matrix3d& block,
                 Eigen::SparseMatrix<double>* stiffness) const;
  std::vector<double> von_mises(const Eigen::VectorXd& u) const;
  /// Cauchy stress (Pa) per element at its centroid: the von Mises value above is of this tensor.
  std::vector<Eigen::Matrix3d> cauchy_stress(const Eigen::VectorXd& u) const;
  /// Strain energy density (J/m^3) per element (mean over its quadrature points).
  std::vector<double> energy_density(const Eigen::VectorXd& u) const;

 private:
  // Sorts and deduplicates each node's lower neighbours and stores them (adjacency_).
  void set_adjacency(std::vector<std::vector<int>>& lower);
  std::vector<Eigen::Vector3d> element_nodes(int element) const;
  Eigen::VectorXd element_displacement(int element, const Eigen::VectorXd& u) const;
  template <typename ElementMatrix>
  void scatter(int element, const ElementMatrix& ke, Eigen::SparseMatrix<double>* k) const;
  template <int N>
  double assemble_fixed(const Eigen::VectorXd& u, Eigen::SparseMatrix<double>* stiffness,
                        Eigen::VectorXd* internal_force) const;

  const TetMesh* mesh_;
  std::vector<Material> layer_materials_;
  bool linear_ = true;
  // Lower-triangle node adjacency (sorted, includes the node itself): column offsets of blocks.
  std::vector<int> adjacency_start_;
  std::vector<int> adjacency_;
};

/// Sets the rows and columns of `constrained` dofs to the identity (keeping the pattern) so the
/// same symbolic factorisation serves every set of prescribed displacements.
void apply_dirichlet(Eigen::SparseMatrix<double>* lower, const std::vector<char>& constrained);

}  // namespace mneedle::fe
