// Needle insertion into the axisymmetric model: sticking and frictionless contact, linear
// (condensed) and nonlinear (Newton) drivers advanced depth by depth, the cracked twin model for
// the energy release rate, per-step outputs, and the one-call problem setup.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "axisymmetric_internal.h"
#include "fe/vtu_writer.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/fe/axisymmetric.h"

namespace mneedle::fe {

using namespace axi;

namespace {

// Largest outer radius of the needle's profile up to `height` above its tip (m), the profile
// linear between its points.
double outline_radius_up_to(const AxisymmetricNeedle& needle, double height) {
  double r = 0.0;
  for (std::size_t i = 0; i < needle.heights_m.size(); ++i) {
    if (needle.heights_m[i] <= height) {
      r = std::max(r, needle.radii_m[i]);
      continue;
    }
    if (i > 0) {
      const double h0 = needle.heights_m[i - 1], h1 = needle.heights_m[i];
      const double t = (height - h0) / (h1 - h0);
      r = std::max(r, needle.radii_m[i - 1] + t * (needle.radii_m[i] - needle.radii_m[i - 1]));
    }
    break;
  }
  return r;
}

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

// Where candidate `node`, inside the needle at (d1, u1), crossed its surface on the straight
// path from (d0, u0): the fraction t of the step (0 when it was not outside at d0), and the
// crossing point; nullopt when it is not inside at d1.
struct Crossing {
  double t;
  Eigen::Vector2d point;
};
std::optional<Crossing> crossing(const AxisymmetricNeedle& needle, const AxisymmetricMesh& mesh,
                                 std::uint32_t node, double d0, const Eigen::VectorXd& u0,
                                 double d1, const Eigen::VectorXd& u1) {
  const Eigen::Vector2d X = mesh.nodes[node];
  const Eigen::Vector2d p0 = X + Eigen::Vector2d(u0[2 * node], u0[2 * node + 1]);
  const Eigen::Vector2d p1 = X + Eigen::Vector2d(u1[2 * node], u1[2 * node + 1]);
  const double g1 = gap(needle, d1, p1);
  if (!(g1 < 0.0)) return std::nullopt;
  const double g0 = gap(needle, d0, p0);
  const double t = std::isfinite(g0) && g0 > 0.0 ? g0 / (g0 - g1) : 0.0;
  return Crossing{t, p0 + t * (p1 - p0)};
}

// Captures every candidate node that entered the needle between (d0, u0) and (d1, u1), at the
// linearly interpolated crossing, as long as that crossing lies within `latest` of the step.
// Returns how many were added.
int capture_new_nodes(const AxisymmetricNeedle& needle,
                      const std::vector<std::uint32_t>& candidates, const AxisymmetricMesh& mesh,
                      double d0, const Eigen::VectorXd& u0, double d1, const Eigen::VectorXd& u1,
                      ContactState& state, double latest = 1.0) {
  int added = 0;
  for (std::uint32_t node : candidates) {
    if (state.captured.count(node)) continue;
    const std::optional<Crossing> c = crossing(needle, mesh, node, d0, u0, d1, u1);
    if (!c || c->t > latest) continue;
    state.captured[node] = Capture{c->point, d0 + c->t * (d1 - d0)};
    ++added;
  }
  return added;
}

// The earliest crossing, as a fraction t of the step (d0, d1], of the candidates not yet captured
// that are inside the needle at d1; 2 when none is.
double earliest_capture(const AxisymmetricNeedle& needle,
                        const std::vector<std::uint32_t>& candidates, const AxisymmetricMesh& mesh,
                        double d0, const Eigen::VectorXd& u0, double d1, const Eigen::VectorXd& u1,
                        const ContactState& state) {
  double earliest = 2.0;
  for (std::uint32_t node : candidates) {
    if (state.captured.count(node)) continue;
    if (const std::optional<Crossing> c = crossing(needle, mesh, node, d0, u0, d1, u1))
      earliest = std::min(earliest, c->t);
  }
  return earliest;
}

// A capture inside a step ends the step there (docs/model.md, "Contact with the rigid needle
// (AxisymmetricNeedle)", sticking): the nodes found inside the needle at a step's end are
// captured when the earliest of them crosses within kCaptureGroup of the step's end, or within
// kShortestCaptureStep of a sub-step (linear) or an output interval (nonlinear; at least the
// stepper's shortest step) of its start, where its crossing t = 0 (touching from the start);
// otherwise the step is cut back to that crossing. Capturing every node inside the needle at the
// step's end instead pins nodes the tissue would have carried away before the needle reached
// them (a stiff layer bends away from a rounded tip): the depth then moved with the step (a
// 37 um rounded tip on skin fired at the first step).
constexpr double kCaptureGroup = 1e-3;
constexpr double kShortestCaptureStep = 1e-6;

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

// A ring crack's faces: each doubled node {inner, outer}.
using FacePairs = std::vector<std::array<std::uint32_t, 2>>;

// Linear insertion: one factorisation, the stiffness condensed onto the reachable surface dofs
// (Schur complement S); every depth is then a small dense solve.
class CondensedSurface {
 public:
  /// keep_response: store the free dofs' response to the candidates (n x candidate dofs) so
  /// that full() can recover the whole displacement field.
  CondensedSurface(AxisymmetricModel& model, const std::vector<std::uint32_t>& candidates,
                   bool keep_response)
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
    if (keep_response) response_ = std::move(response);
  }

  /// Whole displacement field for candidate displacements u (keep_response was set).
  Eigen::VectorXd full(const Eigen::VectorXd& u) const { return response_ * u; }

  const std::vector<std::uint32_t>& dofs() const { return dofs_; }

  // Candidate displacements and forces with the captured nodes prescribed and the rest free;
  // each pair in `closed` (condensed dof indices {inner u_r, outer u_r}) held at zero gap,
  // u_r(outer) = u_r(inner), by a Lagrange multiplier.
  // `stiffness`, when given, replaces S (S with a cohesive interface's springs, with_springs).
  void solve(const AxisymmetricMesh& mesh, const ContactState& state, double depth,
             Eigen::VectorXd& u, Eigen::VectorXd& f,
             const std::vector<std::array<int, 2>>& closed = {},
             const Eigen::MatrixXd* stiffness = nullptr) const {
    const Eigen::MatrixXd& S = stiffness ? *stiffness : S_;
    std::vector<Eigen::Index> free, fixed;
    partition(mesh, state, depth, u, free, fixed);
    if (!free.empty() && !closed.empty()) {
      solve_closed(S, free, fixed, closed, u);
    } else if (!free.empty()) {
      Eigen::MatrixXd S_ff(free.size(), free.size());
      Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(free.size()));
      for (std::size_t a = 0; a < free.size(); ++a) {
        for (std::size_t b = 0; b < free.size(); ++b) S_ff(a, b) = S(free[a], free[b]);
        for (Eigen::Index c : fixed) rhs[a] -= S(free[a], c) * u[c];
      }
      const Eigen::VectorXd uf = S_ff.ldlt().solve(rhs);
      for (std::size_t a = 0; a < free.size(); ++a) u[free[a]] = uf[a];
    }
    f = S * u;
  }

  // The condensed dofs held by the needle (captured) or the axis, `fixed`, with their values in
  // u (zero elsewhere), and the rest, `free`.
  void partition(const AxisymmetricMesh& mesh, const ContactState& state, double depth,
                 Eigen::VectorXd& u, std::vector<Eigen::Index>& free,
                 std::vector<Eigen::Index>& fixed) const {
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
    free.clear();
    fixed.clear();
    for (Eigen::Index j = 0; j < m; ++j) (prescribed[j] ? fixed : free).push_back(j);
  }

