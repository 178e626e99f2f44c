#include "mneedle/fe/sparse_solver.h"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/base/memory.h"
#include "mneedle/fe/blas_kernels.h"

#ifdef MNEEDLE_HAVE_CHOLMOD
#include <sys/mman.h>

#include <Eigen/CholmodSupport>
#endif

namespace mneedle::fe {

namespace {
// Off by default: on the 2-core VMs measured (fresh and long-running) ordinary pages were as fast
// or faster (docs/performance.md, "BLAS kernels and huge pages, a fresh VM").
std::atomic<bool> huge_pages_on{false};
}  // namespace

void set_huge_pages(bool on) {
  huge_pages_on.store(on, std::memory_order_relaxed);
}
bool huge_pages() {
  return huge_pages_on.load(std::memory_order_relaxed);
}

namespace {
#ifdef MNEEDLE_HAVE_CHOLMOD
constexpr const char* kCholeskyName = "cholmod-supernodal-llt";

// Large CHOLMOD blocks (above all the factor: 100 MB for the skin half model) 2 MiB-aligned and
// advised away from transparent huge pages by default, which also holds where THP is "always":
// on the VMs we measure on, which hand free memory back to their host, a huge page is memory the
// host must fault in again (docs/performance.md, "BLAS kernels and huge pages, a fresh VM").
// After set_huge_pages(true) the same blocks are advised onto huge pages, where the kernel gives
// them on request (THP "madvise", Debian's default): on one VM the first touch of each 4 KiB page
// was a quarter of a skin run (docs/performance.md, "Where the time goes"). The advice is only
// advice. Blocks come from posix_memalign, so CHOLMOD's free() and realloc() stay valid for them.
constexpr std::size_t kHugePage = std::size_t{2} << 20;
constexpr std::size_t kHugeBlock = 4 * kHugePage;

void* huge_page_malloc(std::size_t bytes) {
  if (bytes < kHugeBlock) return std::malloc(bytes);
  void* block = nullptr;
  if (posix_memalign(&block, kHugePage, bytes) != 0) return nullptr;
  madvise(block, bytes / kHugePage * kHugePage, huge_pages() ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
  return block;
}

void* huge_page_calloc(std::size_t count, std::size_t size) {
  if (size != 0 && count > SIZE_MAX / size) return nullptr;
  if (count * size < kHugeBlock) return std::calloc(count, size);
  void* block = huge_page_malloc(count * size);
  if (block != nullptr) std::memset(block, 0, count * size);
  return block;
}

// CHOLMOD's supernodal Cholesky called directly, not through Eigen's wrapper: the nodal ordering
// goes to cholmod_analyze_p as a given permutation, and CHOLMOD applies it in the transpose it
// makes anyway. The wrapper takes no permutation, so each analysis and factorisation needed a
// permuted copy of K (13 % of a skin run). Only the lower triangle is read (stype -1).
class Cholesky {
 public:
  Cholesky() {
    static std::once_flag hooked;
    std::call_once(hooked, [] {
      SuiteSparse_config.malloc_func = huge_page_malloc;
      SuiteSparse_config.calloc_func = huge_page_calloc;
    });
    cholmod_start(&common_);
    common_.supernodal = CHOLMOD_SUPERNODAL;
    common_.final_asis = 1;
    // A failed Cholesky is expected (the LDLT fallback handles it): keep CHOLMOD quiet on stderr.
    common_.print = 0;
  }
  ~Cholesky() {
    release();
    cholmod_finish(&common_);
  }
  Cholesky(const Cholesky&) = delete;
  Cholesky& operator=(const Cholesky&) = delete;

  cholmod_common& common() { return common_; }

  // `order` (the dof eliminated k-th, for k = 0, 1, ...) or, when empty, CHOLMOD's own choice.
  void analyze(const Eigen::SparseMatrix<double>& matrix, std::vector<int> order) {
    release();
    common_.nmethods = order.empty() ? 0 : 1;  // 0: CHOLMOD's own choice (AMD, then METIS)
    common_.method[0].ordering = CHOLMOD_GIVEN;
    cholmod_sparse a = Eigen::viewAsCholmod(matrix.selfadjointView<Eigen::Lower>());
    factor_ = cholmod_analyze_p(&a, order.empty() ? nullptr : order.data(), nullptr, 0, &common_);
    if (factor_ == nullptr)
      throw SolverError("sparse solver: CHOLMOD analysis failed (status " +
                        std::to_string(common_.status) + ")");
  }

  // False when the matrix is not positive definite (or CHOLMOD ran out of memory).
  bool factorize(const Eigen::SparseMatrix<double>& matrix) {
    cholmod_sparse a = Eigen::viewAsCholmod(matrix.selfadjointView<Eigen::Lower>());
    return cholmod_factorize(&a, factor_, &common_) != 0 && factor_->minor == factor_->n;
  }

  // Bytes the numeric factor will hold once factorised: its values (xsize doubles for a
  // supernodal factor; the predicted nonzeros otherwise). The symbolic part is already held.
  double factor_bytes() const {
    if (factor_ == nullptr) return 0.0;
    const double values = factor_->is_super ? static_cast<double>(factor_->xsize) : common_.lnz;
    return values * sizeof(double);
  }

  // True when the factor's last `count` columns are the last `count` dofs of `order`: CHOLMOD
  // postorders the elimination tree after a given order, which keeps a trailing block that the
  // factor fills (it is a chain at the top of the tree) but is not bound to.
  bool ends_with(const std::vector<int>& order, std::size_t count) const {
    if (factor_ == nullptr || factor_->n != order.size() || count > order.size()) return false;
    const auto* perm = static_cast<const int*>(factor_->Perm);
    for (std::size_t k = order.size() - count; k < order.size(); ++k)
      if (perm[k] != order[k]) return false;
    return true;
  }

  // The factor's last `count` columns and rows as a dense lower-triangular matrix: the Cholesky
  // factor of the Schur complement onto those dofs (docs/performance.md, "The contact block").
  // Read from the supernodes that hold them; empty if the factor is not a supernodal LLᵀ.
  Eigen::MatrixXd trailing_block(std::size_t count) const {
    if (factor_ == nullptr || !factor_->is_super || !factor_->is_ll || count > factor_->n)
      return {};
    const auto n = static_cast<Eigen::Index>(factor_->n);
    const auto t = static_cast<Eigen::Index>(count);
    const Eigen::Index first = n - t;
    const auto* super = static_cast<const int*>(factor_->super);
    const auto* pi = static_cast<const int*>(factor_->pi);
    const auto* px = static_cast<const int*>(factor_->px);
    const auto* rows = static_cast<const int*>(factor_->s);
    const auto* values = static_cast<const double*>(factor_->x);
    Eigen::MatrixXd block = Eigen::MatrixXd::Zero(t, t);
    for (auto s = static_cast<Eigen::Index>(factor_->nsuper) - 1; s >= 0; --s) {
      const Eigen::Index k1 = super[s], k2 = super[s + 1];
      if (k2 <= first) break;
      const Eigen::Index row_count = pi[s + 1] - pi[s];
      for (Eigen::Index k = std::max(k1, first); k < k2; ++k)
        for (Eigen::Index r = k - k1; r < row_count; ++r) {
          // Rows of a trailing column are trailing too (the factor is lower triangular).
          block(rows[pi[s] + r] - first, k - first) = values[px[s] + (k - k1) * row_count + r];
        }
    }
    return block;
  }

  // x = Pᵀ L⁻ᵀ y, in the original numbering: the back substitution and the permutation alone.
  Eigen::MatrixXd back_solve(const Eigen::MatrixXd& y) const {
    cholmod_dense b{};
    b.nrow = static_cast<std::size_t>(y.rows());
    b.ncol = static_cast<std::size_t>(y.cols());
    b.nzmax = b.nrow * b.ncol;
    b.d = b.nrow;
    b.x = const_cast<double*>(y.data());  // read only
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* z = cholmod_solve(CHOLMOD_Lt, factor_, &b, &common_);
    if (z == nullptr) throw SolverError("sparse solver: CHOLMOD solve failed (out of memory?)");
    cholmod_dense* x = cholmod_solve(CHOLMOD_Pt, factor_, z, &common_);
    cholmod_free_dense(&z, &common_);
    if (x == nullptr) throw SolverError("sparse solver: CHOLMOD solve failed (out of memory?)");
    Eigen::MatrixXd result =
        Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), y.rows(), y.cols());
    cholmod_free_dense(&x, &common_);
    return result;
  }

