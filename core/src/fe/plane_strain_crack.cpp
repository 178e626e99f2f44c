// Plane-strain slit opened by a rigid circular needle (paper C §4): graded tensor-product grid of
// bilinear quadrilaterals, linear elasticity, frictionless unilateral contact by an active set.
#include "mneedle/fe/plane_strain_crack.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/fe/sparse_solver.h"
#include "plane_strain_element.h"

namespace mneedle::fe {
namespace {

// The active set settles in a handful of solves (the radial normals converge quadratically);
// more than this means it is cycling.
constexpr int kMaxActiveSetIterations = 60;
// A node counts as penetrating / a contact force as tensile only beyond these fractions (of r,
// of the largest contact force): round-off must not toggle a node at the contact edge.
constexpr double kPenetrationTolerance = 1e-10;
constexpr double kTensionTolerance = 1e-10;
// Radial normals are converged when no unit normal moves by more than this.
constexpr double kNormalTolerance = 1e-10;

[[noreturn]] void bad(const std::string& field, const std::string& what) {
  throw InputError("plane-strain crack: " + field + " " + what);
}

double element_size(const CrackOpeningProblem& p) {
  return p.element_size_m > 0.0 ? p.element_size_m : p.crack_width_m * kCrackDefaultElementFraction;
}

void check(const CrackOpeningProblem& p) {
  auto finite = [](double v) { return std::isfinite(v); };
  if (!finite(p.youngs_modulus_Pa) || p.youngs_modulus_Pa <= 0.0)
    bad("youngs_modulus_Pa", "must be positive and finite, got " + str(p.youngs_modulus_Pa));
  if (!finite(p.poisson_ratio) || p.poisson_ratio < 0.0 || p.poisson_ratio >= 0.5)
    bad("poisson_ratio", "must be in [0, 0.5), got " + str(p.poisson_ratio));
  if (!finite(p.crack_width_m) || p.crack_width_m <= 0.0)
    bad("crack_width_m", "must be positive and finite, got " + str(p.crack_width_m));
  if (!finite(p.needle_radius_m) || p.needle_radius_m <= 0.0)
    bad("needle_radius_m", "must be positive and finite, got " + str(p.needle_radius_m));
  if (2.0 * p.needle_radius_m >= p.crack_width_m)
    bad("needle_radius_m", "gives a needle diameter " + str(2.0 * p.needle_radius_m) +
                               " m not below crack_width_m " + str(p.crack_width_m) +
                               " m: the needle would have to extend the crack");
  if (!finite(p.block_size_m) || p.block_size_m < 10.0 * p.crack_width_m)
    bad("block_size_m", "must be finite and at least 10 crack_width_m (" +
                            str(10.0 * p.crack_width_m) + " m), got " + str(p.block_size_m));
  if (!finite(p.element_size_m) || p.element_size_m < 0.0)
    bad("element_size_m", "must be positive (or 0 for the default), got " + str(p.element_size_m));
  const double h = element_size(p);
  const double a = 0.5 * p.crack_width_m;
  if (h > a / 4.0)
    bad("element_size_m",
        str(h) + " m leaves fewer than 4 elements along the half slit " + str(a) + " m");
  // Counted before anything is allocated: a tiny size must not start unbounded work.
  const double along_slit = std::ceil(a / h);
  if (along_slit > kCrackMaxNodes)
    bad("element_size_m", str(h) + " m would need more than " + str(kCrackMaxNodes) + " nodes");
  const double half = 0.5 * p.block_size_m;
  const double nx = along_slit + graded_count(half - a, h, kCrackGridGrowth) + 1.0;
  const double ny = graded_count(half, h, kCrackGridGrowth) + 1.0;
  if (nx * ny > kCrackMaxNodes)
    bad("element_size_m", str(h) + " m would need about " + str(nx * ny) +
                              " nodes, more than the limit " + str(kCrackMaxNodes));
}

struct Grid {
  std::vector<double> x, y;
  int slit_end = 0;  // index of x = a (the crack tip) in x
  double h = 0.0;
  int nx() const { return static_cast<int>(x.size()); }
  int ny() const { return static_cast<int>(y.size()); }
  int node(int i, int j) const { return j * nx() + i; }
};

Grid make_grid(const CrackOpeningProblem& p) {
  const double a = 0.5 * p.crack_width_m;
  const double half = 0.5 * p.block_size_m;
  const int n = static_cast<int>(std::ceil(a / element_size(p) - 1e-9));
  Grid g;
  g.h = a / n;
  for (int i = 0; i <= n; ++i) g.x.push_back(a * i / n);
  g.slit_end = n;
  append_graded(g.x, a, half, g.h, kCrackGridGrowth);
  g.y.push_back(0.0);
  append_graded(g.y, 0.0, half, g.h, kCrackGridGrowth);
  return g;
}

class Model {
 public:
  explicit Model(const CrackOpeningProblem& p) : grid_(make_grid(p)) {
    const int nx = grid_.nx(), ny = grid_.ny();
    const int dofs = 2 * nx * ny;
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(64) * (nx - 1) * (ny - 1));
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        const Eigen::Matrix<double, 8, 8> k = plane_strain_rectangle_stiffness(
            grid_.x[i + 1] - grid_.x[i], grid_.y[j + 1] - grid_.y[j], p.youngs_modulus_Pa,
            p.poisson_ratio);
        const std::array<int, 4> n{grid_.node(i, j), grid_.node(i + 1, j), grid_.node(i + 1, j + 1),
                                   grid_.node(i, j + 1)};
        for (int a = 0; a < 8; ++a)
          for (int b = 0; b < 8; ++b)
            t.emplace_back(2 * n[a / 2] + a % 2, 2 * n[b / 2] + b % 2, k(a, b));
      }
    K_.resize(dofs, dofs);
    K_.setFromTriplets(t.begin(), t.end());
    K_.makeCompressed();
    fixed_.assign(dofs, 0);
    for (int j = 0; j < ny; ++j) fixed_[2 * grid_.node(0, j)] = 1;  // symmetry x = 0
    for (int i = grid_.slit_end; i < nx; ++i)
      fixed_[2 * grid_.node(i, 0) + 1] = 1;  // symmetry ahead of the tip (tip included)
    if (p.outer_edges == OuterEdges::Pinned) {
      for (int j = 0; j < ny; ++j)
        for (int c = 0; c < 2; ++c) fixed_[2 * grid_.node(nx - 1, j) + c] = 1;
      for (int i = 0; i < nx; ++i)
        for (int c = 0; c < 2; ++c) fixed_[2 * grid_.node(i, ny - 1) + c] = 1;
    }
    // Supports as unit rows and columns: every load below is zero on them, so they stay zero.
    Eigen::SparseMatrix<double> A = K_;
    for (Eigen::Index col = 0; col < A.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, col); it; ++it)
        if (fixed_[it.row()] || fixed_[col]) it.valueRef() = it.row() == col ? 1.0 : 0.0;
    solver_.factorize(A);
    if (!solver_.ok())
      throw SolverError("plane-strain crack: the stiffness matrix could not be factorised");
  }

  const Grid& grid() const { return grid_; }
  int nodes() const { return grid_.nx() * grid_.ny(); }
  int elements() const { return (grid_.nx() - 1) * (grid_.ny() - 1); }
  double energy(const Eigen::VectorXd& u) const { return 0.5 * u.dot(K_ * u); }

  // Displacement under nodal forces f (entries on supported dofs are ignored).
  Eigen::VectorXd solve(Eigen::VectorXd f) const {
    for (Eigen::Index k = 0; k < f.size(); ++k)
      if (fixed_[k]) f[k] = 0.0;
    return solver_.solve(f);
  }

  // Compliance of the first `count` nodes (the slit face, row y = 0): C(2i + c, 2j + d) is u_c
  // of node i under a unit force d on node j. Solved in blocks of columns to bound the memory.
  Eigen::MatrixXd face_compliance(int count) const {
    const int m = 2 * count;
    constexpr int kBlock = 64;
    Eigen::MatrixXd C(m, m);
    for (int first = 0; first < m; first += kBlock) {
      const int b = std::min(kBlock, m - first);
      Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(K_.rows(), b);
      for (int k = 0; k < b; ++k)
        if (!fixed_[first + k]) rhs(first + k, k) = 1.0;
      C.middleCols(first, b) = solver_.solve_many(rhs).topRows(m);
    }
    return C;
  }

 private:
  Grid grid_;
  Eigen::SparseMatrix<double> K_;
  std::vector<char> fixed_;
  SparseSolver solver_;
};

}  // namespace