  // The free part of solve() with zero-gap pairs: the saddle-point system
  // [S_ff G_fᵀ; G_f 0] [u_f; μ] = [-S_fc u_c; -G_c u_c], solved by full-pivoting LU (small and
  // indefinite).
  void solve_closed(const Eigen::MatrixXd& S, const std::vector<Eigen::Index>& free,
                    const std::vector<Eigen::Index>& fixed,
                    const std::vector<std::array<int, 2>>& closed, Eigen::VectorXd& u) const {
    const auto nf = static_cast<Eigen::Index>(free.size());
    const auto k = static_cast<Eigen::Index>(closed.size());
    std::vector<Eigen::Index> position(static_cast<std::size_t>(u.size()), -1);
    for (Eigen::Index a = 0; a < nf; ++a) position[static_cast<std::size_t>(free[a])] = a;
    Eigen::MatrixXd kkt = Eigen::MatrixXd::Zero(nf + k, nf + k);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nf + k);
    for (Eigen::Index a = 0; a < nf; ++a) {
      for (Eigen::Index b = 0; b < nf; ++b) kkt(a, b) = S(free[a], free[b]);
      for (Eigen::Index c : fixed) rhs[a] -= S(free[a], c) * u[c];
    }
    for (Eigen::Index p = 0; p < k; ++p) {
      const std::array<int, 2>& dofs = closed[static_cast<std::size_t>(p)];
      const double sign[2] = {-1.0, 1.0};  // gap = u_r(outer) - u_r(inner)
      for (int side = 0; side < 2; ++side) {
        const Eigen::Index at = position[static_cast<std::size_t>(dofs[side])];
        if (at >= 0) {
          kkt(nf + p, at) = sign[side];
          kkt(at, nf + p) = sign[side];
        } else {
          rhs[nf + p] -= sign[side] * u[dofs[side]];
        }
      }
    }
    const Eigen::VectorXd x = kkt.fullPivLu().solve(rhs);
    for (Eigen::Index a = 0; a < nf; ++a) u[free[a]] = x[a];
  }

  // Frictionless: each active node's vertical displacement puts it on the needle's lower
  // surface above its reference radius; its radial displacement is free (no shear on the
  // surface). Minimises the condensed energy with Lagrange multipliers.
  void solve_frictionless(const AxisymmetricMesh& mesh, const AxisymmetricNeedle& needle,
                          double depth, const std::set<std::uint32_t>& active, Eigen::VectorXd& u,
                          Eigen::VectorXd& f) const {
    const auto m = static_cast<Eigen::Index>(dofs_.size());
    Eigen::Index count = 0;
    for (Eigen::Index j = 0; j < m; ++j) count += axis_fixed_[j];
    count += static_cast<Eigen::Index>(active.size());
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(count, m);
    Eigen::VectorXd c = Eigen::VectorXd::Zero(count);
    Eigen::Index row = 0;
    for (Eigen::Index j = 0; j < m; ++j)
      if (axis_fixed_[j]) G(row++, j) = 1.0;
    for (std::uint32_t node : active) {
      const int j = index_.at(node);
      const Eigen::Vector2d X = mesh.nodes[node];
      G(row, j + 1) = 1.0;
      c[row] = -depth + needle.lowest_height_at(X.x()) - X.y();
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

  /// A spring of stiffness k (N/m, the whole ring) between two condensed dofs.
  struct Spring {
    int a = 0, b = 0;
    double k = 0.0;
  };
  /// S with the springs added: the condensed stiffness of the tissue held across a cohesive
  /// interface whose nodes are all condensed.
  Eigen::MatrixXd with_springs(const std::vector<Spring>& springs) const {
    Eigen::MatrixXd S = S_;
    for (const Spring& s : springs) {
      S(s.a, s.a) += s.k;
      S(s.b, s.b) += s.k;
      S(s.a, s.b) -= s.k;
      S(s.b, s.a) -= s.k;
    }
    return S;
  }

  /// Gap u_r(outer) - u_r(inner) of each crack-face pair in condensed displacements u (every
  /// pair node condensed; zeros before the first solve).
  Eigen::VectorXd gaps(const Eigen::VectorXd& u, const FacePairs& pairs) const {
    Eigen::VectorXd g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs.size()));
    if (u.size() == 0) return g;
    for (std::size_t p = 0; p < pairs.size(); ++p)
      g[static_cast<Eigen::Index>(p)] = u[index_of(pairs[p][1])] - u[index_of(pairs[p][0])];
    return g;
  }

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
  Eigen::MatrixXd response_;
};

// One insertion on one model, advanced to a growing sequence of depths.
// Active-set rounds of the crack-face contact per solve; a pair closes when its faces overlap by
// more than kCrackGapTolerance x the current depth (round-off of the condensed solve is ~1e-16
// of it).
constexpr int kMaxCrackRounds = 100;   // plus four per pair
constexpr int kCrackBlockRounds = 20;  // rounds that open every pulling pair at once
constexpr double kCrackGapTolerance = 1e-10;
// A closed pair pulls when its force is below -kCrackForceFloor x the largest condensed force.
constexpr double kCrackForceFloor = 1e-12;

class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual InsertionStep advance_to(double depth) = 0;
  /// Whole displacement field (2 per node) at the last depth.
  virtual Eigen::VectorXd displacement() const = 0;
  /// Gap u_r(outer) - u_r(inner) of every crack-face pair at the last depth (m).
  virtual Eigen::VectorXd face_gaps(const FacePairs& pairs) const {
    const Eigen::VectorXd u = displacement();
    Eigen::VectorXd gaps(static_cast<Eigen::Index>(pairs.size()));
    for (std::size_t p = 0; p < pairs.size(); ++p)
      gaps[static_cast<Eigen::Index>(p)] = u[2 * pairs[p][1]] - u[2 * pairs[p][0]];
    return gaps;
  }
  /// Pairs held closed by crack-face contact at the last depth.
  virtual int closed_pairs() const { return 0; }
};

// Candidates followed by the crack-face nodes that are not candidates: the condensed set.
std::vector<std::uint32_t> with_face_nodes(std::vector<std::uint32_t> nodes,
                                           const FacePairs& pairs) {
  std::set<std::uint32_t> seen(nodes.begin(), nodes.end());
  for (const auto& pair : pairs)
    for (std::uint32_t node : pair)
      if (seen.insert(node).second) nodes.push_back(node);
  return nodes;
}

// Nonlinear crack-face contact (augmented Lagrangian, AxisymmetricModel::set_face_pairs): a
// closed pair's gap must fall below Newton's relative residual tolerance (default 1e-8) x the
// depth, and a closed pair opens when it pulls by more than that tolerance x the largest pair
// force (the linear path's 1e-10 and 1e-12 are its condensed solve's round-off).
enum class PairUpdate { Settled, Multipliers, Set };

// Crack-face pairs of the nonlinear stepper within one step: held (1) or open, the multipliers,
// the pairs opened for pulling in this step and those latched closed after overlapping again.
struct PairState {
  std::vector<char> closed;
  Eigen::VectorXd multipliers;
  std::vector<char> pulled_open, latched;
};