  template <typename Matrix>  // Eigen::VectorXd or Eigen::MatrixXd: column-major, no stride
  Matrix solve(const Matrix& rhs) const {
    cholmod_dense b{};
    b.nrow = static_cast<std::size_t>(rhs.rows());
    b.ncol = static_cast<std::size_t>(rhs.cols());
    b.nzmax = b.nrow * b.ncol;
    b.d = b.nrow;
    b.x = const_cast<double*>(rhs.data());  // read only: CHOLMOD writes its result elsewhere
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor_, &b, &common_);
    if (x == nullptr) throw SolverError("sparse solver: CHOLMOD solve failed (out of memory?)");
    Matrix result =
        Eigen::Map<const Matrix>(static_cast<const double*>(x->x), rhs.rows(), rhs.cols());
    cholmod_free_dense(&x, &common_);
    return result;
  }

 private:
  void release() {
    if (factor_ != nullptr) cholmod_free_factor(&factor_, &common_);
  }
  // cholmod_solve updates its statistics: a solve is logically const.
  mutable cholmod_common common_{};
  cholmod_factor* factor_ = nullptr;
};
#else
using Cholesky = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
constexpr const char* kCholeskyName = "eigen-simplicial-llt";
#endif
using Indefinite = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
enum class Active { None, Cholesky, Indefinite };
}  // namespace