double pressurised_slit_strain_energy(const CrackOpeningProblem& geometry_and_material,
                                      double pressure_Pa, double* opening_at_centre_m) {
  check(geometry_and_material);
  if (!std::isfinite(pressure_Pa)) bad("pressure_Pa", "must be finite, got " + str(pressure_Pa));
  Model model(geometry_and_material);
  const Grid& g = model.grid();
  // Consistent nodal forces of a uniform pressure on the face 0 <= x <= a; it pushes the upper
  // face (material y > 0) in +y. The tip node's share goes to its support.
  Eigen::VectorXd f = Eigen::VectorXd::Zero(2 * model.nodes());
  for (int i = 0; i < g.slit_end; ++i) {
    const double half = 0.5 * pressure_Pa * (g.x[i + 1] - g.x[i]);
    f[2 * g.node(i, 0) + 1] += half;
    f[2 * g.node(i + 1, 0) + 1] += half;
  }
  const Eigen::VectorXd u = model.solve(f);
  if (opening_at_centre_m) *opening_at_centre_m = 2.0 * u[2 * g.node(0, 0) + 1];
  return 4.0 * model.energy(u);
}

CrackOpeningResult crack_opening_strain_energy(const CrackOpeningProblem& problem) {
  check(problem);
  const Model model(problem);
  const Grid& g = model.grid();
  const double r = problem.needle_radius_m;
  const bool radial = problem.contact_gap == CrackContactGap::Radial;

  // The needle touches only the slit face (nodes 0 <= x < a of row y = 0, node index = i; the
  // tip is held by symmetry), and the block is linear: the contact problem lives on the face's
  // compliance, factorised once. A held node i carries a normal force lambda_i n_i (frictionless)
  // and its displacement along n_i is prescribed: sum_j n_i^T C_ij n_j lambda_j = value_i.
  const int face = g.slit_end;
  const Eigen::MatrixXd C = model.face_compliance(face);
  std::vector<char> active(face, 0);
  std::vector<Eigen::Vector2d> normal(face, Eigen::Vector2d::UnitY());
  auto value_of = [&](int i) {
    // radial: the node is moved onto the circle along its normal (exact once the normal is the
    // one through its final position); vertical: to the circle's height above its reference x
    return radial ? r - normal[i].x() * g.x[i] : std::sqrt(std::max(0.0, r * r - g.x[i] * g.x[i]));
  };
  // Start: every node the undeformed face has inside the circle, aimed at the circle point above
  // it. The node on x = 0 keeps the normal (0, 1): symmetry holds its u_x.
  for (int i = 0; i < face; ++i)
    if (g.x[i] < r) {
      active[i] = 1;
      if (radial) normal[i] = Eigen::Vector2d(g.x[i], std::sqrt(r * r - g.x[i] * g.x[i])) / r;
    }

  Eigen::VectorXd q = Eigen::VectorXd::Zero(2 * face);   // forces on the face nodes
  Eigen::VectorXd uf = Eigen::VectorXd::Zero(2 * face);  // their displacements
  int iterations = 0;
  for (;;) {
    if (iterations == kMaxActiveSetIterations)
      throw SolverError("plane-strain crack: the needle's contact set did not settle in " +
                        std::to_string(kMaxActiveSetIterations) + " active-set iterations");
    ++iterations;
    std::vector<int> held;
    for (int i = 0; i < face; ++i)
      if (active[i]) held.push_back(i);
    const int k = static_cast<int>(held.size());
    Eigen::MatrixXd N = Eigen::MatrixXd::Zero(2 * face, k);  // columns: n_i at node i's dofs
    Eigen::VectorXd value(k);
    for (int c = 0; c < k; ++c) {
      N.block<2, 1>(2 * held[c], c) = normal[held[c]];
      value[c] = value_of(held[c]);
    }
    const Eigen::MatrixXd CN = C * N;
    const Eigen::VectorXd lambda = (N.transpose() * CN).ldlt().solve(value);
    q = N * lambda;
    uf = CN * lambda;

    const double largest = k > 0 ? lambda.cwiseAbs().maxCoeff() : 0.0;
    bool changed = false;
    double normal_change = 0.0;
    for (int c = 0; c < k; ++c)
      if (lambda[c] < -kTensionTolerance * largest) {
        active[held[c]] = 0;  // the needle would have to pull: the face leaves it here
        changed = true;
      }
    for (int i = 0; i < face; ++i) {
      const Eigen::Vector2d p(g.x[i] + uf[2 * i], uf[2 * i + 1]);
      if (active[i]) {
        if (radial && i > 0) {
          const Eigen::Vector2d n = p.normalized();
          normal_change = std::max(normal_change, (n - normal[i]).norm());
          normal[i] = n;
        }
        continue;
      }
      const bool inside =
          radial ? p.norm() < r * (1.0 - kPenetrationTolerance)
                 : g.x[i] < r && uf[2 * i + 1] < value_of(i) - kPenetrationTolerance * r;
      if (inside) {
        active[i] = 1;
        if (radial) normal[i] = i > 0 ? p.normalized() : Eigen::Vector2d::UnitY();
        changed = true;
      }
    }
    if (!changed && normal_change < kNormalTolerance) break;
  }

  // The whole field under the converged face forces: U = 1/2 u^T K u of the quarter.
  Eigen::VectorXd f = Eigen::VectorXd::Zero(2 * model.nodes());
  f.head(2 * face) = q;
  const Eigen::VectorXd u = model.solve(f);

  CrackOpeningResult out;
  out.strain_energy_J_per_m = 4.0 * model.energy(u);
  out.nodes = model.nodes();
  out.elements = model.elements();
  out.element_size_m = g.h;
  out.active_set_iterations = iterations;
  out.min_face_opening_m = u[1];
  for (int i = 0; i < face; ++i) {
    const Eigen::Vector2d p(g.x[i] + u[2 * i], u[2 * i + 1]);
    out.max_penetration_m = std::max(out.max_penetration_m, r - p.norm());
    out.min_face_opening_m = std::min(out.min_face_opening_m, u[2 * i + 1]);
    if (active[i]) {
      ++out.contact_nodes;
      out.contact_extent_m = std::max(out.contact_extent_m, g.x[i]);
    }
  }
  return out;
}

}  // namespace mneedle::fe