// Nonlinear layers: Newton at every sub-step, adaptive step length.
class NonlinearStepper : public Stepper {
 public:
  // pairs: the ring crack's faces (cracked twin), kept apart when `close_pairs` is set.
  NonlinearStepper(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                   const InsertionOptions& options, FacePairs pairs = {}, bool close_pairs = false)
      : model_(model),
        needle_(needle),
        newton_(options.newton),
        candidates_(reachable_surface_nodes(model.mesh(), needle, options.depth_m)),
        interval_(options.depth_m / options.output_steps),
        step_(interval_),
        min_step_(1e-5 * options.depth_m),
        pairs_(std::move(pairs)) {
    current_.displacement = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.dof_count()));
    current_.reaction = current_.displacement;
    close_pairs_ = close_pairs && !pairs_.empty();
    if (close_pairs_) {
      model_.set_face_pairs(pairs_);
      pairs_state_.closed.assign(pairs_.size(), 0);
      pairs_state_.multipliers = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs_.size()));
    }
  }

  int closed_pairs() const override {
    return static_cast<int>(std::count(pairs_state_.closed.begin(), pairs_state_.closed.end(), 1));
  }

  InsertionStep advance_to(double target) override {
    const AxisymmetricMesh& mesh = model_.mesh();
    int iterations = 0;
    while (depth_ < target * (1.0 - 1e-12)) {
      step_ = std::min(step_, target - depth_);
      const double next = depth_ + step_;
      ContactState trial_state = state_;
      PairState trial_pairs = pairs_state_;
      trial_pairs.pulled_open.assign(pairs_.size(), 0);
      trial_pairs.latched.assign(pairs_.size(), 0);
      int trial_iterations = 0;
      int largest_solve = 0;  // Newton iterations of the step's hardest single solve
      double event = 0.0;     // > 0: a capture inside the step, which ends there
      std::string failure;
      Equilibrium trial;
      try {
        boundary_conditions(mesh, trial_state, next, dofs_, values_);
        if (close_pairs_) model_.set_pair_state(trial_pairs.closed, trial_pairs.multipliers);
        trial = model_.solve(dofs_, values_, predictor(next), newton_);
        trial_iterations += trial.newton_iterations;
        const int rounds =
            50 + (close_pairs_ ? kMaxCrackRounds + 4 * static_cast<int>(pairs_.size()) : 0);
        largest_solve = trial.newton_iterations;
        for (int round = 0;; ++round) {
          // The first capture inside the step ends the step there (kCaptureGroup).
          const double t =
              earliest_capture(needle_, candidates_, mesh, depth_, current_.displacement, next,
                               trial.displacement, trial_state);
          // An event never cuts the step below the stepper's shortest one, which a failed
          // solve right after it could not halve.
          const double start =
              std::max(kShortestCaptureStep * interval_, min_step_) / (next - depth_);
          if (t > start && t < 1.0 - kCaptureGroup) {
            event = depth_ + t * (next - depth_);
            break;
          }
          const bool captured =
              capture_new_nodes(needle_, candidates_, mesh, depth_, current_.displacement, next,
                                trial.displacement, trial_state, t <= start ? start : 1.0) > 0;
          PairUpdate pairs = close_pairs_
                                 ? update_pairs(trial.displacement, next, round, trial_pairs)
                                 : PairUpdate::Settled;
          // New multipliers that Newton absorbed without an iteration are within its tolerance.
          if (pairs == PairUpdate::Multipliers && round > 0 && trial.newton_iterations == 0)
            pairs = PairUpdate::Settled;
          if (!captured && pairs == PairUpdate::Settled) break;
          if (round + 1 >= rounds) {
            // Captures alone may stop short (as on the intact model); crack faces may not.
            if (pairs != PairUpdate::Settled)
              throw SolverError("crack-face contact did not settle at depth " + format_depth(next));
            break;
          }
          boundary_conditions(mesh, trial_state, next, dofs_, values_);
          if (close_pairs_) model_.set_pair_state(trial_pairs.closed, trial_pairs.multipliers);
          trial = model_.solve(dofs_, values_, trial.displacement, newton_);
          trial_iterations += trial.newton_iterations;
          largest_solve = std::max(largest_solve, trial.newton_iterations);
        }
      } catch (const OutOfMemoryError&) {
        throw;  // a shorter step needs as much memory
      } catch (const SolverError& e) {
        failure = e.what();
      }
      if (event > 0.0) {
        step_ = event - depth_;
        iterations += trial_iterations;
        continue;
      }
      if (!failure.empty()) {
        step_ *= 0.5;
        if (step_ < min_step_)
          throw SolverError("axisymmetric insertion stopped at depth " + format_depth(depth_) +
                            ": " + failure);
        continue;
      }
      last_increment_ = trial.displacement - current_.displacement;
      last_step_ = next - depth_;
      depth_ = next;
      current_ = std::move(trial);
      state_ = std::move(trial_state);
      pairs_state_ = std::move(trial_pairs);
      // Grow the step when no single solve was hard (the re-solves of captures and crack faces
      // each converge in a few iterations and do not say the step was too long).
      // Without crack faces the rule is the sum over the step's solves, as before the faces were
      // held, so that an intact run's sub-steps (hence its captures) do not move.
      const int effort = close_pairs_ ? largest_solve : trial_iterations;
      iterations += trial_iterations;
      if (effort <= 6) step_ = std::min(step_ * 1.5, interval_);
    }
    const double force = needle_force(state_, current_.reaction);
    const double area = contact_area(mesh, needle_, state_, current_.displacement);
    return make_step(depth_, force, area, current_.strain_energy_J, iterations,
                     static_cast<int>(state_.captured.size()));
  }

  Eigen::VectorXd displacement() const override { return current_.displacement; }

 private:
  // Start of Newton at depth `next`: the last converged increment extrapolated linearly (the
  // path is smooth between captures), with the prescribed values put in place, so that the
  // previous factorisation can often serve the whole step (modified Newton).
  Eigen::VectorXd predictor(double next) const {
    Eigen::VectorXd start = current_.displacement;
    if (last_step_ > 0.0) start += (next - depth_) / last_step_ * last_increment_;
    for (std::size_t i = 0; i < dofs_.size(); ++i)
      start[dofs_[i]] = values_[static_cast<Eigen::Index>(i)];
    return start;
  }

  // One round of the crack-face active set on the solution u at `depth`, with the state the solve
  // used: closed pairs that pull (t > 0) open, all at once for the first kCrackBlockRounds rounds
  // and then the one pulled hardest; when none pulls, each closed pair's multiplier takes its
  // force (Uzawa) and open pairs that overlap close. Set: a pair opened or closed; Multipliers:
  // only the multipliers moved because a closed pair still overlaps or gapes by more than the
  // tolerance; Settled: neither.
  PairUpdate update_pairs(const Eigen::VectorXd& u, double depth, int round,
                          PairState& state) const {
    std::vector<char>& closed = state.closed;
    Eigen::VectorXd& multipliers = state.multipliers;
    const double tolerance = newton_.residual_tolerance * std::max(depth, 1e-12);
    const Eigen::VectorXd t = model_.pair_forces(u);
    const double floor = newton_.residual_tolerance * t.lpNorm<Eigen::Infinity>();
    Eigen::VectorXd gaps(static_cast<Eigen::Index>(pairs_.size()));
    for (std::size_t p = 0; p < pairs_.size(); ++p)
      gaps[static_cast<Eigen::Index>(p)] = u[2 * pairs_[p][1]] - u[2 * pairs_[p][0]];
    std::size_t worst = pairs_.size();
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      const auto i = static_cast<Eigen::Index>(p);
      if (closed[p] && !state.latched[p] && t[i] > floor &&
          (worst == pairs_.size() || t[i] > t[worst]))
        worst = p;
    }
    if (worst < pairs_.size()) {
      for (std::size_t p = 0; p < pairs_.size(); ++p) {
        const auto i = static_cast<Eigen::Index>(p);
        if (closed[p] && !state.latched[p] && t[i] > floor &&
            (round < kCrackBlockRounds || p == worst)) {
          closed[p] = 0;
          multipliers[i] = 0.0;
          state.pulled_open[p] = 1;
        }
      }
      return PairUpdate::Set;
    }
    bool moved = false, changed = false;
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      const auto i = static_cast<Eigen::Index>(p);
      if (closed[p]) {
        multipliers[i] = t[i];
        moved = moved || std::abs(gaps[i]) > tolerance;
      } else if (gaps[i] < -tolerance) {
        closed[p] = 1;
        multipliers[i] = 0.0;
        // Pulls when closed, overlaps when open: no complementary state exists for this pair
        // in this step (node-to-node under large sliding); it stays closed, pulling a little.
        if (state.pulled_open[p]) state.latched[p] = 1;
        changed = true;
      }
    }
    return changed ? PairUpdate::Set : moved ? PairUpdate::Multipliers : PairUpdate::Settled;
  }

  AxisymmetricModel& model_;
  AxisymmetricNeedle needle_;
  NewtonOptions newton_;
  std::vector<std::uint32_t> candidates_;
  double interval_, step_, min_step_;
  double depth_ = 0.0;
  ContactState state_;
  Equilibrium current_;
  FacePairs pairs_;
  bool close_pairs_ = false;
  PairState pairs_state_;
  std::vector<std::uint32_t> dofs_;
  Eigen::VectorXd values_;
  Eigen::VectorXd last_increment_;
  double last_step_ = 0.0;
};