struct SparseSolver::Impl {
  int dofs_per_node = 1;
  // Nodal ordering (dofs_per_node > 1): CHOLMOD factorises P K Pᵀ with this permutation given;
  // the LDLT fallback is handed P K Pᵀ itself.
  bool permuted = false;
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> permutation;
  Cholesky cholesky;
  Indefinite indefinite;
  bool indefinite_analyzed = false;
  bool indefinite_fallback = true;  // set_indefinite_fallback
  Eigen::Index rows = -1;
  Eigen::Index nonzeros = -1;
  int analyses = 0;
  Active active = Active::None;
  // Nodes eliminated last (set_trailing_nodes), whether the analysis kept them there, and the
  // dense factor of the Schur complement onto them after a successful Cholesky.
  std::vector<int> trailing_nodes;
  bool trailing_ordered = false;
  std::size_t trailing_dofs = 0;  // of the last analysis (a later set_trailing_nodes waits)
  Eigen::MatrixXd trailing_factor;
  MemoryReservation factor_reservation;  // from the analysis until the factor is allocated
};

SparseSolver::SparseSolver(int dofs_per_node) : impl_(std::make_unique<Impl>()) {
  if (dofs_per_node < 1) throw SolverError("sparse solver: dofs_per_node must be >= 1");
  impl_->dofs_per_node = dofs_per_node;
}
SparseSolver::~SparseSolver() = default;
SparseSolver::SparseSolver(SparseSolver&&) noexcept = default;
SparseSolver& SparseSolver::operator=(SparseSolver&&) noexcept = default;

