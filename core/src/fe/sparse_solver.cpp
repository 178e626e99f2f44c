#include "mneedle/fe/sparse_solver.h"

#include <Eigen/SparseCholesky>
#include <mutex>

#include "mneedle/base/error.h"

#ifdef MNEEDLE_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace mneedle::fe {

namespace {
#ifdef MNEEDLE_HAVE_CHOLMOD
using Cholesky = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
constexpr const char* kCholeskyName = "cholmod-supernodal-llt";
#else
using Cholesky = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
constexpr const char* kCholeskyName = "eigen-simplicial-llt";
#endif
using Indefinite = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
enum class Active { None, Cholesky, Indefinite };
}  // namespace

struct SparseSolver::Impl {
  Cholesky cholesky;
  Indefinite indefinite;
  bool indefinite_analyzed = false;
  Eigen::Index rows = -1;
  Eigen::Index nonzeros = -1;
  int analyses = 0;
  Active active = Active::None;
};

SparseSolver::SparseSolver() : impl_(std::make_unique<Impl>()) {
#ifdef MNEEDLE_HAVE_CHOLMOD
  // A failed Cholesky is expected (the LDLT fallback handles it): keep CHOLMOD quiet on stderr.
  impl_->cholesky.cholmod().print = 0;
#endif
}
SparseSolver::~SparseSolver() = default;
SparseSolver::SparseSolver(SparseSolver&&) noexcept = default;
SparseSolver& SparseSolver::operator=(SparseSolver&&) noexcept = default;

void SparseSolver::analyze(const Eigen::SparseMatrix<double>& matrix) {
  if (matrix.rows() != matrix.cols()) throw SolverError("sparse solver: matrix is not square");
  {
    // CHOLMOD's ordering may call METIS, whose random numbers come from one generator per
    // process (GKlib's, reseeded at each call): two threads ordering at once draw from each
    // other's sequence, and the ordering, hence the round-off of every result, would depend on
    // timing. One ordering at a time keeps screen --jobs N bit for bit equal to the serial run.
    static std::mutex ordering;
    std::lock_guard<std::mutex> lock(ordering);
    impl_->cholesky.analyzePattern(matrix);
  }
  impl_->indefinite_analyzed = false;
  impl_->rows = matrix.rows();
  impl_->nonzeros = matrix.nonZeros();
  impl_->active = Active::None;
  ++impl_->analyses;
}

void SparseSolver::factorize(const Eigen::SparseMatrix<double>& matrix) {
  if (matrix.rows() != impl_->rows || matrix.nonZeros() != impl_->nonzeros) analyze(matrix);
  impl_->cholesky.factorize(matrix);
  if (impl_->cholesky.info() == Eigen::Success) {
    impl_->active = Active::Cholesky;
    return;
  }
  // Not positive definite (e.g. a hyperelastic tangent past a limit point): LDLT still
  // factorises symmetric indefinite matrices with a nonsingular leading-minor sequence.
  if (!impl_->indefinite_analyzed) {
    impl_->indefinite.analyzePattern(matrix);
    impl_->indefinite_analyzed = true;
  }
  impl_->indefinite.factorize(matrix);
  const bool ok = impl_->indefinite.info() == Eigen::Success &&
                  (impl_->indefinite.vectorD().array().abs() > 0.0).all();
  impl_->active = ok ? Active::Indefinite : Active::None;
}

Eigen::VectorXd SparseSolver::solve(const Eigen::VectorXd& rhs) const {
  switch (impl_->active) {
    case Active::Cholesky:
      return impl_->cholesky.solve(rhs);
    case Active::Indefinite:
      return impl_->indefinite.solve(rhs);
    case Active::None:
      break;
  }
  throw SolverError("sparse solver: no valid factorisation (singular matrix)");
}

Eigen::MatrixXd SparseSolver::solve_many(const Eigen::MatrixXd& rhs) const {
  switch (impl_->active) {
    case Active::Cholesky:
      return impl_->cholesky.solve(rhs);
    case Active::Indefinite:
      return impl_->indefinite.solve(rhs);
    case Active::None:
      break;
  }
  throw SolverError("sparse solver: no valid factorisation (singular matrix)");
}

bool SparseSolver::ok() const {
  return impl_->active != Active::None;
}

std::string SparseSolver::backend() const {
  switch (impl_->active) {
    case Active::Cholesky:
      return kCholeskyName;
    case Active::Indefinite:
      return "eigen-simplicial-ldlt";
    case Active::None:
      break;
  }
  return "none";
}

int SparseSolver::analysis_count() const {
  return impl_->analyses;
}

}  // namespace mneedle::fe