// A cohesive ring crack's face pairs with what the law needs of each (docs/model.md, "Cohesive
// ring crack"): its share of the ring's face area and its depth, and the largest mixed-mode
// opening it has reached at the last committed depth.
struct CohesiveRing {
  CohesiveLaw law;
  std::vector<double> area_m2, depth_m, reached_m;
  double line_depth_m = 0.0;       // the crack line's end (the shared front node)
  std::vector<std::size_t> order;  // the pairs down the line: corner, mid, corner, ...
};

// Shares of the line r = radius, 0 >= z > -depth: the line is a column of quadratic edges whose
// nodes alternate corner, mid-edge, corner from the surface down to the front; each edge of
// length L gives L/6 to its corners and 4L/6 to its mid node (Simpson: nodal integration, which
// keeps the interface's tractions free of the oscillations a Gauss rule gives at a stiff law).
CohesiveRing cohesive_ring(const AxisymmetricMesh& mesh, const FacePairs& pairs, double radius,
                           double depth, const CohesiveLaw& law) {
  CohesiveRing ring;
  ring.law = law;
  ring.line_depth_m = depth;
  std::vector<std::size_t> order(pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p) order[p] = p;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return mesh.nodes[pairs[a][0]].y() > mesh.nodes[pairs[b][0]].y();
  });
  std::vector<double> z;  // down the line, the front last
  for (std::size_t p : order) z.push_back(-mesh.nodes[pairs[p][0]].y());
  z.push_back(depth);
  if (z.size() % 2 == 0)
    throw InputError("cohesive ring crack: the crack line is not a column of quadratic edges");
  ring.area_m2.assign(pairs.size(), 0.0);
  ring.depth_m.assign(pairs.size(), 0.0);
  ring.reached_m.assign(pairs.size(), 0.0);
  const double circumference = 2.0 * kPi * radius;
  for (std::size_t k = 0; k + 2 < z.size(); k += 2) {
    const double edge = z[k + 2] - z[k];
    ring.area_m2[order[k]] += circumference * edge / 6.0;
    ring.area_m2[order[k + 1]] += circumference * 4.0 * edge / 6.0;
    if (k + 2 < pairs.size()) ring.area_m2[order[k + 2]] += circumference * edge / 6.0;
  }
  for (std::size_t k = 0; k < pairs.size(); ++k) ring.depth_m[order[k]] = z[k];
  ring.order = std::move(order);
  return ring;
}

// Cohesive rounds per solve: each lets the damage of the pairs grow to what their openings
// say; an unstable crack advances about a cell per round. A damage change below
// kDamageTolerance ends them.
constexpr int kMaxCohesiveRounds = 20000;
constexpr double kDamageTolerance = 1e-6;
// Conjugate gradients per round before the free block is factorised again, and their residual
// (relative to the right-hand side; the direct solve's round-off is ~1e-14 of it).
constexpr int kMaxCgIterations = 40;
constexpr double kCgTolerance = 1e-12;