namespace {

#ifdef MNEEDLE_HAVE_CHOLMOD
// A fill-reducing ordering of the nodes, not of the dofs (docs/performance.md, "Where the time
// goes"): the nodal graph has 1/b of the vertices and about 1/b² of the edges of the dof graph, so
// METIS orders it in a fraction of the time and finds the same fill, every dof of a node kept
// together. Only the lower triangle of `matrix` is read. Empty when METIS and AMD both fail (the
// caller then lets CHOLMOD order the dofs).
std::vector<int> nodal_ordering(const Eigen::SparseMatrix<double>& matrix, int b,
                                cholmod_common& common) {
  const auto nodes = static_cast<int>(matrix.rows() / b);
  std::vector<int> start(static_cast<std::size_t>(nodes) + 1, 0), rows;
  rows.reserve(static_cast<std::size_t>(matrix.nonZeros() / (b * b) + nodes));
  std::vector<int> seen(static_cast<std::size_t>(nodes), -1);
  for (int j = 0; j < nodes; ++j) {
    start[static_cast<std::size_t>(j)] = static_cast<int>(rows.size());
    for (int c = b * j; c < b * j + b; ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(matrix, c); it; ++it) {
        if (it.row() < c) continue;  // upper triangle: not read
        const auto i = static_cast<int>(it.row() / b);
        if (seen[static_cast<std::size_t>(i)] == j) continue;
        seen[static_cast<std::size_t>(i)] = j;
        rows.push_back(i);
      }
    std::sort(rows.begin() + start[static_cast<std::size_t>(j)], rows.end());
  }
  start.back() = static_cast<int>(rows.size());
  cholmod_sparse graph{};
  graph.nrow = graph.ncol = static_cast<std::size_t>(nodes);
  graph.nzmax = rows.size();
  graph.p = start.data();
  graph.i = rows.data();
  graph.stype = -1;  // lower triangle of a symmetric pattern
  graph.itype = CHOLMOD_INT;
  graph.xtype = CHOLMOD_PATTERN;
  graph.dtype = CHOLMOD_DOUBLE;
  graph.sorted = 1;
  graph.packed = 1;
  std::vector<int> order(static_cast<std::size_t>(nodes), -1);
  if (!cholmod_metis(&graph, nullptr, 0, 0, order.data(), &common) &&
      !cholmod_amd(&graph, nullptr, 0, order.data(), &common))
    return {};
  // CHOLMOD does not pass on every METIS failure: accept only a permutation of the nodes.
  std::vector<char> placed(static_cast<std::size_t>(nodes), 0);
  for (int node : order) {
    if (node < 0 || node >= nodes || placed[static_cast<std::size_t>(node)]) return {};
    placed[static_cast<std::size_t>(node)] = 1;
  }
  return order;
}

// `order` with the `last` nodes moved to its end, in the order `last` gives (the rest keep their
// order). Moving them costs less fill than ordering the graph without them (measured on the skin
// half model with a resolved tip: 62.9 against 64.5 million factor entries; 49.3 with none
// moved). Empty when `last` names a node twice or one outside the order (the analysis then
// forgets the list and orders without it).
std::vector<int> ending_with(std::vector<int> order, const std::vector<int>& last) {
  std::vector<char> moved(order.size(), 0);
  for (int node : last) {
    if (node < 0 || static_cast<std::size_t>(node) >= order.size() ||
        moved[static_cast<std::size_t>(node)])
      return {};
    moved[static_cast<std::size_t>(node)] = 1;
  }
  std::erase_if(order, [&](int node) { return moved[static_cast<std::size_t>(node)] != 0; });
  order.insert(order.end(), last.begin(), last.end());
  return order;
}
#endif

// P K Pᵀ, lower triangle: the matrix in the order the factorisation uses. A copy that lives only
// as long as the analysis or factorisation that needs it.
Eigen::SparseMatrix<double> permuted(
    const Eigen::SparseMatrix<double>& matrix,
    const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>& permutation) {
  Eigen::SparseMatrix<double> scattered(matrix.rows(), matrix.cols());
  scattered.selfadjointView<Eigen::Lower>() =
      matrix.selfadjointView<Eigen::Lower>().twistedBy(permutation);
  // The permutation leaves each column's row indices unsorted; CHOLMOD is told (by Eigen) and
  // Eigen's AMD assumes they are sorted. Transposing twice sorts them.
  const Eigen::SparseMatrix<double> transposed = scattered.transpose();
  return transposed.transpose();
}

// A factor that cannot fit in the memory left is refused before it is allocated, with what it
// needs and what there is (docs/performance.md, "Memory"): otherwise the allocation fails deep
// in CHOLMOD (read as "not positive definite") or the machine swaps for minutes.
// The room stays reserved until the factor is allocated (SparseSolver::factorize), so that
// `screen --jobs N`'s threads do not each count the same memory.
[[maybe_unused]] MemoryReservation reserve_factor(double factor_bytes, Eigen::Index unknowns) {
  return reserve_memory(factor_bytes,
                        "sparse solver: the factor of " + std::to_string(unknowns) + " unknowns",
                        "a coarser fidelity, a smaller contact zone or fewer mesh refinement "
                        "levels needs less");
}

}  // namespace

