#pragma once
// Sparse symmetric direct solver shared by the finite element models. CHOLMOD stays inside
// sparse_solver.cpp: including it costs seconds per translation unit.

#include <Eigen/Sparse>
#include <memory>
#include <string>
#include <vector>

namespace mneedle::fe {

/// SPD direct solver with a symmetric-indefinite fallback. CHOLMOD supernodal Cholesky when
/// MNEEDLE_HAVE_CHOLMOD, else Eigen's SimplicialLLT; when the Cholesky factorisation fails
/// (matrix not positive definite) it falls back to Eigen's SimplicialLDLT.
/// analyze() once per sparsity pattern, factorize() per matrix, solve() per right-hand side.
/// Only the lower triangle of the matrix is read.
class SparseSolver {
 public:
  /// `dofs_per_node` > 1 (a solid model's unknowns, node by node: 3 in 3-D) orders the nodes
  /// rather than the dofs: the same fill, found in a fraction of the time. CHOLMOD only, and only
  /// when METIS (or AMD) orders the nodal graph; otherwise CHOLMOD orders the dofs itself.
  explicit SparseSolver(int dofs_per_node = 1);
  ~SparseSolver();
  SparseSolver(SparseSolver&&) noexcept;
  SparseSolver& operator=(SparseSolver&&) noexcept;
  SparseSolver(const SparseSolver&) = delete;
  SparseSolver& operator=(const SparseSolver&) = delete;

  /// Symbolic analysis (fill-reducing ordering); reused by every factorize() of the same pattern.
  void analyze(const Eigen::SparseMatrix<double>& matrix);
  /// Numeric factorisation; calls analyze() itself when the pattern size changed.
  void factorize(const Eigen::SparseMatrix<double>& matrix);
  /// Solves matrix * x = rhs with the last factorisation; throws SolverError if none succeeded.
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const;
  /// Several right-hand sides (columns) at once.
  Eigen::MatrixXd solve_many(const Eigen::MatrixXd& rhs) const;
  /// True when the last factorize() succeeded.
  bool ok() const;
  /// Which factorisation served the last factorize(): "cholmod-supernodal-llt",
  /// "eigen-simplicial-llt" or "eigen-simplicial-ldlt".
  std::string backend() const;
  /// Number of symbolic analyses performed so far (to check that the pattern is reused).
  int analysis_count() const;
  /// True when the last analysis ordered nodes (dofs_per_node > 1, a whole number of nodes and
  /// CHOLMOD's METIS or AMD gave a valid order).
  bool ordered_by_node() const;
  /// Nonzeros of the last CHOLMOD Cholesky factor (its fill); 0 for the other factorisations.
  double factor_nonzeros() const;
  /// Whether a failed Cholesky falls back to LDLᵀ (on, the default). Off, a matrix that is not
  /// positive definite leaves ok() false at once: a caller that shifts the matrix and tries again
  /// (docs/model.md, "Solver") does not pay for a simplicial factorisation it would discard.
  void set_indefinite_fallback(bool on);

  /// Nodes whose dofs the factorisation eliminates last, in this order (docs/performance.md,
  /// "The contact block"): the factor's trailing block is then the dense Cholesky factor of K's
  /// Schur complement onto those dofs, and K⁻¹ on them (trailing_columns) costs two dense
  /// triangular solves of that size instead of a sparse solve. Takes effect at the next
  /// analyze(); an empty list clears it, and so does a list that names a node twice or one out
  /// of range. Only a nodal ordering (ordered_by_node) honours it.
  void set_trailing_nodes(std::vector<int> nodes);
  /// True when the last factorize() gave the Cholesky factor with the trailing nodes last.
  bool has_trailing_block() const;
  /// Columns of K⁻¹ restricted to the trailing dofs (rows and columns numbered b·i + d for the
  /// i-th trailing node's d-th dof, b = dofs_per_node). Throws SolverError without a trailing
  /// block.
  Eigen::MatrixXd trailing_columns(const std::vector<Eigen::Index>& columns) const;
  /// K⁻¹ B for loads on the trailing dofs alone (each column of `loads` in their numbering), in
  /// the original numbering: the forward substitution is the dense block's, so it costs about
  /// half a solve_many(). Throws SolverError without a trailing block.
  Eigen::MatrixXd solve_trailing_loads(const Eigen::MatrixXd& loads) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Whether CHOLMOD's large blocks (the factor above all) are advised onto transparent huge pages
/// (on) or away from them (off, the default). On a VM whose free memory is handed back to the
/// host (free page reporting), a huge page is memory the host must fault in again: such VMs ran
/// 1.1-2x slower (wall time) with them, fresh or long-running (docs/performance.md, "Huge pages,
/// measured again" and "BLAS kernels and huge pages, a fresh VM"). Results do not depend on it.
/// Process-wide; set it before the first factorisation.
void set_huge_pages(bool on);
bool huge_pages();

}  // namespace mneedle::fe