// Linear layers, sticking: the condensed surface; sub-steps only refine where captures happen,
// the solve itself is exact at any depth.
class LinearStepper : public Stepper {
 public:
  // pairs: the ring crack's faces (cracked twin), kept apart when `close_pairs` is set.
  // cohesive: the pairs' law and shares (then `pairs` are the cohesive ring's, not in contact).
  LinearStepper(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                const InsertionOptions& options, bool keep_field, FacePairs pairs = {},
                bool close_pairs = false, std::optional<CohesiveRing> cohesive = std::nullopt)
      : mesh_(model.mesh()),
        needle_(needle),
        candidates_(reachable_surface_nodes(mesh_, needle, options.depth_m)),
        n_(model.dof_count()),
        sub_step_(options.depth_m / (options.output_steps * kSubsteps)),
        pairs_(std::move(pairs)),
        close_pairs_(close_pairs),
        cohesive_(std::move(cohesive)) {
    previous_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_));
    if (!candidates_.empty())
      surface_ = std::make_unique<CondensedSurface>(model, with_face_nodes(candidates_, pairs_),
                                                    keep_field);
  }

  Eigen::VectorXd face_gaps(const FacePairs& pairs) const override {
    if (!surface_) return Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs.size()));
    return surface_->gaps(u_, pairs);
  }
  int closed_pairs() const override { return static_cast<int>(closed_.size()); }

  InsertionStep advance_to(double target) override {
    if (!surface_) return make_step(target, 0, 0, 0, 0, 0);
    int solves = 0;
    while (depth_ < target * (1.0 - 1e-12)) {
      double next = std::min(target, depth_ + sub_step_ * (1.0 + 1e-9));
      // Captures of this step's rounds at its end are undone when the step is cut back to an
      // earlier crossing: they would be held above where the needle reaches them.
      const ContactState at_start = state_;
      for (int round = 0; round < 1000; ++round) {
        solve_contact(next);
        ++solves;
        const Eigen::VectorXd u = surface_->scatter(u_, n_);
        const double t =
            earliest_capture(needle_, candidates_, mesh_, depth_, previous_, next, u, state_);
        if (t > 1.0) break;
        // Nodes already touching at the step's start are captured there; otherwise the first
        // capture inside the step ends the step there: solve again at it.
        const double start = kShortestCaptureStep * sub_step_ / (next - depth_);
        if (t <= start) {
          capture_new_nodes(needle_, candidates_, mesh_, depth_, previous_, next, u, state_, start);
          continue;
        }
        if (t < 1.0 - kCaptureGroup) {
          next = depth_ + t * (next - depth_);
          for (auto it = state_.captured.begin(); it != state_.captured.end();)
            it = at_start.captured.count(it->first) || it->second.depth <= next
                     ? std::next(it)
                     : state_.captured.erase(it);
          continue;
        }
        capture_new_nodes(needle_, candidates_, mesh_, depth_, previous_, next, u, state_);
      }
      depth_ = next;
      previous_ = surface_->scatter(u_, n_);
      if (cohesive_) cohesive_->reached_m = trial_reached_;
    }
    double force = 0.0;
    for (const auto& entry : state_.captured) {
      const auto& dofs = surface_->dofs();
      const auto it = std::find(dofs.begin(), dofs.end(), 2 * entry.first + 1);
      force -= f_[it - dofs.begin()];
    }
    const double area = contact_area(mesh_, needle_, state_, previous_);
    InsertionStep step = make_step(depth_, force, area, 0.5 * u_.dot(f_), solves,
                                   static_cast<int>(state_.captured.size()));
    if (cohesive_) describe_cohesive(step);
    return step;
  }

  Eigen::VectorXd displacement() const override {
    if (!surface_ || u_.size() == 0) return Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_));
    return surface_->full(u_);
  }

 private:
  // Crack-face contact by an active set (docs/model.md, "Crack faces in contact"): closed pairs
  // whose contact force pulls (the outer node's radial force below zero) open, open pairs whose
  // faces overlap close, until nothing changes.
  void solve_contact(double depth) {
    if (cohesive_) {
      solve_cohesive(depth);
      return;
    }
    if (!close_pairs_ || pairs_.empty()) {
      surface_->solve(mesh_, state_, depth, u_, f_);
      return;
    }
    const double tolerance = kCrackGapTolerance * std::max(depth, 1e-12);
    const int rounds = kMaxCrackRounds + 4 * static_cast<int>(pairs_.size());
    for (int round = 0; round < rounds; ++round) {
      std::vector<std::array<int, 2>> dofs;
      for (std::size_t p : closed_)
        dofs.push_back({surface_->index_of(pairs_[p][0]), surface_->index_of(pairs_[p][1])});
      surface_->solve(mesh_, state_, depth, u_, f_, dofs);
      // Pulling pairs open, all at once for the first kCrackBlockRounds rounds and then the one
      // pulled hardest per round; when none pulls, every overlapping pair closes.
      const double floor = kCrackForceFloor * f_.lpNorm<Eigen::Infinity>();
      std::size_t worst = closed_.size();
      double worst_force = -floor;
      std::vector<std::size_t> kept;
      for (std::size_t c = 0; c < closed_.size(); ++c) {
        const double force = f_[surface_->index_of(pairs_[closed_[c]][1])];
        if (force < worst_force) worst = c, worst_force = force;
        if (force >= -floor) kept.push_back(closed_[c]);
      }
      if (worst < closed_.size()) {
        if (round < kCrackBlockRounds)
          closed_ = std::move(kept);
        else
          closed_.erase(closed_.begin() + static_cast<std::ptrdiff_t>(worst));
        continue;
      }
      const Eigen::VectorXd gaps = face_gaps(pairs_);
      bool changed = false;
      std::vector<std::size_t> next = closed_;
      for (std::size_t p = 0; p < pairs_.size(); ++p)
        if (!std::binary_search(closed_.begin(), closed_.end(), p) &&
            gaps[static_cast<Eigen::Index>(p)] < -tolerance) {
          next.push_back(p);
          changed = true;
        }
      if (!changed) return;
      std::sort(next.begin(), next.end());
      closed_ = std::move(next);
    }
    throw SolverError("axisymmetric insertion: crack-face contact did not settle at depth " +
                      format_depth(depth));
  }

  // The cohesive ring's springs at the largest openings `reached` (the whole ring, N/m): the
  // law's damaged secant on both the radial opening and the axial slip, and the undamaged
  // initial stiffness radially where the faces press on each other (`pressed`).
  std::vector<CondensedSurface::Spring> cohesive_springs(const std::vector<double>& reached,
                                                         const std::vector<char>& pressed) const {
    const CohesiveLaw& law = cohesive_->law;
    const double initial = cohesive_peak_traction(law) / law.peak_opening_m;  // Pa/m
    std::vector<CondensedSurface::Spring> springs;
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      const double k = initial * cohesive_->area_m2[p];
      const double kept = (1.0 - cohesive_damage(law, reached[p])) * k;
      const int in = surface_->index_of(pairs_[p][0]), out = surface_->index_of(pairs_[p][1]);
      springs.push_back({in, out, pressed[p] ? k : kept});
      springs.push_back({in + 1, out + 1, kept});
    }
    return springs;
  }

  // The cohesive ring at `depth` from the committed damage: solve with the springs of the
  // damage so far, let each pair's damage grow to what its opening says, until no damage moves
  // by kDamageTolerance and no pair changes between pressed and open (a secant fixed point; the
  // damage only grows, so the rounds end on the state the law allows nearest the committed one).
  void solve_cohesive(double depth) {
    std::vector<double> reached = cohesive_->reached_m;
    std::vector<char> pressed(pairs_.size(), 0);
    const CohesiveLaw& law = cohesive_->law;
    std::vector<Eigen::Index> free, fixed;
    Eigen::VectorXd u;
    surface_->partition(mesh_, state_, depth, u, free, fixed);
    const auto nf = static_cast<Eigen::Index>(free.size());
    // Each round changes the springs of the few pairs whose damage moved: the factor of an
    // earlier round's free block preconditions conjugate gradients on this one's (the change is
    // of low rank, so they converge in about as many iterations as pairs changed); refactored
    // when they take more than kMaxCgIterations.
    Eigen::LLT<Eigen::MatrixXd> factor;
    bool factored = false;
    Eigen::VectorXd uf = Eigen::VectorXd::Zero(nf);
    for (int round = 0;; ++round) {
      if (round == kMaxCohesiveRounds)
        throw SolverError("cohesive ring crack: the damage did not settle in " +
                          std::to_string(kMaxCohesiveRounds) + " rounds at depth " +
                          format_depth(depth));
      const Eigen::MatrixXd S = surface_->with_springs(cohesive_springs(reached, pressed));
      if (nf > 0) {
        Eigen::MatrixXd A(nf, nf);
        Eigen::VectorXd b = Eigen::VectorXd::Zero(nf);
        for (Eigen::Index a = 0; a < nf; ++a) {
          for (Eigen::Index c = 0; c < nf; ++c) A(a, c) = S(free[a], free[c]);
          for (Eigen::Index c : fixed) b[a] -= S(free[a], c) * u[c];
        }
        if (!factored || !conjugate_gradients(A, b, factor, uf)) {
          factor.compute(A);
          if (factor.info() != Eigen::Success)
            throw SolverError(
                "cohesive ring crack: the stiffness lost its positive definiteness "
                "at depth " +
                format_depth(depth));
          factored = true;
          uf = factor.solve(b);
        }
        for (Eigen::Index a = 0; a < nf; ++a) u[free[a]] = uf[a];
      }
      u_ = u;
      f_ = S * u_;
      ++rounds_;
      bool changed = false;
      for (std::size_t p = 0; p < pairs_.size(); ++p) {
        const int in = surface_->index_of(pairs_[p][0]), out = surface_->index_of(pairs_[p][1]);
        const double radial = u_[out] - u_[in], slip = u_[out + 1] - u_[in + 1];
        const char press = radial < 0.0 ? 1 : 0;
        if (press != pressed[p]) pressed[p] = press, changed = true;
        const double opening = std::hypot(std::max(radial, 0.0), slip);
        if (opening <= reached[p]) continue;
        const double before = cohesive_damage(law, reached[p]);
        reached[p] = opening;
        if (cohesive_damage(law, opening) - before > kDamageTolerance) changed = true;
      }
      if (!changed) break;
    }
    trial_reached_ = std::move(reached);
  }

  // Preconditioned conjugate gradients on A x = b from x, the preconditioner `factor` (of a
  // nearby A): true when the residual falls below kCgTolerance of b within kMaxCgIterations.
  static bool conjugate_gradients(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                                  const Eigen::LLT<Eigen::MatrixXd>& factor, Eigen::VectorXd& x) {
    const double target = kCgTolerance * b.norm();
    Eigen::VectorXd r = b - A * x;
    if (r.norm() <= target) return true;
    Eigen::VectorXd z = factor.solve(r), p = z;
    double rz = r.dot(z);
    for (int k = 0; k < kMaxCgIterations; ++k) {
      const Eigen::VectorXd Ap = A * p;
      const double alpha = rz / p.dot(Ap);
      x += alpha * p;
      r -= alpha * Ap;
      if (r.norm() <= target) return true;
      z = factor.solve(r);
      const double next = r.dot(z);
      p = z + (next / rz) * p;
      rz = next;
    }
    return false;
  }

  // The crack's extent, process zone and dissipated energy at the committed damage. The line's
  // edges (corner, mid, corner) are the cells: an edge with a damaged node is in the damaged
  // zone, which reaches its lower end; one with a damaged node that has not failed is in the
  // process zone.
  void describe_cohesive(InsertionStep& step) {
    const CohesiveRing& ring = *cohesive_;
    std::vector<double> damage(pairs_.size());
    double area = 0.0, failed = 0.0;
    for (std::size_t p = 0; p < pairs_.size(); ++p) {
      damage[p] = cohesive_damage(ring.law, ring.reached_m[p]);
      area += ring.area_m2[p];
      if (damage[p] >= 1.0) failed += ring.area_m2[p];
      step.fracture_energy_J +=
          ring.area_m2[p] * cohesive_dissipated_energy(ring.law, ring.reached_m[p]);
      if (damage[p] >= 1.0)
        step.cohesive_crack_m = std::max(step.cohesive_crack_m, ring.depth_m[p]);
    }
    const std::size_t nodes = ring.order.size();
    for (std::size_t k = 0; k + 1 < nodes; k += 2) {
      bool damaged = false, softening = false;
      for (std::size_t j = k; j <= std::min(k + 2, nodes - 1); ++j) {
        const double d = damage[ring.order[j]];
        damaged = damaged || d > 0.0;
        softening = softening || (d > 0.0 && d < 1.0);
      }
      const double lower = k + 2 < nodes ? ring.depth_m[ring.order[k + 2]] : ring.line_depth_m;
      if (damaged) step.cohesive_zone_m = std::max(step.cohesive_zone_m, lower);
      if (softening) ++step.process_zone_cells;
    }
    step.cohesive_rounds = rounds_;
    step.cohesive_failed_fraction = area > 0.0 ? failed / area : 0.0;
    rounds_ = 0;
  }

  static constexpr int kSubsteps = 4;
  const AxisymmetricMesh& mesh_;
  AxisymmetricNeedle needle_;
  std::vector<std::uint32_t> candidates_;
  std::size_t n_;
  double sub_step_;
  std::unique_ptr<CondensedSurface> surface_;
  ContactState state_;
  Eigen::VectorXd previous_, u_, f_;
  double depth_ = 0.0;
  FacePairs pairs_;
  bool close_pairs_ = false;
  std::vector<std::size_t> closed_;  // sorted
  std::optional<CohesiveRing> cohesive_;
  std::vector<double> trial_reached_;  // the last solve's largest openings, committed per step
  int rounds_ = 0;
};