void SparseSolver::analyze(const Eigen::SparseMatrix<double>& matrix) {
  if (matrix.rows() != matrix.cols()) throw SolverError("sparse solver: matrix is not square");
  impl_->permuted = false;
  impl_->trailing_ordered = false;
  impl_->trailing_dofs = 0;
  bool trailing_lost = false;
  {
    // CHOLMOD's ordering may call METIS, whose random numbers come from one generator per
    // process (GKlib's, reseeded at each call): two threads ordering at once draw from each
    // other's sequence, and the ordering, hence the round-off of every result, would depend on
    // timing. One ordering at a time keeps screen --jobs N bit for bit equal to the serial run.
    static std::mutex ordering;
    std::lock_guard<std::mutex> lock(ordering);
#ifdef MNEEDLE_HAVE_CHOLMOD
    std::vector<int> dof_order;
    const int b = impl_->dofs_per_node;
    if (b > 1 && matrix.rows() % b == 0 && matrix.rows() > 0) {
      std::vector<int> order = nodal_ordering(matrix, b, impl_->cholesky.common());
      if (!order.empty() && !impl_->trailing_nodes.empty()) {
        std::vector<int> ending = ending_with(order, impl_->trailing_nodes);
        if (ending.empty())
          impl_->trailing_nodes.clear();  // a bad list: ordered without it
        else
          order = std::move(ending);
      }
      if (!order.empty()) {
        // order[k] is the node eliminated k-th: its dofs are the k-th block of P K Pᵀ. The
        // permutation maps old dof to new (for the LDLT fallback).
        dof_order.resize(static_cast<std::size_t>(matrix.rows()));
        impl_->permutation.resize(matrix.rows());
        for (std::size_t k = 0; k < order.size(); ++k)
          for (int d = 0; d < b; ++d) {
            dof_order[static_cast<std::size_t>(b) * k + static_cast<std::size_t>(d)] =
                b * order[k] + d;
            impl_->permutation.indices()[b * order[k] + d] = b * static_cast<int>(k) + d;
          }
        impl_->permuted = true;
      }
    }
    const std::size_t trailing_dofs = static_cast<std::size_t>(b) * impl_->trailing_nodes.size();
    const bool trailing = impl_->permuted && trailing_dofs > 0;
    const std::vector<int> given = trailing ? dof_order : std::vector<int>{};
    impl_->cholesky.analyze(matrix, std::move(dof_order));
    impl_->trailing_ordered = trailing && impl_->cholesky.ends_with(given, trailing_dofs);
    impl_->trailing_dofs = impl_->trailing_ordered ? trailing_dofs : 0;
    trailing_lost = trailing && !impl_->trailing_ordered;
#else
    impl_->cholesky.analyzePattern(matrix);
#endif
  }
  impl_->indefinite_analyzed = false;
  impl_->rows = matrix.rows();
  impl_->nonzeros = matrix.nonZeros();
  impl_->active = Active::None;
  ++impl_->analyses;
  if (trailing_lost) {
    // CHOLMOD's postorder moved a trailing node (the factor did not fill the block): the fill
    // paid for it buys nothing, so the matrix is ordered again without them.
    std::vector<int> nodes = std::move(impl_->trailing_nodes);
    impl_->trailing_nodes.clear();
    --impl_->analyses;  // one analysis, as the caller sees it
    analyze(matrix);
    impl_->trailing_nodes = std::move(nodes);
    return;
  }
#ifdef MNEEDLE_HAVE_CHOLMOD
  impl_->factor_reservation.release();  // the previous analysis's, if never factorised
  impl_->factor_reservation = reserve_factor(impl_->cholesky.factor_bytes(), matrix.rows());
#endif
}

void SparseSolver::factorize(const Eigen::SparseMatrix<double>& input) {
  // The BLAS kernels are chosen before the first factorisation (a no-op once chosen; the CLI
  // chooses them first thing, docs/performance.md "BLAS kernels and huge pages, a fresh VM").
  select_blas_kernels();
  if (input.rows() != impl_->rows || input.nonZeros() != impl_->nonzeros) analyze(input);
#ifdef MNEEDLE_HAVE_CHOLMOD
  const bool factorized = impl_->cholesky.factorize(input);
  impl_->factor_reservation.release();  // allocated now (or failed): the kernel counts it
#else
  impl_->cholesky.factorize(input);
  const bool factorized = impl_->cholesky.info() == Eigen::Success;
#endif
  impl_->trailing_factor.resize(0, 0);
  if (factorized) {
    impl_->active = Active::Cholesky;
#ifdef MNEEDLE_HAVE_CHOLMOD
    if (impl_->trailing_ordered)
      impl_->trailing_factor = impl_->cholesky.trailing_block(impl_->trailing_dofs);
#endif
    return;
  }
  if (!impl_->indefinite_fallback) {
    impl_->active = Active::None;
    return;
  }
  // Not positive definite (e.g. a hyperelastic tangent past a limit point): LDLT still
  // factorises symmetric indefinite matrices with a nonsingular leading-minor sequence. It gets
  // P K Pᵀ, the Cholesky's fill-reducing order.
#ifdef MNEEDLE_HAVE_CHOLMOD
  // The fallback's simplicial factor has about the supernodal one's entries, each with its row
  // index (12 bytes), and the permuted copy of K comes on top: refused as the factor is when it
  // cannot fit (CHOLMOD itself fails this way when it ran out of memory).
  MemoryReservation fallback;  // held while Eigen allocates the factor
  if (!impl_->indefinite_analyzed)
    fallback = reserve_memory(
        1.5 * impl_->cholesky.factor_bytes() +
            (impl_->permuted ? 12.0 * static_cast<double>(input.nonZeros()) : 0.0),
        "sparse solver: the LDLT fallback for " + std::to_string(input.rows()) + " unknowns",
        "a coarser fidelity, a smaller contact zone or fewer mesh refinement levels "
        "needs less");
#endif
  Eigen::SparseMatrix<double> reordered;
  if (impl_->permuted) reordered = permuted(input, impl_->permutation);
  const Eigen::SparseMatrix<double>& matrix = impl_->permuted ? reordered : input;
  if (!impl_->indefinite_analyzed) {
    impl_->indefinite.analyzePattern(matrix);
    impl_->indefinite_analyzed = true;
  }
  impl_->indefinite.factorize(matrix);
  const bool ok = impl_->indefinite.info() == Eigen::Success &&
                  (impl_->indefinite.vectorD().array().abs() > 0.0).all();
  impl_->active = ok ? Active::Indefinite : Active::None;
}