// Linear layers, frictionless: active set on the condensed surface; each depth solved
// independently (elastic, no history), starting from the previous active set.
// The contact is the small-strain (Signorini) condition of the linear theory this stepper
// solves, as in Sneddon's solutions: the gap is vertical, between a node's deformed height and
// the needle's lower surface above its reference radius, and the contact force is vertical (no
// shear on the surface). A node held instead on the sloped face (gap and force along the face
// normal) can meet a face of slope cot(alpha) by moving out by u_r instead of down by
// cot(alpha) u_r; mixed with kinematics linearised about the flat reference surface, that
// outward slide of single nodes is nearly free, and a sharp cone came out far too soft and
// softer under refinement (10 deg, nu 0.3: 0.22 / 0.18 / 0.13 of Sneddon at fast / standard /
// fine; 60 deg, nu 0.45: 0.96).
// Each solve adds or releases nodes; a set that has not settled by then is cycling.
constexpr int kMaxActiveSetSolves = 200;

class FrictionlessStepper : public Stepper {
  FacePairs pairs_;

 public:
  // pairs: the ring crack's faces (cracked twin), measured only (their contact is not modelled
  // with frictionless needle contact).
  FrictionlessStepper(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                      const InsertionOptions& options, bool keep_field, FacePairs pairs = {})
      : pairs_(std::move(pairs)),
        mesh_(model.mesh()),
        needle_(needle),
        candidates_(reachable_surface_nodes(mesh_, needle, options.depth_m)),
        n_(model.dof_count()),
        depth_scale_(options.depth_m) {
    if (candidates_.empty()) throw InputError("frictionless contact: the needle reaches no node");
    surface_ =
        std::make_unique<CondensedSurface>(model, with_face_nodes(candidates_, pairs_), keep_field);
  }

  Eigen::VectorXd face_gaps(const FacePairs& pairs) const override {
    return surface_->gaps(u_, pairs);
  }

  InsertionStep advance_to(double depth) override {
    int solves = 0;
    bool changed = true;
    while (changed) {
      if (solves == kMaxActiveSetSolves)
        throw SolverError("frictionless contact: the contact set did not settle in " +
                          std::to_string(kMaxActiveSetSolves) + " solves at depth " +
                          std::to_string(depth * 1e6) + " um");
      changed = false;
      surface_->solve_frictionless(mesh_, needle_, depth, active_, u_, f_);
      ++solves;
      // Release the node pulled hardest (upward force on the needle), else add penetrating nodes.
      std::uint32_t worst = 0;
      double worst_pull = 0.0;
      for (std::uint32_t node : active_) {
        const double pull = f_[surface_->index_of(node) + 1];
        if (pull > worst_pull) worst = node, worst_pull = pull;
      }
      if (worst_pull > 1e-12 * std::max(1.0, f_.norm())) {
        active_.erase(worst);
        changed = true;
        continue;
      }
      for (std::uint32_t node : candidates_) {
        if (active_.count(node)) continue;
        const Eigen::Vector2d X = mesh_.nodes[node];
        const Eigen::Vector2d p = X + Eigen::Vector2d(0.0, u_[surface_->index_of(node) + 1]);
        if (gap(needle_, depth, p) < -1e-12 * depth_scale_) {
          active_.insert(node);
          changed = true;
        }
      }
    }
    double force = 0.0;
    ContactState state;
    for (std::uint32_t node : active_) {
      force -= f_[surface_->index_of(node) + 1];
      state.captured[node] = Capture{Eigen::Vector2d::Zero(), 0.0};
    }
    // Reference radii, as the contact condition: the linear theory's contact radius.
    const double area =
        contact_area(mesh_, needle_, state, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_)));
    return make_step(depth, force, area, 0.5 * u_.dot(f_), solves,
                     static_cast<int>(active_.size()));
  }

  Eigen::VectorXd displacement() const override {
    if (u_.size() == 0) return Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_));
    return surface_->full(u_);
  }

 private:
  const AxisymmetricMesh& mesh_;
  AxisymmetricNeedle needle_;
  std::vector<std::uint32_t> candidates_;
  std::size_t n_;
  double depth_scale_;
  std::unique_ptr<CondensedSurface> surface_;
  std::set<std::uint32_t> active_;
  Eigen::VectorXd u_, f_;
};

// pairs: a cracked twin's face pairs (contact per options.crack_face_contact where modelled).
std::unique_ptr<Stepper> make_stepper(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                                      const InsertionOptions& options, bool keep_field,
                                      const FacePairs& pairs = {}) {
  if (options.contact == ContactMode::Frictionless)
    return std::make_unique<FrictionlessStepper>(model, needle, options, keep_field, pairs);
  if (model.is_linear())
    return std::make_unique<LinearStepper>(model, needle, options, keep_field, pairs,
                                           options.crack_face_contact);
  return std::make_unique<NonlinearStepper>(model, needle, options, pairs,
                                            options.crack_face_contact);
}

}  // namespace

double cohesive_ring_radius(const AxisymmetricNeedle& needle) {
  const double r = needle.max_radius();
  if (!(r > 0.0)) throw InputError("cohesive ring crack: the needle has no radius");
  return r;
}

double ring_crack_radius(const AxisymmetricNeedle& needle, double depth_m) {
  const auto& H = needle.heights_m;
  const auto& R = needle.radii_m;
  if (R.empty()) throw InputError("ring crack: the needle has no profile");
  double r = R.back();
  for (std::size_t i = 1; i < H.size(); ++i)
    if (depth_m < H[i]) {
      const double t = std::clamp((depth_m - H[i - 1]) / (H[i] - H[i - 1]), 0.0, 1.0);
      r = R[i - 1] + t * (R[i] - R[i - 1]);
      break;
    }
  if (!(r > 0.0)) throw InputError("ring crack: the needle's section at that depth has no radius");
  return r;
}