namespace {

// Solves with the active factorisation. CHOLMOD applies its own permutation; the LDLT fallback
// factorised P K Pᵀ (P = identity when not permuted).
template <typename Matrix, typename Impl>
Matrix solve_with(const Impl& impl, const Matrix& rhs) {
  switch (impl.active) {
    case Active::Cholesky:
      return impl.cholesky.solve(rhs);
    case Active::Indefinite:
      if (impl.permuted) {
        // One copy of the right-hand side's size at a time beside the caller's (a block of
        // compliance columns is dofs x 3 captured nodes): permuted, solved, permuted back.
        Matrix x;
        {
          const Matrix reordered_rhs = impl.permutation * rhs;
          x = impl.indefinite.solve(reordered_rhs);
        }
        x = impl.permutation.transpose() * x;
        return x;
      }
      return impl.indefinite.solve(rhs);
    case Active::None:
      break;
  }
  throw SolverError("sparse solver: no valid factorisation (singular matrix)");
}

}  // namespace

Eigen::VectorXd SparseSolver::solve(const Eigen::VectorXd& rhs) const {
  return solve_with(*impl_, rhs);
}

Eigen::MatrixXd SparseSolver::solve_many(const Eigen::MatrixXd& rhs) const {
  return solve_with(*impl_, rhs);
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

bool SparseSolver::ordered_by_node() const {
  return impl_->permuted;
}

double SparseSolver::factor_nonzeros() const {
#ifdef MNEEDLE_HAVE_CHOLMOD
  if (impl_->active == Active::Cholesky) return impl_->cholesky.common().lnz;
#endif
  return 0.0;
}

void SparseSolver::set_indefinite_fallback(bool on) {
  impl_->indefinite_fallback = on;
}

void SparseSolver::set_trailing_nodes(std::vector<int> nodes) {
  impl_->trailing_nodes = std::move(nodes);
}

bool SparseSolver::has_trailing_block() const {
  return impl_->active == Active::Cholesky && impl_->trailing_factor.size() > 0;
}

Eigen::MatrixXd SparseSolver::trailing_columns(const std::vector<Eigen::Index>& columns) const {
  if (!has_trailing_block())
    throw SolverError("sparse solver: no trailing block (set_trailing_nodes before analyze)");
  const Eigen::MatrixXd& factor = impl_->trailing_factor;
  Eigen::MatrixXd x =
      Eigen::MatrixXd::Zero(factor.rows(), static_cast<Eigen::Index>(columns.size()));
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (columns[j] < 0 || columns[j] >= factor.rows())
      throw SolverError("sparse solver: trailing column out of range");
    x(columns[j], static_cast<Eigen::Index>(j)) = 1.0;
  }
  // With S = L Lᵀ the Schur complement onto the trailing dofs, K⁻¹ there is S⁻¹ = L⁻ᵀ L⁻¹.
  factor.triangularView<Eigen::Lower>().solveInPlace(x);
  factor.transpose().triangularView<Eigen::Upper>().solveInPlace(x);
  return x;
}

Eigen::MatrixXd SparseSolver::solve_trailing_loads(const Eigen::MatrixXd& loads) const {
  if (!has_trailing_block())
    throw SolverError("sparse solver: no trailing block (set_trailing_nodes before analyze)");
  const Eigen::MatrixXd& factor = impl_->trailing_factor;
  if (loads.rows() != factor.rows())
    throw SolverError("sparse solver: trailing loads of the wrong size");
#ifdef MNEEDLE_HAVE_CHOLMOD
  // L y = P b has y = 0 but on the trailing rows, where it is the dense block's forward solve.
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(impl_->rows, loads.cols());
  y.bottomRows(factor.rows()) = factor.triangularView<Eigen::Lower>().solve(loads);
  return impl_->cholesky.back_solve(y);
#else
  return {};  // no trailing block without CHOLMOD
#endif
}

int SparseSolver::analysis_count() const {
  return impl_->analyses;
}

}  // namespace mneedle::fe