InsertionResult insert_needle(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                              const InsertionOptions& options) {
  if (!(options.depth_m > 0.0)) throw InputError("insertion depth must be > 0 m");
  if (options.output_steps < 1) throw InputError("insertion needs at least one output step");
  if (!(options.stress_average_length_m >= 0.0))
    throw InputError("stress_average_length_m must be >= 0 m");
  if (!(options.crack_depth_m >= 0.0)) throw InputError("crack_depth_m must be >= 0 m");
  const bool frictionless = options.contact == ContactMode::Frictionless;
  if (frictionless && !model.is_linear())
    throw InputError(
        "axisymmetric solver: frictionless contact needs linear layers; use sticking, or --model "
        "3d");
  const auto start = std::chrono::steady_clock::now();
  const int before = model.factorization_count();
  const bool keep_field = options.stress_average_length_m > 0.0 || !options.vtu_directory.empty();
  // A cohesive ring crack replaces the intact model by the split one, its faces held by the law.
  std::unique_ptr<AxisymmetricModel> cohesive_model;
  AxisymmetricModel* run_model = &model;
  std::unique_ptr<Stepper> intact;
  if (options.cohesive_depth_m > 0.0) {
    const CohesiveLaw& law = options.cohesive;
    if (frictionless || !model.is_linear())
      throw InputError("cohesive ring crack: needs linear layers and sticking contact");
    if (options.crack_depth_m > 0.0)
      throw InputError("cohesive ring crack: not together with the energy criterion's crack");
    if (!(law.toughness_J_per_m2 > 0.0) || !(law.peak_opening_m > 0.0) ||
        !(law.failure_opening_m > law.peak_opening_m) || !std::isfinite(law.failure_opening_m))
      throw InputError("cohesive ring crack: the law needs G_c > 0 and 0 < delta_y < delta_0");
    const double radius = cohesive_ring_radius(needle);
    FacePairs pairs;
    cohesive_model = std::make_unique<AxisymmetricModel>(
        crack_axisymmetric_mesh(model.mesh(), radius, options.cohesive_depth_m, nullptr, &pairs),
        model.layer_materials());
    CohesiveRing ring =
        cohesive_ring(cohesive_model->mesh(), pairs, radius, options.cohesive_depth_m, law);
    intact = std::make_unique<LinearStepper>(*cohesive_model, needle, options, keep_field,
                                             std::move(pairs), false, std::move(ring));
    run_model = cohesive_model.get();
  } else {
    intact = make_stepper(model, needle, options, keep_field);
  }
  // Energy release rate: a ring-cracked twin advanced in lock-step with the intact model.
  std::unique_ptr<AxisymmetricModel> cracked_model;
  std::unique_ptr<Stepper> cracked;
  double crack_area = 0.0;
  FacePairs face_pairs;
  if (options.crack_depth_m > 0.0) {
    const double radius = ring_crack_radius(needle, options.depth_m);
    cracked_model = std::make_unique<AxisymmetricModel>(
        crack_axisymmetric_mesh(model.mesh(), radius, options.crack_depth_m, &crack_area,
                                &face_pairs),
        model.layer_materials());
    cracked = make_stepper(*cracked_model, needle, options, false, face_pairs);
  }
  std::vector<PvdEntry> collection;
  if (!options.vtu_directory.empty()) {
    create_output_folder(options.vtu_directory, "--vtu");
    clear_step_files(options.vtu_directory);
  }
  InsertionResult result;
  for (int k = 1; k <= options.output_steps; ++k) {
    const double depth = options.depth_m * k / options.output_steps;
    InsertionStep step = intact->advance_to(depth);
    if (cracked) {
      InsertionStep twin;
      try {
        twin = cracked->advance_to(depth);
      } catch (const OutOfMemoryError&) {
        throw;  // the twin's memory, not its crack faces
      } catch (const SolverError& e) {
        // Name the twin: its failure ends the run, and on nonlinear layers the held crack faces
        // are the likely cause (docs/model.md, "Crack faces in contact").
        throw CrackedTwinError(std::string("the energy criterion's cracked twin (ring crack ") +
                               format_depth(options.crack_depth_m) + " deep, faces " +
                               (options.crack_face_contact ? "in contact" : "free") +
                               ") failed: " + e.what());
      }
      step.crack_area_m2 = crack_area;
      step.energy_release_rate_J_per_m2 =
          (step.strain_energy_J - twin.strain_energy_J) / crack_area;
      const Eigen::VectorXd gaps = cracked->face_gaps(face_pairs);
      step.crack_face_overlap_m = gaps.size() > 0 ? std::max(0.0, -gaps.minCoeff()) : 0.0;
      step.crack_face_contacts = cracked->closed_pairs();
    }
    if (keep_field) {
      const Eigen::VectorXd u = intact->displacement();
      // The stress criterion's probe searches the top layer within the needle's outline at
      // this depth plus two averaging lengths (docs/model.md, "Criteria", stress).
      if (options.stress_average_length_m > 0.0)
        step.tip_stress_Pa = run_model->peak_averaged_max_principal_stress(
            u, outline_radius_up_to(needle, depth) + 2.0 * options.stress_average_length_m,
            options.stress_average_length_m, 0);
      if (!options.vtu_directory.empty()) {
        const std::filesystem::path dir(options.vtu_directory);
        const std::string file = "step_" + std::to_string(k) + ".vtu",
                          needle_file = "needles_" + std::to_string(k) + ".vtu";
        run_model->write_vtu((dir / file).string(), u, depth, options.vtu_comment);
        VtuFile profile = axi::needle_profile_vtu(needle, depth);
        profile.comment = options.vtu_comment;
        write_vtu((dir / needle_file).string(), profile);
        collection.push_back({depth, 0, file});
        collection.push_back({depth, 1, needle_file});
        write_pvd((dir / "steps.pvd").string(), collection, options.vtu_comment);
      }
    }
    require_finite(step);
    result.steps.push_back(step);
    if (options.on_step && !options.on_step(step)) break;
  }
  result.factorizations = model.is_linear() ? 1 : model.factorization_count() - before;
  if (cracked_model)
    result.factorizations += cracked_model->is_linear() ? 1 : cracked_model->factorization_count();
  result.nodes = run_model->mesh().nodes.size();
  result.elements = run_model->mesh().elements.size();
  result.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

namespace {

void require_override(bool ok, const std::string& field, const std::string& problem) {
  if (!ok) throw InputError("axisymmetric model: overrides." + field + " " + problem);
}

void check_overrides(const FidelityOverrides& o) {
  require_override(!o.order || *o.order == 2, "order",
                   "= " + std::to_string(o.order.value_or(2)) +
                       " is not available: the axisymmetric model has 6-node (order 2) "
                       "triangles only");
  require_override(!o.tip_size_m || (std::isfinite(*o.tip_size_m) && *o.tip_size_m > 0.0),
                   "tip_size_m", "must be > 0 m");
  require_override(!o.growth || (std::isfinite(*o.growth) && *o.growth >= 1.0), "growth",
                   "must be >= 1");
  require_override(!o.domain_scale || (std::isfinite(*o.domain_scale) && *o.domain_scale > 0.0),
                   "domain_scale", "must be > 0");
  require_override(!o.tolerance || (std::isfinite(*o.tolerance) && *o.tolerance > 0.0), "tolerance",
                   "must be > 0");
  require_override(!o.steps || *o.steps >= 1, "steps", "must be >= 1");
  require_override(!o.elements_through_top || *o.elements_through_top >= 1, "elements_through_top",
                   "must be >= 1");
}

// The needle's outer radius where it crosses the undeformed surface at tip depth depth_m: the
// widest section that can touch the tissue (the profile never narrows upward).
double footprint_radius(const AxisymmetricNeedle& needle, double depth_m) {
  const auto& H = needle.heights_m;
  const auto& R = needle.radii_m;
  for (std::size_t i = 1; i < H.size(); ++i)
    if (depth_m < H[i])
      return R[i - 1] + (depth_m - H[i - 1]) / (H[i] - H[i - 1]) * (R[i] - R[i - 1]);
  return needle.max_radius();
}

// The tip must stay above the clamped base, and the cylinder must be wider than the needle's
// footprint (its outer side is clamped): otherwise the model returns a force for an impossible
// geometry.
void check_geometry(const AxisymmetricProblem& problem) {
  double thickness = 0.0;
  for (const AxisymmetricLayer& l : problem.layers) thickness += l.thickness_m;
  if (problem.depth_m >= thickness)
    throw InputError("axisymmetric model: depth_m = " + format_depth(problem.depth_m) +
                     " reaches the rigid base: the layers are " + format_depth(thickness) +
                     " thick in total");
  const double radius = problem.radius_m * problem.overrides.domain_scale.value_or(1.0);
  const double footprint = footprint_radius(problem.needle, problem.depth_m);
  if (!(radius > footprint))
    throw InputError(std::string("axisymmetric model: radius_m") +
                     (problem.overrides.domain_scale ? " x overrides.domain_scale" : "") + " = " +
                     format_depth(radius) +
                     " (tissue cylinder) is not wider than the needle's section " +
                     format_depth(footprint) + " at depth_m = " + format_depth(problem.depth_m));
}

}  // namespace

// The cohesive ring's band: the mesh's own cells at most this many times the band's.
constexpr double kMaxBandRatio = 4.0;

AxisymmetricMeshOptions mesh_options_for(const AxisymmetricProblem& problem) {
  check_overrides(problem.overrides);
  const AxisymmetricNeedle& needle = problem.needle;
  // Contact radius scale: the needle's section where it crosses the undeformed surface.
  double a = footprint_radius(needle, problem.depth_m);
  a = std::max(a, 1e-3 * problem.depth_m);
  int per_radius = 8;
  double growth = 1.3;
  if (problem.fidelity == Fidelity::Fast) per_radius = 4, growth = 1.45;
  if (problem.fidelity == Fidelity::Fine) per_radius = 16, growth = 1.2;
  const FidelityOverrides& ov = problem.overrides;
  AxisymmetricMeshOptions o;
  o.radius_m = problem.radius_m * ov.domain_scale.value_or(1.0);
  o.h_m = std::min(ov.tip_size_m.value_or(a / per_radius), o.radius_m);
  o.fine_radius_m = 2.0 * a;
  // Total Lagrangian: the captured nodes sit on the reference surface, so the fine zone is the
  // reference neighbourhood of the footprint (a deep, slender needle does not need a fine
  // column down to its depth); below it the rows grow geometrically.
  o.fine_depth_m = std::min(problem.depth_m, a) + a;
  // A pointed needle under the stress criterion loads the top layer at one point until it
  // breaks: the layer's underside below it reads the averaged stress only with elements a
  // fraction of L (docs/model.md, "Axisymmetric mesh"), near the axis.
  const double length = problem.stress_average_length_m;
  const bool pointed =
      !needle.radii_m.empty() && needle.radii_m.front() <= 1e-9 * needle.max_radius();
  if (length > 0.0 && !ov.tip_size_m && pointed && !problem.layers.empty()) {
    const double per_length = problem.fidelity == Fidelity::Fast   ? 2.0
                              : problem.fidelity == Fidelity::Fine ? 8.0
                                                                   : 4.0;
    const double h_length = std::max(length / per_length, o.h_m / 8.0);
    if (h_length < o.h_m) {
      o.h_m = h_length;
      const double reach = problem.layers.front().thickness_m + 2.0 * length;
      o.fine_radius_m = std::min(o.fine_radius_m, std::max(reach, 8.0 * h_length));
    }
  }
  o.growth = ov.growth.value_or(growth);
  o.max_size_m = o.radius_m / 8.0;
  o.elements_through_top = ov.elements_through_top.value_or(0);
  o.radial_breaks_m = {needle.bore_radius_m, needle.max_radius()};
  // The flat face edge must be a node column; a sampled profile adds no further breaks.
  if (!needle.radii_m.empty()) o.radial_breaks_m.push_back(needle.radii_m.front());
  if (problem.crack_depth_m > 0.0) {
    const double r_c = ring_crack_radius(needle, problem.depth_m);
    o.radial_breaks_m.push_back(r_c);
    o.fine_radius_m = std::max(o.fine_radius_m, 1.5 * r_c);
    o.depth_breaks_m.push_back(problem.crack_depth_m);
  }
  // A cohesive ring crack: the fine cells run down its whole line, where the process zone may
  // travel (docs/model.md, "Cohesive ring crack").
  if (problem.cohesive_depth_m > 0.0) {
    const double r_c = cohesive_ring_radius(needle);
    o.radial_breaks_m.push_back(r_c);
    o.fine_radius_m = std::max(o.fine_radius_m, 1.5 * r_c);
    o.fine_depth_m = std::max(o.fine_depth_m, problem.cohesive_depth_m);
    o.depth_breaks_m.push_back(problem.cohesive_depth_m);
    // Finer cells along the ring only, graded to the mesh's own on either side; the mesh's own
    // at most kMaxBandRatio times the band's, so that the band's rows stay well shaped away
    // from it.
    const double cell = problem.cohesive_cell_m;
    if (cell > 0.0 && cell < o.h_m) {
      o.h_m = std::min(o.h_m, kMaxBandRatio * cell);
      o.band_radius_m = r_c;
      o.band_size_m = cell;
      o.band_depth_m = problem.cohesive_depth_m;
    }
  }
  return o;
}

InsertionResult simulate_axisymmetric(const AxisymmetricProblem& problem) {
  check_overrides(problem.overrides);
  const AxisymmetricNeedle& n = problem.needle;
  if (!n.heights_m.empty() && n.heights_m.size() == n.radii_m.size() && problem.depth_m > 0.0)
    check_geometry(problem);
  const auto start = std::chrono::steady_clock::now();
  AxisymmetricMesh mesh = make_axisymmetric_mesh(problem.layers, mesh_options_for(problem));
  std::vector<MaterialParameters> materials;
  for (const AxisymmetricLayer& l : problem.layers) materials.push_back(l.material);
  AxisymmetricModel model(std::move(mesh), materials);
  const double mesh_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (problem.on_mesh) {
    InsertionResult built;
    built.nodes = model.mesh().nodes.size();
    built.elements = model.mesh().elements.size();
    built.mesh_seconds = mesh_seconds;
    problem.on_mesh(built);
  }
  InsertionOptions options;
  options.depth_m = problem.depth_m;
  options.contact = problem.contact;
  options.output_steps = problem.output_steps > 0             ? problem.output_steps
                         : problem.fidelity == Fidelity::Fast ? 10
                         : problem.fidelity == Fidelity::Fine ? 40
                                                              : 20;
  if (problem.overrides.steps) options.output_steps = *problem.overrides.steps;
  if (problem.overrides.tolerance) options.newton.residual_tolerance = *problem.overrides.tolerance;
  options.stress_average_length_m = problem.stress_average_length_m;
  options.crack_depth_m = problem.crack_depth_m;
  options.crack_face_contact = problem.crack_face_contact;
  options.cohesive_depth_m = problem.cohesive_depth_m;
  options.cohesive = problem.cohesive;
  options.on_step = problem.on_step;
  options.vtu_directory = problem.vtu_directory;
  options.vtu_comment = problem.vtu_comment;
  InsertionResult result = insert_needle(model, problem.needle, options);
  result.mesh_seconds = mesh_seconds;
  return result;
}

}  // namespace mneedle::fe
