#include "mneedle/fe/indentation3d.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "fe/contact3d.h"
#include "fe/field_output3d.h"
#include "fe/inp_writer.h"
#include "fe/mirror_planes.h"
#include "fe/needle_shape.h"
#include "fe/vtu_writer.h"
#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/memory.h"
#include "mneedle/fe/crack.h"
#include "mneedle/fe/solid3d.h"
#include "mneedle/fe/sparse_solver.h"
#include "mneedle/fe/stress_probe.h"

namespace mneedle::fe {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct CapturedNode {
  int node;
  int needle;
  Eigen::Vector3d anchor;  // where it sits on the needle surface, needle frame
};

std::string micrometres(double metres) {
  std::ostringstream out;
  out.precision(4);
  out << metres * 1e6 << " um";
  return out.str();
}

constexpr int kMaxCaptureRounds = 60;
// Nonlinear sticking (solve_nonlinear_at): a node's entry inside a step is bisected to
// 2^-kEntryBisections of the step; nodes inside at the step's start are those entering within
// its first kCaptureStartFraction.
constexpr int kEntryBisections = 30;
constexpr double kCaptureStartFraction = 1e-6;

// The first capture of a nonlinear step enters before the step's end: the step ends at `depth`.
struct CaptureEvent {
  double depth;
};
// Captures in depth order (advance_linear): a node's entry depth is bisected to
// kCaptureBisection x the needle's radius; the nodes entering within kCaptureGroup x the radius
// after the first are captured with it (1.15 um for paper A's needles), at most a fiftieth of the
// surface's half spacing: a quarter took a node beside a flat that the flat's own hold keeps out,
// and the depth jumped with the bevel angle (docs/model.md, "Contact with the rigid needle
// (sticking)", has what the group length changed); never below kCaptureGroupBisections
// bisection tolerances, which the bisection cannot tell apart.
constexpr double kCaptureBisection = 1e-5;
constexpr double kCaptureGroup = 1e-2;
constexpr double kCaptureGroupPerSpacing = 0.02;
constexpr double kCaptureGroupBisections = 4.0;
constexpr int kMaxNewtonIterations = 40;
// Past a bifurcation (Impl::shift_tangent): Newton iterations per solve while the path settles
// onto the stable branch, and the fourfold shifts tried per factorisation.
constexpr int kMaxDescentIterations = 200;
constexpr int kMaxShifts = 20;
// Relative round-off of an assembled strain energy (a sum over elements): Impl::descend.
constexpr double kEnergyRoundOff = 1e-12;
constexpr int kMaxLineSearchHalvings = 6;
constexpr int kMaxStepCuts = 12;
// Frictionless contact: Uzawa updates of the multipliers until no nodal contact force changes by
// more than kUzawaTolerance of the summed contact force (ε = 100 E*/h: about 10 updates).
constexpr int kMaxUzawa = 50;
constexpr double kUzawaTolerance = 1e-4;
constexpr int kMaxContactNewton = 60;
// Largest size of the watched nodes' rows of the compliance columns (Indentation3d::watch_nodes):
// 256 MiB, a tenth of what the largest 3-D problems of docs/performance.md hold.
constexpr double kWatchedRowsBudget = 256.0 * 1024 * 1024;
// Nodes whose compliance columns one sparse solve computes (the path without the contact block):
// 64 nodes of a 450 000-dof mesh hold 0.7 GB of unit loads and as much of columns.
constexpr std::size_t kColumnChunkNodes = 64;
// Captured nodes whose watched rows the contact block path keeps (two half solves per node);
// past them the probe reads the field once per output depth (docs/performance.md, "The contact
// block").
constexpr std::size_t kWatchedBlockNodes = 16;
// Depths whose watched rows one back substitution reads (Indentation3d::watched_displacements),
// and the dense copies of the field it may hold for them: 256 MiB, as kWatchedRowsBudget.
constexpr Eigen::Index kBackSolveColumns = 8;
constexpr double kBackSolveBudget = 256.0 * 1024 * 1024;
// A first contact narrower than this fraction of the needle's radius, with no face in it, is a
// point (simulate_3d): a rounded bevel of tip_radius 1 um puts vertices about 0.35 um apart
// within 1 nm of its lowest one; a blunt bevel's flat (50 um) or a flat end spans tens of
// percent of the radius, and has faces there.
constexpr double kPointContactPerRadius = 0.05;
// Largest dense factor of the contact block (Impl::contact_block_fits): 256 MiB, 3 × 1900
// surface nodes.
constexpr double kContactBlockBudget = 256.0 * 1024 * 1024;
// Crack-face contact: active-set rounds per solve; a pair closes when its faces overlap by more
// than kCrackGapTolerance x the current depth (round-off of the condensed solve is ~1e-16 of it).
constexpr int kMaxCrackRounds = 100;   // plus four per pair
constexpr int kCrackBlockRounds = 20;  // rounds that open every pulling pair at once
// Nonlinear path (augmented Lagrangian): the penalty per pair, kFacePenalty x the pair's mean
// normal stiffness at u = 0, leaves about a thousandth of an overlap per multiplier update; a
// closed pair's gap must fall below Newton's tolerance x the depth.
constexpr double kNonlinearFacePenalty = 1e3;
constexpr double kCrackGapTolerance = 1e-10;
// A pair force below -kCrackForceFloor x the largest force of the solve pulls (round-off of a
// dense solve is ~1e-15 of it).
constexpr double kCrackForceFloor = 1e-12;

}  // namespace

struct Indentation3d::Impl {
  Impl(const TetMesh& m, std::vector<Needle3d> n, const Indentation3dOptions& o)
      : mesh(m), model(mesh), needles(std::move(n)), options(o) {}

  const TetMesh mesh;  // a copy: callers may pass a temporary
  SolidModel model;
  std::vector<Needle3d> needles;
  Indentation3dOptions options;
  std::vector<NeedleShape> shapes;
  std::vector<double> reach;         // horizontal reach radius per needle
  std::vector<int> candidates;       // top-surface nodes a needle may capture
  std::vector<int> candidate_index;  // node -> index in candidates or -1
  // Surface nodes that share a top face with a candidate without being one (nor fixed): their
  // compliance rows follow the candidates', so that the faces a needle holds, whose area is
  // reported, are known without a solve over the whole mesh.
  std::vector<int> ring;
  std::vector<int> ring_index;  // node -> index in ring or -1
  std::vector<CapturedNode> captured;
  std::vector<int> captured_by;  // node -> needle or -1
  // Compliance columns of nodes a capture search found inside a needle but not yet captured.
  struct CachedColumns {
    Eigen::Matrix<double, Eigen::Dynamic, 3> surface;  // surface rows (candidates, then ring)
    Eigen::Matrix<double, Eigen::Dynamic, 3> gaps;     // crack-face pairs' gaps
    Eigen::Matrix<double, Eigen::Dynamic, 3> watched;  // watched nodes' rows
  };
  // Nodes whose displacement is read every step, and their rows of the captured nodes' columns
  // (watch_nodes): u there is watched_compliance * multipliers on the linear sticking path.
  std::vector<int> watched;
  Eigen::MatrixXd watched_compliance;
  // Set when the kept rows would outgrow kWatchedRowsBudget bytes (many watched nodes times
  // many captured ones): from then on the watched displacement comes from the whole field.
  bool watched_overflow = false;
  std::unordered_map<int, CachedColumns> column_cache;
  // The smallest needle radius up to the final depth: the length scale of the capture search.
  double capture_radius = std::numeric_limits<double>::infinity();
  double surface_spacing = std::numeric_limits<double>::infinity();
  std::vector<char> fixed_dof;
  SparseSolver solver{3};  // x, y, z per node: ordered by node
  Eigen::SparseMatrix<double> stiffness;
  Timing3d timing;
  double depth = 0.0;
  int iterations = 0;
  bool linear_factorized = false;
  // Linear path: rows (candidate dofs) of K⁻¹ columns at captured dofs, and the multipliers.
  Eigen::MatrixXd compliance;
  Eigen::VectorXd multipliers;
  // Nonlinear path.
  Eigen::VectorXd u;
  double step = 0.0;
  Eigen::SparseMatrix<double> tangent;   // last factorised tangent before the Dirichlet rows
  std::vector<char> factor_constraints;  // prescribed dofs of the current factorisation
  // Past a bifurcation (shift_tangent): the factorisation held is of a shifted tangent; a step
  // has descended along one (from then on Newton may take kMaxDescentIterations); the last
  // shift that made the tangent positive definite.
  bool factor_shifted = false;
  bool bifurcated = false;
  double shift = 1e-6;
  // Frictionless path: quadrature-point contact; on linear layers the tissue is condensed onto
  // the contact-face nodes (rows) through K⁻¹ columns at the loaded ("involved") nodes.
  std::optional<FrictionlessContact> contact;
  std::vector<int> row_index;       // node -> row block in contact->nodes() or -1
  std::vector<int> involved;        // nodes with a compliance column block
  std::vector<int> involved_index;  // node -> column block or -1
  Eigen::VectorXd contact_load;     // force on the tissue at the involved nodes (linear path)
  std::vector<ContactPointState> contact_states;
  // Cracked twin: the run whose captures this one copies, and each node's node in its mesh.
  const Impl* leader = nullptr;
  std::vector<int> leader_node;
  // Crack faces in contact (linear sticking path): the node pairs; the gap of every pair under
  // a unit load at each captured dof (columns follow `compliance`); K⁻¹ columns of the pairs
  // that have been in contact (their surface rows and the gap of every pair); the pairs in
  // contact now and their compressive forces (N).
  std::vector<CrackFacePair> pairs;
  bool pair_contact = false;
  Eigen::MatrixXd capture_gaps;
  std::vector<int> pair_column;  // pair -> column of pair_surface / pair_gaps, or -1
  Eigen::MatrixXd pair_surface;
  Eigen::MatrixXd pair_gaps;
  std::vector<int> active_pairs;
  Eigen::VectorXd pair_forces;

  bool crack_contact() const {
    return pair_contact && !pairs.empty() && model.is_linear() && !frictionless();
  }
  // Crack faces held on the nonlinear sticking path: an augmented Lagrangian inside Newton
  // (docs/model.md, "Crack faces in contact"), as in the axisymmetric model. Per pair: held or
  // not, its multiplier (N, < 0 pressing), its penalty (N/m); within one depth, the pairs opened
  // for pulling and those latched closed after overlapping again.
  std::vector<char> pair_closed;
  Eigen::VectorXd pair_multiplier;
  Eigen::VectorXd pair_penalty;
  std::vector<char> pair_pulled_open, pair_latched;
  bool nonlinear_pairs() const {
    return pair_contact && !pairs.empty() && !model.is_linear() && !frictionless();
  }

  // The held pairs' term of the potential, sum of lambda g + k g^2 / 2 (J), its gradient added to
  // `force` and its Hessian to `tangent` (either may be null).
  double add_pair_terms(const Eigen::VectorXd& at, Eigen::SparseMatrix<double>* tangent,
                        Eigen::VectorXd* force) const {
    if (!nonlinear_pairs()) return 0.0;
    double total = 0.0;
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      if (!pair_closed[p]) continue;
      const auto i = static_cast<Eigen::Index>(p);
      const CrackFacePair& pair = pairs[p];
      const double g = gap_of(p, at);
      const double t = pair_multiplier[i] + pair_penalty[i] * g;
      total += pair_multiplier[i] * g + 0.5 * pair_penalty[i] * g * g;
      if (force) {
        force->segment<3>(3 * pair.positive_node) += t * pair.normal;
        force->segment<3>(3 * pair.negative_node) -= t * pair.normal;
      }
      if (tangent) {
        const Eigen::Matrix3d block = pair_penalty[i] * pair.normal * pair.normal.transpose();
        model.add_block(pair.positive_node, pair.positive_node, block, tangent);
        model.add_block(pair.negative_node, pair.negative_node, block, tangent);
        model.add_block(std::max(pair.positive_node, pair.negative_node),
                        std::min(pair.positive_node, pair.negative_node), -block, tangent);
      }
    }
    return total;
  }

  // Penalties from the tangent at u = 0 (`stiffness` holds the coupled pattern).
  void set_pair_penalties() {
    Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.dof_count());
    Eigen::VectorXd force;
    model.assemble(zero, &stiffness, &force);
    const auto normal_stiffness = [&](int node, const Eigen::Vector3d& n) {
      double sum = 0.0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          sum +=
              n[a] * n[b] * stiffness.coeff(3 * node + std::max(a, b), 3 * node + std::min(a, b));
      return sum;
    };
    pair_penalty.resize(static_cast<Eigen::Index>(pairs.size()));
    for (std::size_t p = 0; p < pairs.size(); ++p)
      pair_penalty[static_cast<Eigen::Index>(p)] =
          kNonlinearFacePenalty * 0.5 *
          (normal_stiffness(pairs[p].positive_node, pairs[p].normal) +
           normal_stiffness(pairs[p].negative_node, pairs[p].normal));
  }

  enum class PairUpdate { Settled, Multipliers, Set };
  // One update of the held pairs after a converged solve at `at_depth` (as the axisymmetric
  // stepper's): closed pairs that pull open, all at once for the first kCrackBlockRounds rounds
  // and then the one pulled hardest; when none pulls, each closed pair's multiplier takes its
  // force (Uzawa) and open pairs that overlap close. Set: a pair opened or closed; Multipliers:
  // only multipliers moved, because a closed pair still overlaps or gapes by more than the
  // tolerance; Settled: neither.
  PairUpdate update_pairs(double at_depth, int round) {
    const double tolerance = options.tolerance * std::max(at_depth, 1e-12);
    const auto count = static_cast<Eigen::Index>(pairs.size());
    Eigen::VectorXd t = Eigen::VectorXd::Zero(count), gaps(count);
    for (Eigen::Index i = 0; i < count; ++i) {
      gaps[i] = gap_of(static_cast<std::size_t>(i), u);
      if (pair_closed[static_cast<std::size_t>(i)])
        t[i] = pair_multiplier[i] + pair_penalty[i] * gaps[i];
    }
    const double floor = options.tolerance * t.lpNorm<Eigen::Infinity>();
    Eigen::Index worst = -1;
    for (Eigen::Index i = 0; i < count; ++i) {
      const auto p = static_cast<std::size_t>(i);
      if (pair_closed[p] && !pair_latched[p] && t[i] > floor && (worst < 0 || t[i] > t[worst]))
        worst = i;
    }
    if (worst >= 0) {
      for (Eigen::Index i = 0; i < count; ++i) {
        const auto p = static_cast<std::size_t>(i);
        if (pair_closed[p] && !pair_latched[p] && t[i] > floor &&
            (round < kCrackBlockRounds || i == worst)) {
          pair_closed[p] = 0;
          pair_multiplier[i] = 0.0;
          pair_pulled_open[p] = 1;
        }
      }
      return PairUpdate::Set;
    }
    bool moved = false, changed = false;
    for (Eigen::Index i = 0; i < count; ++i) {
      const auto p = static_cast<std::size_t>(i);
      if (pair_closed[p]) {
        pair_multiplier[i] = t[i];
        moved = moved || std::abs(gaps[i]) > tolerance;
      } else if (gaps[i] < -tolerance) {
        pair_closed[p] = 1;
        pair_multiplier[i] = 0.0;
        // Pulls when closed, overlaps when open: it stays closed, pulling a little.
        if (pair_pulled_open[p]) pair_latched[p] = 1;
        changed = true;
      }
    }
    return changed ? PairUpdate::Set : moved ? PairUpdate::Multipliers : PairUpdate::Settled;
  }
  // Gap of pair p in the displacement field `field` (full length, or any vector indexed by dof).
  double gap_of(std::size_t p, Eigen::Ref<const Eigen::VectorXd> field) const {
    const CrackFacePair& pair = pairs[p];
    return pair.normal.dot(field.segment<3>(3 * pair.positive_node) -
                           field.segment<3>(3 * pair.negative_node));
  }
  // Unit opening load of pair p: +normal on the positive node, -normal on the negative one
  // (prescribed dofs left out).
  void put_pair_load(std::size_t p, double scale, Eigen::Ref<Eigen::VectorXd> load) const {
    const CrackFacePair& pair = pairs[p];
    for (int j = 0; j < 3; ++j) {
      const auto plus = static_cast<std::size_t>(3 * pair.positive_node + j);
      const auto minus = static_cast<std::size_t>(3 * pair.negative_node + j);
      if (!fixed_dof[plus]) load(static_cast<Eigen::Index>(plus)) += scale * pair.normal(j);
      if (!fixed_dof[minus]) load(static_cast<Eigen::Index>(minus)) -= scale * pair.normal(j);
    }
  }
  // Both nodes held by a needle: their gap is prescribed (zero), the pair has nothing to add.
  bool pair_held(std::size_t p) const {
    return captured_by[static_cast<std::size_t>(pairs[p].positive_node)] >= 0 &&
           captured_by[static_cast<std::size_t>(pairs[p].negative_node)] >= 0;
  }

  Eigen::Vector3d tip(int needle, double at_depth) const {
    const auto& n = needles[static_cast<std::size_t>(needle)];
    return {n.x, n.y, -at_depth};
  }
  Eigen::Vector3d prescribed(const CapturedNode& c, double at_depth) const {
    return c.anchor + tip(c.needle, at_depth) - mesh.nodes[static_cast<std::size_t>(c.node)];
  }
  Eigen::VectorXd prescribed_vector(double at_depth) const {
    Eigen::VectorXd values(3 * static_cast<Eigen::Index>(captured.size()));
    for (std::size_t i = 0; i < captured.size(); ++i)
      values.segment<3>(3 * static_cast<Eigen::Index>(i)) = prescribed(captured[i], at_depth);
    return values;
  }

  void select_candidates(double max_depth) {
    candidate_index.assign(mesh.nodes.size(), -1);
    for (std::size_t n = 0; n < needles.size(); ++n) {
      shapes.emplace_back(needles[n].mesh);
      // Margin: surface nodes move sideways a little before the needle reaches them.
      reach.push_back(1.1 * shapes.back().max_radius_up_to(max_depth) + 1e-9);
      capture_radius = std::min(capture_radius, shapes.back().max_radius_up_to(max_depth));
    }
    for (const auto& face : mesh.top_faces)
      for (int node : face) {
        if (node < 0 || candidate_index[static_cast<std::size_t>(node)] >= 0) continue;
        if (mesh.fixed[static_cast<std::size_t>(node)]) continue;
        const Eigen::Vector3d& p = mesh.nodes[static_cast<std::size_t>(node)];
        for (std::size_t n = 0; n < needles.size(); ++n)
          if (std::hypot(p.x() - needles[n].x, p.y() - needles[n].y) <= reach[n]) {
            candidate_index[static_cast<std::size_t>(node)] = static_cast<int>(candidates.size());
            candidates.push_back(node);
            break;
          }
      }
    ring_index.assign(mesh.nodes.size(), -1);
    for (const auto& face : mesh.top_faces) {
      if (std::none_of(face.begin(), face.end(), [&](int node) {
            return node >= 0 && candidate_index[static_cast<std::size_t>(node)] >= 0;
          }))
        continue;
      for (int node : face) {
        const auto i = static_cast<std::size_t>(node);
        if (node < 0 || candidate_index[i] >= 0 || ring_index[i] >= 0 || mesh.fixed[i]) continue;
        ring_index[i] = static_cast<int>(ring.size());
        ring.push_back(node);
      }
    }
    captured_by.assign(mesh.nodes.size(), -1);
    // Half the shortest top-face edge with a candidate on it (a TET10's corner-to-midside
    // distance): the capture group's bound on a finely meshed surface.
    for (const auto& face : mesh.top_faces)
      for (std::size_t a = 0; a < 3; ++a) {
        const auto p = static_cast<std::size_t>(face[a]);
        const auto q = static_cast<std::size_t>(face[(a + 1) % 3]);
        if (candidate_index[p] < 0 && candidate_index[q] < 0) continue;
        surface_spacing = std::min(surface_spacing, 0.5 * (mesh.nodes[p] - mesh.nodes[q]).norm());
      }
  }

  // Nodes entering a needle within this depth of the first entry of an event are captured with
  // it: kCaptureGroup of the needle's radius, but no more than kCaptureGroupPerSpacing of the
  // surface's finest spacing, so that a group never spans the nodes of a resolved contact patch.
  double group_length() const {
    // Never below a few bisection tolerances: entries closer than that are not told apart.
    return std::max(
        std::min(kCaptureGroup * capture_radius, kCaptureGroupPerSpacing * surface_spacing),
        kCaptureGroupBisections * kCaptureBisection * capture_radius);
  }

  // Where a node that entered needle n is held: on the face that swept over it, or where it
  // entered a wall sideways (NeedleShape::sticking_anchor).
  Eigen::Vector3d anchor_of(int n, const Eigen::Vector3d& local,
                            const Eigen::Vector3d& entered) const {
    return shapes[static_cast<std::size_t>(n)].sticking_anchor(local, entered, group_length());
  }

  // Rows of the sticking path's compliance: the candidates, then the ring.
  Eigen::Index surface_rows() const {
    return 3 * static_cast<Eigen::Index>(candidates.size() + ring.size());
  }

  // Candidates whose current position lies inside a needle at `at_depth` are captured onto the
  // needle face right below them (the face that swept over them).
  std::vector<CapturedNode> find_new_captures(double at_depth, const auto& displacement_of) const {
    if (leader) return captures_from_leader();
    std::vector<CapturedNode> found;
    for (int node : candidates) {
      if (captured_by[static_cast<std::size_t>(node)] >= 0) continue;
      const Eigen::Vector3d x = mesh.nodes[static_cast<std::size_t>(node)] + displacement_of(node);
      for (std::size_t n = 0; n < needles.size(); ++n) {
        const Eigen::Vector3d local = x - tip(static_cast<int>(n), at_depth);
        if (local.head<2>().norm() > reach[n] || !shapes[n].touches(local)) continue;
        // Where it entered is not known here: the face below (the nonlinear path re-anchors
        // its captures with their entry points, the linear path's capture event likewise).
        found.push_back({node, static_cast<int>(n), shapes[n].lower_surface_below(local)});
        break;
      }
    }
    return found;
  }

  // The leader's captures this run does not hold yet, on every copy of each captured node.
  std::vector<CapturedNode> captures_from_leader() const {
    std::vector<CapturedNode> found;
    for (int node : candidates) {
      if (captured_by[static_cast<std::size_t>(node)] >= 0) continue;
      const int in_leader = leader_node[static_cast<std::size_t>(node)];
      const int needle = leader->captured_by[static_cast<std::size_t>(in_leader)];
      if (needle < 0) continue;
      for (const CapturedNode& c : leader->captured)
        if (c.node == in_leader) found.push_back({node, needle, c.anchor});
    }
    return found;
  }

  void add_captures(const std::vector<CapturedNode>& found) {
    for (const auto& c : found) {
      captured.push_back(c);
      captured_by[static_cast<std::size_t>(c.node)] = c.needle;
    }
  }

  // ---- linear path --------------------------------------------------------------------------
  void factorize_linear() {
    auto start = Clock::now();
    stiffness = model.empty_stiffness();
    model.assemble(Eigen::VectorXd::Zero(model.dof_count()), &stiffness, nullptr);
    apply_dirichlet(&stiffness, fixed_dof);
    timing.assembly_s += seconds_since(start);
    start = Clock::now();
    if (contact_block_fits()) {
      std::vector<int> surface = candidates;
      surface.insert(surface.end(), ring.begin(), ring.end());
      solver.set_trailing_nodes(std::move(surface));
    }
    solver.analyze(stiffness);
    solver.factorize(stiffness);
    ++timing.factorizations;
    timing.factorization_s += seconds_since(start);
    if (!solver.ok()) throw SolverError("3-D solve: singular stiffness at depth 0 um");
    linear_factorized = true;
  }

  // The linear sticking path holds every captured node's compliance densely: over a flat end
  // under a fine contact zone that is thousands of nodes and tens of GB. What would not fit is
  // refused before it is allocated (docs/performance.md, "Memory").
  // Held until the block is allocated, so that other threads (screen --jobs N) count it.
  [[nodiscard]] static MemoryReservation reserve_contact_memory(double bytes, std::size_t nodes) {
    return reserve_memory(bytes,
                          "3-D contact: the dense compliance of " + std::to_string(nodes) +
                              " surface nodes held by the needle",
                          "a coarser contact_zone or fidelity needs less");
  }

  // The sticking path's surface rows (candidates, then the ring) eliminated last, so that their
  // compliance is read from the dense factor of the Schur complement onto them
  // (docs/performance.md, "The contact block"). Not with crack faces in contact (their gaps need
  // the whole columns) nor with frictionless contact (other rows), and only while the dense
  // block stays small.
  bool contact_block_fits() const {
    const auto dofs = static_cast<double>(surface_rows());
    return options.contact_block && !frictionless() && !crack_contact() && dofs > 0.0 &&
           8.0 * dofs * dofs <= kContactBlockBudget;
  }

  // K⁻¹ at unit loads on the nodes' three dofs, kept at the surface rows (and the pairs' gaps):
  // one multi-right-hand-side solve for every node not cached yet. K does not change on the
  // linear path, so a node's columns stay valid until it is captured, however many capture
  // events later (reading the factor once for many columns is what makes the solve cheap).
  void cache_compliance_columns(const std::vector<CapturedNode>& nodes) {
    std::vector<int> missing;
    for (const CapturedNode& c : nodes)
      if (!column_cache.count(c.node) &&
          std::find(missing.begin(), missing.end(), c.node) == missing.end())
        missing.push_back(c.node);
    if (missing.empty()) return;
    MemoryReservation reserved;
    {
      // What the new columns keep, and what computing them holds meanwhile: the contact block's
      // columns and (first nodes only) their fields, or one chunk's unit loads, its columns and
      // CHOLMOD's copy of them.
      const double columns = 3.0 * static_cast<double>(missing.size());
      const double kept_rows =
          static_cast<double>(surface_rows()) +
          (watched_overflow ? 0.0 : 3.0 * static_cast<double>(watched.size())) +
          (crack_contact() ? static_cast<double>(pairs.size()) : 0.0);
      const double dofs = static_cast<double>(model.dof_count());
      const double meanwhile =
          solver.has_trailing_block()
              ? static_cast<double>(surface_rows()) * columns +
                    (watched.empty() || watched_overflow ||
                             column_cache.size() + captured.size() + missing.size() >
                                 kWatchedBlockNodes
                         ? 0.0
                         : dofs * columns)
              : 3.0 * dofs * 3.0 * static_cast<double>(std::min(kColumnChunkNodes, missing.size()));
      reserved = reserve_contact_memory(8.0 * (kept_rows * columns + meanwhile),
                                        column_cache.size() + missing.size());
    }
    if (solver.has_trailing_block()) {
      std::vector<Eigen::Index> at;
      for (int node : missing)
        for (int j = 0; j < 3; ++j)
          at.push_back(
              3 * static_cast<Eigen::Index>(candidate_index[static_cast<std::size_t>(node)]) + j);
      const Eigen::MatrixXd columns = solver.trailing_columns(at);
      // The watched rows take half solves (solve_trailing_loads) for the first
      // kWatchedBlockNodes nodes; past them each output depth reads the field once instead.
      if (!watched.empty() && !watched_overflow &&
          column_cache.size() + captured.size() + missing.size() > kWatchedBlockNodes)
        watched_overflow = true;
      Eigen::MatrixXd field;
      if (!watched.empty() && !watched_overflow) {
        Eigen::MatrixXd unit =
            Eigen::MatrixXd::Zero(surface_rows(), static_cast<Eigen::Index>(at.size()));
        for (std::size_t j = 0; j < at.size(); ++j) unit(at[j], static_cast<Eigen::Index>(j)) = 1.0;
        field = solver.solve_trailing_loads(unit);
      }
      for (std::size_t i = 0; i < missing.size(); ++i) {
        CachedColumns& cached = column_cache[missing[i]];
        cached.surface = columns.middleCols<3>(3 * static_cast<Eigen::Index>(i));
        if (field.size() == 0) continue;
        cached.watched.resize(3 * static_cast<Eigen::Index>(watched.size()), 3);
        for (std::size_t w = 0; w < watched.size(); ++w)
          cached.watched.middleRows<3>(3 * static_cast<Eigen::Index>(w)) =
              field.block<3, 3>(3 * watched[w], 3 * static_cast<Eigen::Index>(i));
      }
      return;
    }
    // In chunks of kColumnChunkNodes: the unit loads and their columns are dofs x 3 per node
    // (a flat end under a fine zone finds hundreds of nodes at once, tens of GB in one block).
    for (std::size_t first = 0; first < missing.size(); first += kColumnChunkNodes) {
      const std::size_t count = std::min(kColumnChunkNodes, missing.size() - first);
      Eigen::MatrixXd unit =
          Eigen::MatrixXd::Zero(model.dof_count(), 3 * static_cast<Eigen::Index>(count));
      for (std::size_t i = 0; i < count; ++i)
        for (int j = 0; j < 3; ++j)
          unit(3 * missing[first + i] + j, 3 * static_cast<Eigen::Index>(i) + j) = 1.0;
      const Eigen::MatrixXd columns = solver.solve_many(unit);
      unit.resize(0, 0);
      for (std::size_t i = 0; i < count; ++i) {
        CachedColumns& cached = column_cache[missing[first + i]];
        const auto at = 3 * static_cast<Eigen::Index>(i);
        cached.watched.resize(watched_overflow ? 0 : 3 * static_cast<Eigen::Index>(watched.size()),
                              3);
        for (std::size_t w = 0; w < watched.size() && !watched_overflow; ++w)
          cached.watched.middleRows<3>(3 * static_cast<Eigen::Index>(w)) =
              columns.block<3, 3>(3 * watched[w], at);
        cached.surface.resize(surface_rows(), 3);
        for (std::size_t c = 0; c < candidates.size() + ring.size(); ++c) {
          const int node = c < candidates.size() ? candidates[c] : ring[c - candidates.size()];
          cached.surface.middleRows<3>(3 * static_cast<Eigen::Index>(c)) =
              columns.block<3, 3>(3 * node, at);
        }
        if (!crack_contact()) continue;
        cached.gaps.resize(static_cast<Eigen::Index>(pairs.size()), 3);
        for (std::size_t p = 0; p < pairs.size(); ++p)
          for (int j = 0; j < 3; ++j)
            cached.gaps(static_cast<Eigen::Index>(p), j) = gap_of(p, columns.col(at + j));
      }
    }
  }

  void append_compliance_columns(const std::vector<CapturedNode>& found) {
    cache_compliance_columns(found);
    const Eigen::Index old_columns = compliance.cols();
    const auto added = 3 * static_cast<Eigen::Index>(found.size());
    MemoryReservation reserved;
    {
      // The grown compliance (copied while the old one is still held), the watched rows, and
      // the next condensed solve's dense matrix with its Cholesky factor.
      const auto columns = static_cast<double>(old_columns + added);
      const double coupling = columns + static_cast<double>(active_pairs.size());
      const double watched_rows =
          watched_overflow ? 0.0 : 3.0 * static_cast<double>(watched.size());
      reserved = reserve_contact_memory(
          8.0 * ((static_cast<double>(surface_rows()) + watched_rows) * columns +
                 2.0 * coupling * coupling),
          captured.size() + found.size());
    }
    compliance.conservativeResize(surface_rows(), old_columns + added);
    const double watched_bytes =
        8.0 * 3.0 * static_cast<double>(watched.size()) * static_cast<double>(old_columns + added);
    if (watched_bytes > kWatchedRowsBudget) watched_overflow = true;
    if (watched_overflow)
      watched_compliance.resize(0, 0);
    else
      watched_compliance.conservativeResize(3 * static_cast<Eigen::Index>(watched.size()),
                                            old_columns + added);
    if (crack_contact())
      capture_gaps.conservativeResize(static_cast<Eigen::Index>(pairs.size()), old_columns + added);
    for (std::size_t i = 0; i < found.size(); ++i) {
      const auto it = column_cache.find(found[i].node);
      assert(it != column_cache.end() && "a node captured twice in one call");
      const Eigen::Index at = old_columns + 3 * static_cast<Eigen::Index>(i);
      compliance.middleCols<3>(at) = it->second.surface;
      if (!watched_overflow) watched_compliance.middleCols<3>(at) = it->second.watched;
      if (crack_contact()) capture_gaps.middleCols<3>(at) = it->second.gaps;
      column_cache.erase(it);
    }
  }

  // K⁻¹ columns of the opening loads of pairs that have none yet.
  void add_pair_columns(const std::vector<int>& new_pairs) {
    if (new_pairs.empty()) return;
    const auto k = static_cast<Eigen::Index>(new_pairs.size());
    Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(model.dof_count(), k);
    for (Eigen::Index i = 0; i < k; ++i)
      put_pair_load(static_cast<std::size_t>(new_pairs[static_cast<std::size_t>(i)]), 1.0,
                    unit.col(i));
    const Eigen::MatrixXd columns = solver.solve_many(unit);
    const Eigen::Index old_columns = pair_surface.cols();
    pair_surface.conservativeResize(surface_rows(), old_columns + k);
    for (std::size_t c = 0; c < candidates.size() + ring.size(); ++c) {
      const int node = c < candidates.size() ? candidates[c] : ring[c - candidates.size()];
      for (int j = 0; j < 3; ++j)
        pair_surface.block(3 * static_cast<Eigen::Index>(c) + j, old_columns, 1, k) =
            columns.row(3 * node + j);
    }
    pair_gaps.conservativeResize(static_cast<Eigen::Index>(pairs.size()), old_columns + k);
    for (std::size_t p = 0; p < pairs.size(); ++p)
      for (Eigen::Index i = 0; i < k; ++i)
        pair_gaps(static_cast<Eigen::Index>(p), old_columns + i) = gap_of(p, columns.col(i));
    for (Eigen::Index i = 0; i < k; ++i)
      pair_column[static_cast<std::size_t>(new_pairs[static_cast<std::size_t>(i)])] =
          static_cast<int>(old_columns + i);
  }

  // Gap of every pair under the current captured loads and pair forces.
  Eigen::VectorXd pair_gaps_now() const {
    Eigen::VectorXd gaps = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs.size()));
    if (!captured.empty()) gaps += capture_gaps * multipliers;
    for (std::size_t a = 0; a < active_pairs.size(); ++a)
      gaps += pair_gaps.col(pair_column[static_cast<std::size_t>(active_pairs[a])]) *
              pair_forces(static_cast<Eigen::Index>(a));
    return gaps;
  }

  Eigen::VectorXd candidate_displacement() const {
    Eigen::VectorXd us = Eigen::VectorXd::Zero(surface_rows());
    if (!captured.empty()) us += compliance * multipliers;
    for (std::size_t a = 0; a < active_pairs.size(); ++a)
      us += pair_surface.col(pair_column[static_cast<std::size_t>(active_pairs[a])]) *
            pair_forces(static_cast<Eigen::Index>(a));
    return us;
  }

  // The captured nodes' forces for their prescribed displacements, with the pairs in
  // `active_pairs` closed (gap zero): one symmetric positive definite system
  // [C_cc C_ca; C_ac C_aa] [f; λ] = [u_prescribed; 0] on the condensed compliance.
  void solve_with_active_pairs(double at_depth) {
    const Eigen::Index m = 3 * static_cast<Eigen::Index>(captured.size());
    const auto k = static_cast<Eigen::Index>(active_pairs.size());
    Eigen::MatrixXd coupling(m + k, m + k);
    for (std::size_t i = 0; i < captured.size(); ++i)
      coupling.block(3 * static_cast<Eigen::Index>(i), 0, 3, m) =
          compliance.middleRows(3 * candidate_index[static_cast<std::size_t>(captured[i].node)], 3);
    for (Eigen::Index a = 0; a < k; ++a) {
      const auto p = static_cast<std::size_t>(active_pairs[static_cast<std::size_t>(a)]);
      if (m > 0) {
        coupling.block(m + a, 0, 1, m) = capture_gaps.row(static_cast<Eigen::Index>(p));
        coupling.block(0, m + a, m, 1) = capture_gaps.row(static_cast<Eigen::Index>(p)).transpose();
      }
      for (Eigen::Index b = 0; b < k; ++b)
        coupling(m + a, m + b) = pair_gaps(
            static_cast<Eigen::Index>(p),
            pair_column[static_cast<std::size_t>(active_pairs[static_cast<std::size_t>(b)])]);
    }
    // LLT reads the lower triangle only: the captured block as before (runs without a crack
    // are unchanged to the bit), the pairs' rows from capture_gaps and pair_gaps.
    Eigen::LLT<Eigen::MatrixXd> llt(coupling);
    if (llt.info() != Eigen::Success)
      throw SolverError("3-D solve: contact compliance not positive definite at depth " +
                        micrometres(at_depth));
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + k);
    rhs.head(m) = prescribed_vector(at_depth);
    const Eigen::VectorXd x = llt.solve(rhs);
    multipliers = x.head(m);
    pair_forces = x.tail(k);
  }

  void solve_linear_contact(double at_depth) {
    if (!crack_contact()) {
      if (captured.empty()) {
        multipliers.resize(0);
        return;
      }
      solve_with_active_pairs(at_depth);
      return;
    }
    // Active set (docs/model.md, "Crack faces in contact"): pairs in contact that pull (λ < 0)
    // open, all at once for the first kCrackBlockRounds rounds and then the one pulled hardest
    // per round (which cannot cycle the way block exchanges can); when none pulls, every open
    // pair whose faces overlap closes; repeat until nothing changes. The round limit grows with
    // the pairs: a shallow step can close most of a fine mesh's crack at once and open it again
    // pair by pair.
    const double tolerance = kCrackGapTolerance * std::max(at_depth, 1e-12);
    const int rounds = kMaxCrackRounds + 4 * static_cast<int>(pairs.size());
    for (int round = 0; round < rounds; ++round) {
      std::erase_if(active_pairs, [&](int p) { return pair_held(static_cast<std::size_t>(p)); });
      pair_forces.resize(static_cast<Eigen::Index>(active_pairs.size()));
      solve_with_active_pairs(at_depth);
      const double floor = kCrackForceFloor * std::max(multipliers.lpNorm<Eigen::Infinity>(),
                                                       pair_forces.lpNorm<Eigen::Infinity>());
      if (pair_forces.size() > 0 && pair_forces.minCoeff() < -floor) {
        if (round < kCrackBlockRounds) {
          std::vector<int> kept;
          for (std::size_t a = 0; a < active_pairs.size(); ++a)
            if (pair_forces(static_cast<Eigen::Index>(a)) >= -floor)
              kept.push_back(active_pairs[a]);
          active_pairs = std::move(kept);
        } else {
          Eigen::Index worst = 0;
          pair_forces.minCoeff(&worst);
          active_pairs.erase(active_pairs.begin() + worst);
        }
        continue;
      }
      const Eigen::VectorXd gaps = pair_gaps_now();
      std::vector<char> in_contact(pairs.size(), 0);
      for (int p : active_pairs) in_contact[static_cast<std::size_t>(p)] = 1;
      std::vector<int> missing;
      bool closed = false;
      for (std::size_t p = 0; p < pairs.size(); ++p) {
        if (in_contact[p] || pair_held(p) || !(gaps(static_cast<Eigen::Index>(p)) < -tolerance))
          continue;
        active_pairs.push_back(static_cast<int>(p));
        if (pair_column[p] < 0) missing.push_back(static_cast<int>(p));
        closed = true;
      }
      if (!closed) return;
      add_pair_columns(missing);
      std::sort(active_pairs.begin(), active_pairs.end());
    }
    active_pairs.clear();  // keep the state consistent (pair_forces matches active_pairs)
    pair_forces.resize(0);
    throw SolverError("3-D solve: crack-face contact did not settle at depth " +
                      micrometres(at_depth));
  }

  int advance_linear(double at_depth) {
    if (!linear_factorized) factorize_linear();
    // A cracked twin copies its leader's captures; with crack faces in contact the active set
    // may change inside a step, so the solution is only piecewise affine in depth: both keep
    // the capture rounds at the step's end.
    if (leader || crack_contact()) return capture_at_step_end(at_depth);
    const auto start = Clock::now();
    // Sticking contact holds a node from the depth where the needle reaches it, so the captured
    // set must grow in that order, not at the ends of output steps: taken at a step's end, every
    // node found inside in a solve that did not hold the ones reached before it is held, and in
    // skin the force fell with the step length (docs/model.md, "Contact with the rigid needle
    // (sticking)"). With the set fixed the condensed solution is affine in depth, so between two
    // depths every node's path is a segment: the first entry on it is found by bisection, the
    // nodes entering within kCaptureGroup of it are captured there, and the rest of the step is
    // solved again.
    double from = depth;
    Eigen::VectorXd us_from = candidate_displacement();
    int solves = 0;
    const auto limit = static_cast<int>(candidates.size()) + kMaxCaptureRounds;
    for (int event = 0; event < limit; ++event) {
      solve_linear_contact(at_depth);
      ++solves;
      const Eigen::VectorXd us_to = candidate_displacement();
      const auto position = [&](int node, double t) -> Eigen::Vector3d {
        const Eigen::Index row = 3 * candidate_index[static_cast<std::size_t>(node)];
        return mesh.nodes[static_cast<std::size_t>(node)] + (1.0 - t) * us_from.segment<3>(row) +
               t * us_to.segment<3>(row);
      };
      const auto found = find_new_captures(at_depth, [&](int node) -> Eigen::Vector3d {
        return us_to.segment<3>(3 * candidate_index[static_cast<std::size_t>(node)]);
      });
      if (found.empty()) {
        timing.contact_s += seconds_since(start);
        return solves;
      }
      cache_compliance_columns(found);
      const double span = at_depth - from;
      std::vector<double> entry(found.size(), 1.0);
      double first = 1.0;
      for (std::size_t i = 0; i < found.size(); ++i) {
        const auto inside = [&](double t) {
          const Eigen::Vector3d local =
              position(found[i].node, t) - tip(found[i].needle, from + t * span);
          return shapes[static_cast<std::size_t>(found[i].needle)].touches(local);
        };
        double lo = 0.0, hi = 1.0;
        if (inside(0.0)) hi = 0.0;
        for (int halving = 0;
             halving < 60 && hi - lo > 0.0 && (hi - lo) * span > kCaptureBisection * capture_radius;
             ++halving) {
          const double mid = 0.5 * (lo + hi);
          (inside(mid) ? hi : lo) = mid;
        }
        entry[i] = hi;
        first = std::min(first, hi);
      }
      // The event is the first entry; the nodes entering within the group length after it are
      // taken with it, each anchored on the face below (or nearest to) where it is then.
      const double group = first + group_length() / std::max(span, 1e-300);
      std::vector<CapturedNode> now;
      for (std::size_t i = 0; i < found.size(); ++i) {
        if (entry[i] > group) continue;
        const int needle = found[i].needle;
        const Eigen::Vector3d local =
            position(found[i].node, first) - tip(needle, from + first * span);
        now.push_back({found[i].node, needle, anchor_of(needle, local, local)});
      }
      from += first * span;
      append_compliance_columns(now);
      add_captures(now);
      // The rest of the step starts from the solution at the event's depth with the new nodes
      // held (their anchors lie on the face, up to the group length from where the segment had
      // them): one more condensed solve, no factorisation.
      solve_linear_contact(from);
      ++solves;
      us_from = candidate_displacement();
    }
    throw SolverError("3-D solve: contact set did not settle at depth " + micrometres(at_depth));
  }

  // Captures at the step's end, repeated until none is inside: a cracked twin (the leader's
  // captured set and anchors at each output depth, which is all the linear solution depends on)
  // and a run with crack faces in contact.
  int capture_at_step_end(double at_depth) {
    const auto start = Clock::now();
    int solves = 0;
    for (int round = 0; round < kMaxCaptureRounds; ++round) {
      solve_linear_contact(at_depth);
      ++solves;
      const Eigen::VectorXd us = candidate_displacement();
      const auto found = find_new_captures(at_depth, [&](int node) -> Eigen::Vector3d {
        return us.segment<3>(3 * candidate_index[static_cast<std::size_t>(node)]);
      });
      if (found.empty()) {
        timing.contact_s += seconds_since(start);
        return solves;
      }
      append_compliance_columns(found);
      add_captures(found);
    }
    throw SolverError("3-D solve: contact set did not settle at depth " + micrometres(at_depth));
  }

  Eigen::VectorXd linear_displacement() const {
    Eigen::VectorXd load = Eigen::VectorXd::Zero(model.dof_count());
    for (std::size_t i = 0; i < captured.size(); ++i)
      load.segment<3>(3 * captured[i].node) =
          multipliers.segment<3>(3 * static_cast<Eigen::Index>(i));
    for (std::size_t a = 0; a < active_pairs.size(); ++a)
      put_pair_load(static_cast<std::size_t>(active_pairs[a]),
                    pair_forces(static_cast<Eigen::Index>(a)), load);
    if (captured.empty()) return load;
    if (solver.has_trailing_block() && active_pairs.empty()) {
      // The captured nodes are candidates, hence trailing: half a solve.
      Eigen::VectorXd trailing = Eigen::VectorXd::Zero(surface_rows());
      for (std::size_t i = 0; i < captured.size(); ++i)
        trailing.segment<3>(3 * candidate_index[static_cast<std::size_t>(captured[i].node)]) =
            multipliers.segment<3>(3 * static_cast<Eigen::Index>(i));
      return solver.solve_trailing_loads(trailing);
    }
    return solver.solve(load);
  }

  // ---- nonlinear path -----------------------------------------------------------------------
  std::vector<char> constrained_dofs() const {
    std::vector<char> constrained = fixed_dof;
    for (const auto& c : captured)
      for (int j = 0; j < 3; ++j) constrained[static_cast<std::size_t>(3 * c.node + j)] = 1;
    return constrained;
  }

  static Eigen::VectorXd free_part(const Eigen::VectorXd& v, const std::vector<char>& constrained) {
    Eigen::VectorXd r = v;
    for (Eigen::Index i = 0; i < r.size(); ++i)
      if (constrained[static_cast<std::size_t>(i)]) r(i) = 0.0;
    return r;
  }

  double reaction_norm(const Eigen::VectorXd& force) const {
    double sum = 0.0;
    for (const auto& c : captured) sum += force.segment<3>(3 * c.node).squaredNorm();
    return std::sqrt(sum);
  }

  Eigen::VectorXd internal_force(const Eigen::VectorXd& at) {
    const auto start = Clock::now();
    Eigen::VectorXd force;
    model.assemble(at, nullptr, &force);
    add_pair_terms(at, nullptr, &force);
    timing.assembly_s += seconds_since(start);
    return force;
  }

  // Factorises the assembled tangent in `stiffness` for this set of prescribed dofs; keeps the
  // unconstrained copy for the predictor's coupling term.
  // With `may_shift` (the sticking path's Newton), a tangent that is not positive definite is
  // shifted instead (shift_tangent).
  void factorize_tangent(const std::vector<char>& constrained, bool may_shift = false) {
    tangent = stiffness;
    apply_dirichlet(&stiffness, constrained);
    const auto start = Clock::now();
    solver.set_indefinite_fallback(!may_shift);
    solver.factorize(stiffness);
    ++timing.factorizations;
    factor_shifted = false;
    if (may_shift && !solver.ok()) shift_tangent(constrained);
    timing.factorization_s += seconds_since(start);
    if (!solver.ok()) throw SolverError("singular tangent stiffness");
    factor_constraints = constrained;
  }

  // Past a bifurcation (docs/model.md, "Solver"): the free diagonal raised by sigma of itself,
  // from a sixteenth of the last shift that worked (1e-6 at first) up fourfold, until the
  // Cholesky factorisation succeeds; the step it gives descends the strain energy (descend).
  // When no shift up to 4^19 of the first works, the LDLᵀ of the tangent itself, as before.
  void shift_tangent(const std::vector<char>& constrained) {
    const Eigen::VectorXd diagonal = stiffness.diagonal();
    const auto set_diagonal = [&](double sigma) {
      for (Eigen::Index i = 0; i < diagonal.size(); ++i)
        if (!constrained[static_cast<std::size_t>(i)])
          stiffness.coeffRef(i, i) = diagonal[i] + sigma * std::abs(diagonal[i]);
    };
    double sigma = std::max(1e-9, shift / 16.0);
    for (int attempt = 0; attempt < kMaxShifts; ++attempt, sigma *= 4.0) {
      set_diagonal(sigma);
      solver.factorize(stiffness);
      ++timing.factorizations;
      if (solver.ok()) {
        factor_shifted = true;
        shift = sigma;
        ++timing.shifted_factorizations;
        return;
      }
    }
    set_diagonal(0.0);
    solver.set_indefinite_fallback(true);
    solver.factorize(stiffness);
    ++timing.factorizations;
  }

  bool factor_fits(const std::vector<char>& constrained) const {
    return factor_constraints == constrained;
  }

  Eigen::VectorXd assemble_force(bool with_tangent, double* energy = nullptr) {
    const auto start = Clock::now();
    Eigen::VectorXd force;
    const double e = model.assemble(u, with_tangent ? &stiffness : nullptr, &force) +
                     add_pair_terms(u, with_tangent ? &stiffness : nullptr, &force);
    if (energy != nullptr) *energy = e;
    timing.assembly_s += seconds_since(start);
    return force;
  }

  // Linear extrapolation of the prescribed jump into the free dofs (K_ff du_f = -r_f - K_fc du_c):
  // moving only the captured nodes would invert the thin elements around them. The last
  // tangent is reused when the prescribed set has not changed (modified Newton across steps).
  int predict(const Eigen::VectorXd& jump, const std::vector<char>& constrained) {
    const bool reuse = factor_fits(constrained);
    const Eigen::VectorXd force = assemble_force(!reuse);
    if (!reuse) factorize_tangent(constrained, true);
    const Eigen::VectorXd coupled = tangent.selfadjointView<Eigen::Lower>() * jump;
    u += jump + solver.solve(Eigen::VectorXd(free_part(-(force + coupled), constrained)));
    return 1;
  }

  int newton(double at_depth) {
    const std::vector<char> constrained = constrained_dofs();
    Eigen::VectorXd jump = Eigen::VectorXd::Zero(u.size());
    for (const auto& c : captured)
      jump.segment<3>(3 * c.node) = prescribed(c, at_depth) - u.segment<3>(3 * c.node);
    const int predicted = jump.squaredNorm() > 0.0 ? predict(jump, constrained) : 0;
    const double length_scale = (mesh.nodes.front() - mesh.nodes.back()).norm();
    // Modified Newton: a factorisation is kept while it still shrinks the residual at least
    // fourfold per iteration.
    bool refactor = !factor_fits(constrained);
    int iteration = 1 + predicted;
    for (; iteration <= (bifurcated ? kMaxDescentIterations : kMaxNewtonIterations); ++iteration) {
      double energy = 0.0;
      const Eigen::VectorXd force = assemble_force(refactor, &energy);
      const Eigen::VectorXd residual = free_part(force, constrained);
      const double residual_norm = residual.norm();
      if (residual_norm <= options.tolerance * reaction_norm(force)) return iteration - 1;
      if (refactor) factorize_tangent(constrained, true);
      const Eigen::VectorXd delta = solver.solve(Eigen::VectorXd(-residual));
      const double accepted = factor_shifted ? descend(delta, energy, constrained)
                                             : line_search(delta, residual_norm, constrained);
      if (delta.lpNorm<Eigen::Infinity>() < 1e-13 * length_scale) return iteration;
      refactor = !(accepted < 0.25 * residual_norm);
    }
    throw SolverError("Newton-Raphson did not converge in " + std::to_string(iteration - 1) +
                      " iterations");
  }

  // Backtracking on the strain energy after a shifted factorisation: a step toward the stable
  // branch raises the residual before it lowers it, so the residual cannot judge it. With the
  // captured nodes prescribed, the strain energy is the whole potential. No trial lowers it:
  // the shortest one is taken, as on the residual. Returns the residual norm at the new point.
  double descend(const Eigen::VectorXd& delta, double start_energy,
                 const std::vector<char>& constrained) {
    double alpha = 1.0;
    for (int halving = 0; halving <= kMaxLineSearchHalvings; ++halving, alpha *= 0.5) {
      const Eigen::VectorXd trial = u + alpha * delta;
      try {
        const auto start = Clock::now();
        Eigen::VectorXd force;
        const double energy =
            model.assemble(trial, nullptr, &force) + add_pair_terms(trial, nullptr, &force);
        timing.assembly_s += seconds_since(start);
        // Near equilibrium a step lowers the energy by about the squared relative residual,
        // below the round-off of summing element energies: within that it is no rise.
        if (energy < start_energy + kEnergyRoundOff * std::abs(start_energy) ||
            halving == kMaxLineSearchHalvings) {
          u = trial;
          bifurcated = true;
          return free_part(force, constrained).norm();
        }
      } catch (const OutOfMemoryError&) {
        throw;
      } catch (const SolverError&) {
        if (halving == kMaxLineSearchHalvings) throw;
      }
    }
    throw SolverError("no descent along the shifted tangent");  // not reached
  }

  // Backtracking on the residual norm; an inverted element at a trial point counts as a failure.
  // Returns the residual norm at the accepted point.
  template <class ResidualNorm>
  double backtrack(const Eigen::VectorXd& delta, double residual_norm, ResidualNorm&& norm_at) {
    double alpha = 1.0;
    for (int halving = 0; halving <= kMaxLineSearchHalvings; ++halving, alpha *= 0.5) {
      const Eigen::VectorXd trial = u + alpha * delta;
      try {
        const double trial_norm = norm_at(trial);
        if (trial_norm < (1.0 - 1e-4 * alpha) * residual_norm ||
            halving == kMaxLineSearchHalvings) {
          u = trial;
          return trial_norm;
        }
      } catch (const OutOfMemoryError&) {
        throw;
      } catch (const SolverError&) {
        if (halving == kMaxLineSearchHalvings) throw;
      }
    }
    return residual_norm;
  }

  double line_search(const Eigen::VectorXd& delta, double residual_norm,
                     const std::vector<char>& constrained) {
    return backtrack(delta, residual_norm, [&](const Eigen::VectorXd& trial) {
      return free_part(internal_force(trial), constrained).norm();
    });
  }

  // Where, as a fraction t of the step from (from_depth, from_u) to (at_depth, u), the node of
  // capture c entered its needle, both moving linearly over the step: bisected on the needle's
  // inside test to kEntryBisections halvings.
  double entry_fraction(const CapturedNode& c, double from_depth, const Eigen::VectorXd& from_u,
                        double at_depth) const {
    const auto node = static_cast<std::size_t>(c.node);
    const Eigen::Vector3d x0 = mesh.nodes[node] + from_u.segment<3>(3 * c.node);
    const Eigen::Vector3d x1 = mesh.nodes[node] + u.segment<3>(3 * c.node);
    const auto inside = [&](double t) {
      const Eigen::Vector3d local =
          x0 + t * (x1 - x0) - tip(c.needle, from_depth + t * (at_depth - from_depth));
      return shapes[static_cast<std::size_t>(c.needle)].touches(local);
    };
    if (inside(0.0)) return 0.0;
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < kEntryBisections; ++i)
      (inside(0.5 * (lo + hi)) ? hi : lo) = 0.5 * (lo + hi);
    return hi;
  }

  // The node of capture c in its needle's frame at the fraction t of that step.
  Eigen::Vector3d local_at(const CapturedNode& c, double from_depth, const Eigen::VectorXd& from_u,
                           double at_depth, double t) const {
    const auto node = static_cast<std::size_t>(c.node);
    const Eigen::Vector3d x0 = mesh.nodes[node] + from_u.segment<3>(3 * c.node);
    const Eigen::Vector3d x1 = mesh.nodes[node] + u.segment<3>(3 * c.node);
    return x0 + t * (x1 - x0) - tip(c.needle, from_depth + t * (at_depth - from_depth));
  }

  // Nonlinear sticking: the nodes that enter a needle within the step are captured in depth order
  // (docs/model.md, "Contact with the rigid needle (sticking)"): those inside at the step's start
  // at once; when the first of the others enters more than the group length (group_length(), as
  // on the linear path) before the step's end, the step ends that far after it (CaptureEvent);
  // otherwise every node found is captured at the step's end. A twin copying a leader's captures
  // takes them as they come.
  int solve_nonlinear_at(double at_depth, double from_depth, const Eigen::VectorXd& from_u) {
    int total = 0;
    pair_pulled_open.assign(pairs.size(), 0);
    pair_latched.assign(pairs.size(), 0);
    int pair_round = 0;
    const int pair_rounds = kMaxCrackRounds + 4 * static_cast<int>(pairs.size());
    for (int round = 0; round < kMaxCaptureRounds; ++round) {
      const int used = newton(at_depth);
      total += used;
      const auto start = Clock::now();
      auto found = find_new_captures(
          at_depth, [&](int node) -> Eigen::Vector3d { return u.segment<3>(3 * node); });
      if (!found.empty() && !leader) {
        const double step_start = kCaptureStartFraction;
        std::vector<double> t;
        for (const CapturedNode& c : found)
          t.push_back(entry_fraction(c, from_depth, from_u, at_depth));
        const double first = *std::min_element(t.begin(), t.end());
        // The nodes entering within the group length of the first are captured with it.
        const double end = from_depth + first * (at_depth - from_depth) + group_length();
        if (first > step_start && end < at_depth - 1e-9 * (at_depth - from_depth)) {
          timing.contact_s += seconds_since(start);
          throw CaptureEvent{end};
        }
        // Each node held where it entered (anchor_of), which matters only for a wall entered
        // sideways.
        std::vector<CapturedNode> kept;
        for (std::size_t i = 0; i < found.size(); ++i) {
          if (first <= step_start && t[i] > step_start) continue;
          CapturedNode c = found[i];
          c.anchor = anchor_of(c.needle, local_at(c, from_depth, from_u, at_depth, 1.0),
                               local_at(c, from_depth, from_u, at_depth, t[i]));
          kept.push_back(c);
        }
        found = std::move(kept);
      }
      timing.contact_s += seconds_since(start);
      if (found.empty()) {
        if (!nonlinear_pairs()) return total;
        // The crack's faces once the captures settled; multipliers that Newton absorbed
        // without an iteration are within its tolerance.
        const PairUpdate update = update_pairs(at_depth, pair_round);
        if (update == PairUpdate::Settled ||
            (update == PairUpdate::Multipliers && used == 0 && pair_round > 0))
          return total;
        if (++pair_round > pair_rounds)
          throw SolverError("crack-face contact did not settle at depth " + micrometres(at_depth));
        if (update == PairUpdate::Set) factor_constraints.clear();  // another tangent
        --round;  // a pair round is not a capture round
        continue;
      }
      add_captures(found);
    }
    throw SolverError("contact set did not settle");
  }

  int advance_nonlinear(double target) {
    if (u.size() == 0) {
      u = Eigen::VectorXd::Zero(model.dof_count());
      if (nonlinear_pairs()) {
        std::vector<std::array<int, 2>> coupled;
        for (const CrackFacePair& pair : pairs)
          coupled.push_back({pair.positive_node, pair.negative_node});
        model.couple_nodes(coupled);
      }
      stiffness = model.empty_stiffness();
      if (nonlinear_pairs()) {
        set_pair_penalties();
        pair_closed.assign(pairs.size(), 0);
        pair_multiplier = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs.size()));
      }
      solver.analyze(stiffness);
    }
    if (step <= 0.0) step = target - depth;
    int total = 0;
    int cuts = 0;
    while (depth < target) {
      const double h = std::min(step, target - depth);
      const Eigen::VectorXd saved_u = u;
      const std::size_t saved_captured = captured.size();
      const std::vector<double> saved_multipliers =
          frictionless() ? multipliers_of() : std::vector<double>{};
      const std::vector<char> saved_closed = pair_closed;
      const bool saved_bifurcated = bifurcated;
      const Eigen::VectorXd saved_pair_multiplier = pair_multiplier;
      // Undoes the held crack faces with the step; a factor with other held pairs is not kept.
      const auto restore_pairs = [&]() {
        if (!nonlinear_pairs()) return;
        if (pair_closed != saved_closed) factor_constraints.clear();
        pair_closed = saved_closed;
        pair_multiplier = saved_pair_multiplier;
      };
      try {
        const int used = frictionless() ? solve_frictionless_nonlinear_at(depth + h)
                                        : solve_nonlinear_at(depth + h, depth, saved_u);
        total += used;
        depth += h;
        if (used <= 4) step = 1.5 * h;
        cuts = 0;
      } catch (const OutOfMemoryError&) {
        throw;  // a shorter step needs as much memory
      } catch (const CaptureEvent& event) {
        // The step ends where its first capture enters: not a failure, no cut counted.
        u = saved_u;
        restore_pairs();
        for (std::size_t i = saved_captured; i < captured.size(); ++i)
          captured_by[static_cast<std::size_t>(captured[i].node)] = -1;
        captured.resize(saved_captured);
        step = event.depth - depth;
      } catch (const SolverError& error) {
        u = saved_u;
        restore_pairs();
        bifurcated = saved_bifurcated;  // the undone step's descent does not count
        if (frictionless()) contact->set_multipliers(saved_multipliers);
        for (std::size_t i = saved_captured; i < captured.size(); ++i)
          captured_by[static_cast<std::size_t>(captured[i].node)] = -1;
        captured.resize(saved_captured);
        step = 0.5 * h;
        factor_constraints.clear();  // a fresh tangent for the retry
        if (++cuts > kMaxStepCuts)
          throw SolverError("3-D solve: stopped at depth " + micrometres(depth) + ": " +
                            error.what());
      }
    }
    return total;
  }

  // ---- frictionless path ----------------------------------------------------------------------
  bool frictionless() const { return options.contact == ContactMode::Frictionless; }

  // Nodes a needle touches now: captured (sticking) or of a face with a pressed contact point
  // (frictionless, as the step's report counts them).
  std::vector<char> touched_nodes() const {
    std::vector<char> touched(mesh.nodes.size(), 0);
    if (!frictionless()) {
      for (const CapturedNode& c : captured) touched[static_cast<std::size_t>(c.node)] = 1;
      return touched;
    }
    const auto& points = contact->points();
    for (std::size_t q = 0; q < points.size() && q < contact_states.size(); ++q) {
      if (contact_states[q].traction <= 0.0) continue;
      for (int a = 0; a < contact->face_nodes(); ++a)
        touched[static_cast<std::size_t>(points[q].nodes[static_cast<std::size_t>(a)])] = 1;
    }
    return touched;
  }

  void setup_frictionless() {
    contact.emplace(mesh, needles, &shapes, reach);
    row_index.assign(mesh.nodes.size(), -1);
    involved_index.assign(mesh.nodes.size(), -1);
    const auto& rows = contact->nodes();
    for (std::size_t r = 0; r < rows.size(); ++r)
      row_index[static_cast<std::size_t>(rows[r])] = static_cast<int>(r);
    compliance.resize(3 * static_cast<Eigen::Index>(rows.size()), 0);
    contact_load.resize(0);
  }

  // Nodal force of the contact on the tissue, free dofs only, at the involved nodes.
  Eigen::VectorXd involved_contact_force(const std::vector<ContactPointState>& states) const {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(involved.size()));
    contact->for_each_force(states, [&](int node, const Eigen::Vector3d& force) {
      const int i = involved_index[static_cast<std::size_t>(node)];
      for (int j = 0; j < 3; ++j)
        if (!fixed_dof[static_cast<std::size_t>(3 * node + j)]) f(3 * i + j) += force(j);
    });
    return f;
  }

  // Nodes of loaded faces that have no compliance column yet.
  std::vector<int> missing_involved(const std::vector<ContactPointState>& states) const {
    std::vector<int> missing;
    contact->for_each_force(states, [&](int node, const Eigen::Vector3d&) {
      if (involved_index[static_cast<std::size_t>(node)] < 0) missing.push_back(node);
    });
    std::sort(missing.begin(), missing.end());
    missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
    return missing;
  }

  void add_involved(const std::vector<int>& nodes) {
    const Eigen::Index old_columns = compliance.cols();
    Eigen::MatrixXd unit =
        Eigen::MatrixXd::Zero(model.dof_count(), 3 * static_cast<Eigen::Index>(nodes.size()));
    for (std::size_t i = 0; i < nodes.size(); ++i)
      for (int j = 0; j < 3; ++j)
        unit(3 * nodes[i] + j, 3 * static_cast<Eigen::Index>(i) + j) = 1.0;
    const Eigen::MatrixXd columns = solver.solve_many(unit);
    const auto& rows = contact->nodes();
    compliance.conservativeResize(Eigen::NoChange, old_columns + columns.cols());
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (int j = 0; j < 3; ++j)
        compliance.block(3 * static_cast<Eigen::Index>(r) + j, old_columns, 1, columns.cols()) =
            columns.row(3 * rows[r] + j);
    for (int node : nodes) {
      involved_index[static_cast<std::size_t>(node)] = static_cast<int>(involved.size());
      involved.push_back(node);
    }
    contact_load.conservativeResize(3 * static_cast<Eigen::Index>(involved.size()));
    contact_load.tail(3 * static_cast<Eigen::Index>(nodes.size())).setZero();
  }

  // Displacement of the contact-face nodes under the current contact load.
  Eigen::VectorXd condensed_displacement() const {
    if (involved.empty()) return Eigen::VectorXd::Zero(compliance.rows());
    return compliance * contact_load;
  }

  std::vector<ContactPointState> condensed_states(double at_depth) const {
    const Eigen::VectorXd ur = condensed_displacement();
    return contact->evaluate(at_depth, [&](int node) -> Eigen::Vector3d {
      const int r = row_index[static_cast<std::size_t>(node)];
      return ur.segment<3>(3 * r);
    });
  }

  // Newton on the contact load f at fixed multipliers: R(f) = f - f_c(u(f)) with u = C f, so
  // dR/df = I + K_c C (K_c the penalty tangent at the loaded points).
  int solve_condensed(double at_depth) {
    int iterations = 0;
    for (int iteration = 0; iteration < kMaxContactNewton; ++iteration) {
      std::vector<ContactPointState> states = condensed_states(at_depth);
      const std::vector<int> missing = missing_involved(states);
      if (!missing.empty()) {
        add_involved(missing);
        continue;
      }
      const Eigen::VectorXd target = involved_contact_force(states);
      const Eigen::VectorXd residual = contact_load - target;
      contact_states = std::move(states);
      if (residual.norm() <= 1e-10 * std::max(target.norm(), contact_load.norm()) ||
          (target.norm() == 0.0 && contact_load.norm() == 0.0))
        return iterations;
      const Eigen::Index m = contact_load.size();
      Eigen::MatrixXd penalty = Eigen::MatrixXd::Zero(m, m);
      contact->for_each_tangent(contact_states, [&](int a, int b, const Eigen::Matrix3d& block) {
        const int ia = involved_index[static_cast<std::size_t>(a)];
        const int ib = involved_index[static_cast<std::size_t>(b)];
        penalty.block<3, 3>(3 * ia, 3 * ib) += block;
      });
      for (std::size_t i = 0; i < involved.size(); ++i)
        for (int j = 0; j < 3; ++j)
          if (fixed_dof[static_cast<std::size_t>(3 * involved[i] + j)]) {
            penalty.row(3 * static_cast<Eigen::Index>(i) + j).setZero();
            penalty.col(3 * static_cast<Eigen::Index>(i) + j).setZero();
          }
      Eigen::MatrixXd jacobian = penalty * involved_rows();
      jacobian.diagonal().array() += 1.0;
      contact_load -= jacobian.partialPivLu().solve(residual);
      ++iterations;
    }
    throw SolverError("3-D solve: frictionless contact did not converge at depth " +
                      micrometres(at_depth));
  }

  // C restricted to the involved nodes' rows.
  Eigen::MatrixXd involved_rows() const {
    Eigen::MatrixXd c(contact_load.size(), compliance.cols());
    for (std::size_t i = 0; i < involved.size(); ++i)
      c.middleRows(3 * static_cast<Eigen::Index>(i), 3) =
          compliance.middleRows(3 * row_index[static_cast<std::size_t>(involved[i])], 3);
    return c;
  }

  // Uzawa has settled when the nodal contact forces stop changing. The point multipliers
  // themselves are not a good measure: with more contact points than face nodes, patterns of λ
  // that the face interpolation cannot see keep drifting without changing any force.
  bool multipliers_settled(Eigen::VectorXd* previous) const {
    const auto& nodes = contact->nodes();
    Eigen::VectorXd forces = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(nodes.size()));
    contact->for_each_force(contact_states, [&](int node, const Eigen::Vector3d& f) {
      const auto at = std::lower_bound(nodes.begin(), nodes.end(), node) - nodes.begin();
      forces.segment<3>(3 * at) += f;
    });
    const bool settled =
        previous->size() == forces.size() &&
        (forces - *previous).lpNorm<Eigen::Infinity>() <= kUzawaTolerance * needle_force_scale();
    *previous = std::move(forces);
    return settled;
  }

  double needle_force_scale() const {
    double total = 0.0;
    contact->for_each_force(contact_states,
                            [&](int, const Eigen::Vector3d& f) { total += f.norm(); });
    return total;
  }

  int advance_frictionless_linear(double at_depth) {
    if (!linear_factorized) factorize_linear();
    const auto start = Clock::now();
    int solves = 0;
    Eigen::VectorXd previous_forces;
    for (int update = 0; update < kMaxUzawa; ++update) {
      solves += solve_condensed(at_depth);
      contact->update_multipliers(contact_states);
      if (multipliers_settled(&previous_forces)) {
        timing.contact_s += seconds_since(start);
        return solves;
      }
    }
    throw SolverError("3-D solve: frictionless multipliers did not settle at depth " +
                      micrometres(at_depth));
  }

  Eigen::VectorXd frictionless_linear_displacement() const {
    Eigen::VectorXd load = Eigen::VectorXd::Zero(model.dof_count());
    for (std::size_t i = 0; i < involved.size(); ++i)
      load.segment<3>(3 * involved[i]) = contact_load.segment<3>(3 * static_cast<Eigen::Index>(i));
    if (involved.empty()) return load;
    return solver.solve(load);
  }

  // Nonlinear layers: Newton on f_int(u) - f_c(u) = 0 with the penalty tangent added to the
  // assembled one; the factorisation is kept while the residual falls fourfold per iteration.
  Eigen::VectorXd contact_residual(const Eigen::VectorXd& at, double at_depth,
                                   std::vector<ContactPointState>* states) {
    Eigen::VectorXd r = internal_force(at);
    *states = contact->evaluate(
        at_depth, [&](int node) -> Eigen::Vector3d { return at.segment<3>(3 * node); });
    contact->for_each_force(
        *states, [&](int node, const Eigen::Vector3d& f) { r.segment<3>(3 * node) -= f; });
    return free_part(r, fixed_dof);
  }

  int newton_frictionless(double at_depth) {
    const double length_scale = (mesh.nodes.front() - mesh.nodes.back()).norm();
    bool refactor = true;
    for (int iteration = 1; iteration <= kMaxNewtonIterations; ++iteration) {
      std::vector<ContactPointState> states;
      Eigen::VectorXd residual;
      if (refactor) {
        const Eigen::VectorXd force = assemble_force(true);
        states = contact->evaluate(
            at_depth, [&](int node) -> Eigen::Vector3d { return u.segment<3>(3 * node); });
        residual = force;
        contact->for_each_force(states, [&](int node, const Eigen::Vector3d& f) {
          residual.segment<3>(3 * node) -= f;
        });
        residual = free_part(residual, fixed_dof);
        contact->for_each_tangent(states, [&](int a, int b, const Eigen::Matrix3d& block) {
          if (a >= b) model.add_block(a, b, block, &stiffness);
        });
      } else {
        residual = contact_residual(u, at_depth, &states);
      }
      contact_states = states;
      const double scale = std::max(needle_force_scale(), 1e-30);
      if (residual.norm() <= options.tolerance * scale) return iteration - 1;
      if (refactor) factorize_tangent(fixed_dof);
      const Eigen::VectorXd delta = solver.solve(Eigen::VectorXd(-residual));
      const double accepted = contact_line_search(delta, residual.norm(), at_depth);
      if (delta.lpNorm<Eigen::Infinity>() < 1e-13 * length_scale) return iteration;
      refactor = !(accepted < 0.25 * residual.norm());
    }
    throw SolverError("Newton-Raphson with frictionless contact did not converge in " +
                      std::to_string(kMaxNewtonIterations) + " iterations");
  }

  double contact_line_search(const Eigen::VectorXd& delta, double residual_norm, double at_depth) {
    return backtrack(delta, residual_norm, [&](const Eigen::VectorXd& trial) {
      std::vector<ContactPointState> states;
      return contact_residual(trial, at_depth, &states).norm();
    });
  }

  int solve_frictionless_nonlinear_at(double at_depth) {
    int total = 0;
    Eigen::VectorXd previous_forces;
    for (int update = 0; update < kMaxUzawa; ++update) {
      total += newton_frictionless(at_depth);
      contact_states = contact->evaluate(
          at_depth, [&](int node) -> Eigen::Vector3d { return u.segment<3>(3 * node); });
      contact->update_multipliers(contact_states);
      if (multipliers_settled(&previous_forces)) return total;
    }
    throw SolverError("frictionless multipliers did not settle");
  }

  std::vector<double> multipliers_of() const {
    std::vector<double> m;
    for (const auto& p : contact->points()) m.push_back(p.multiplier);
    return m;
  }

  // ---- results ------------------------------------------------------------------------------
  Eigen::VectorXd captured_forces() {
    // Force of the needle on each captured node (N), 3 per captured node.
    if (model.is_linear()) return multipliers;
    const Eigen::VectorXd force = internal_force(u);
    Eigen::VectorXd result(3 * static_cast<Eigen::Index>(captured.size()));
    for (std::size_t i = 0; i < captured.size(); ++i)
      result.segment<3>(3 * static_cast<Eigen::Index>(i)) = force.segment<3>(3 * captured[i].node);
    return result;
  }

  // The linear path's displacement at the corners of the held faces, from the compliance rows
  // of the candidates and their ring (every corner of a held face is one of them or fixed): a
  // solve over the whole mesh per step cost as much as the contact itself. Entries of other
  // nodes are left at zero and are not read.
  Eigen::VectorXd linear_surface_displacement() const {
    Eigen::VectorXd field = Eigen::VectorXd::Zero(model.dof_count());
    const Eigen::VectorXd us = candidate_displacement();
    for (std::size_t c = 0; c < candidates.size() + ring.size(); ++c) {
      const int node = c < candidates.size() ? candidates[c] : ring[c - candidates.size()];
      field.segment<3>(3 * static_cast<Eigen::Index>(node)) =
          us.segment<3>(3 * static_cast<Eigen::Index>(c));
    }
    return field;
  }

  // Projected area of the top faces touched by a needle, each face counted by the fraction of
  // its nodes the needle holds (so the rim faces count in part, not all or nothing).
  double contact_area(int needle, const Eigen::VectorXd& displacement) const {
    double area = 0.0;
    const int face_nodes = mesh.order == 1 ? 3 : 6;
    for (const auto& face : mesh.top_faces) {
      int held = 0;
      for (int k = 0; k < face_nodes; ++k)
        if (captured_by[static_cast<std::size_t>(face[static_cast<std::size_t>(k)])] == needle)
          ++held;
      if (held == 0) continue;
      std::array<Eigen::Vector2d, 3> p;
      for (int k = 0; k < 3; ++k) {
        const int node = face[static_cast<std::size_t>(k)];
        p[static_cast<std::size_t>(k)] = mesh.nodes[static_cast<std::size_t>(node)].head<2>() +
                                         displacement.segment<2>(3 * node);
      }
      const Eigen::Vector2d a = p[1] - p[0], b = p[2] - p[0];
      area += 0.5 * std::abs(a.x() * b.y() - a.y() * b.x()) * held / face_nodes;
    }
    return area;
  }

  // A reduced model reports the whole problem: each mirror image carries the same share.
  double whole() const { return (mesh.mirror_x0 ? 2.0 : 1.0) * (mesh.mirror_y0 ? 2.0 : 1.0); }
  bool on_mirror_x(std::size_t n) const { return mesh.mirror_x0 && needles[n].x == 0.0; }
  bool on_mirror_y(std::size_t n) const { return mesh.mirror_y0 && needles[n].y == 0.0; }
  // A needle on a mirror plane is cut by it: its image there is its other half. A needle off
  // the planes is whole in the model (its images are other needles).
  double share(std::size_t n) const {
    return (on_mirror_x(n) ? 2.0 : 1.0) * (on_mirror_y(n) ? 2.0 : 1.0);
  }
  // Tissue-on-needle force of needle n for the whole needle: the mirror halves' forces
  // across a plane cancel.
  Eigen::Vector3d whole_needle_force(std::size_t n, const Eigen::Vector3d& meshed) const {
    Eigen::Vector3d total = share(n) * meshed;
    if (on_mirror_x(n)) total.x() = 0.0;
    if (on_mirror_y(n)) total.y() = 0.0;
    return total;
  }

  Eigen::VectorXd field() const {
    if (!model.is_linear()) return u;
    return frictionless() ? frictionless_linear_displacement() : linear_displacement();
  }

  Step3d report_frictionless(double at_depth, int solves) {
    Step3d result;
    result.depth_m = at_depth;
    result.newton_iterations = solves;
    if (model.is_linear()) {
      double work = 0.0;  // Clapeyron: U = ½ Σ f·u over the loaded dofs
      const Eigen::VectorXd ur = condensed_displacement();
      for (std::size_t i = 0; i < involved.size(); ++i)
        work += contact_load.segment<3>(3 * static_cast<Eigen::Index>(i))
                    .dot(ur.segment<3>(3 * row_index[static_cast<std::size_t>(involved[i])]));
      result.strain_energy_J = whole() * 0.5 * work;
    } else {
      result.strain_energy_J = whole() * model.strain_energy(u);
    }
    const auto& points = contact->points();
    std::vector<Eigen::Vector3d> force(needles.size(), Eigen::Vector3d::Zero());
    std::vector<double> area(needles.size(), 0.0);
    std::vector<std::vector<char>> touched(needles.size(), std::vector<char>(mesh.nodes.size(), 0));
    for (std::size_t q = 0; q < points.size(); ++q) {
      const ContactPointState& state = contact_states[q];
      if (state.traction <= 0.0) continue;
      const auto n = static_cast<std::size_t>(points[q].needle);
      force[n] -= points[q].weight * state.traction * state.normal;  // tissue on needle
      area[n] += points[q].weight;
      for (int a = 0; a < contact->face_nodes(); ++a)
        touched[n][static_cast<std::size_t>(points[q].nodes[static_cast<std::size_t>(a)])] = 1;
    }
    for (std::size_t n = 0; n < needles.size(); ++n) {
      NeedleStep3d needle;
      needle.name = needles[n].name;
      const Eigen::Vector3d total = whole_needle_force(n, force[n]);
      needle.force_N = total.z();
      needle.lateral_force_N = {total.x(), total.y()};
      needle.contact_area_m2 = share(n) * area[n];
      needle.contact_pressure_Pa =
          needle.contact_area_m2 > 0.0 ? needle.force_N / needle.contact_area_m2 : 0.0;
      needle.captured_nodes =
          static_cast<int>(std::count(touched[n].begin(), touched[n].end(), char{1}));
      result.needles.push_back(needle);
    }
    return result;
  }

  // Largest overlap of the crack faces (m) and the pairs in contact.
  void report_crack_faces(Step3d* step) const {
    if (pairs.empty()) return;
    Eigen::VectorXd gaps;
    if (crack_contact()) {
      gaps = pair_gaps_now();
    } else {
      const Eigen::VectorXd u_now = field();
      gaps.resize(static_cast<Eigen::Index>(pairs.size()));
      for (std::size_t p = 0; p < pairs.size(); ++p)
        gaps(static_cast<Eigen::Index>(p)) = gap_of(p, u_now);
    }
    step->crack_face_overlap_m = std::max(0.0, -gaps.minCoeff());
    step->crack_face_contacts =
        nonlinear_pairs() ? static_cast<int>(std::count(pair_closed.begin(), pair_closed.end(), 1))
                          : static_cast<int>(active_pairs.size());
  }

  Step3d report(double at_depth, int solves) {
    Step3d step = report_needles(at_depth, solves);
    report_crack_faces(&step);
    return step;
  }

  Step3d report_needles(double at_depth, int solves) {
    if (frictionless()) return report_frictionless(at_depth, solves);
    Step3d result;
    result.depth_m = at_depth;
    result.newton_iterations = solves;
    const Eigen::VectorXd forces = captured_forces();
    const Eigen::VectorXd imposed = prescribed_vector(at_depth);
    result.strain_energy_J =
        whole() * (model.is_linear() ? 0.5 * forces.dot(imposed) : model.strain_energy(u));
    const Eigen::VectorXd moved = model.is_linear() ? linear_surface_displacement() : u;
    for (std::size_t n = 0; n < needles.size(); ++n) {
      NeedleStep3d needle;
      needle.name = needles[n].name;
      Eigen::Vector3d total = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; i < captured.size(); ++i) {
        if (captured[i].needle != static_cast<int>(n)) continue;
        total -= forces.segment<3>(3 * static_cast<Eigen::Index>(i));  // tissue on needle
        ++needle.captured_nodes;
      }
      total = whole_needle_force(n, total);
      needle.force_N = total.z();
      needle.lateral_force_N = {total.x(), total.y()};
      needle.contact_area_m2 = share(n) * contact_area(static_cast<int>(n), moved);
#ifndef NDEBUG
      // The surface displacement read from the compliance rows must be the whole-mesh solve's
      // (every corner of a held face is a candidate, a ring node or fixed): checked in debug
      // builds, where it costs the solve it saves. 1e-9: round-off (measured 5e-15).
      if (model.is_linear()) {
        const double full = share(n) * contact_area(static_cast<int>(n), linear_displacement());
        assert(std::abs(needle.contact_area_m2 - full) <= 1e-9 * full);
      }
#endif
      needle.contact_pressure_Pa =
          needle.contact_area_m2 > 0.0 ? needle.force_N / needle.contact_area_m2 : 0.0;
      result.needles.push_back(needle);
    }
    return result;
  }
};

namespace {

double mesh_extent(const TetMesh& mesh) {
  Eigen::Vector3d lo = mesh.nodes.front(), hi = mesh.nodes.front();
  for (const auto& p : mesh.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

// A reduced model holds the needles of its own part: each needle lies on the kept side of every
// mirror plane, and one that a plane cuts must be symmetric about it. Planes are exact
// coordinates (x = 0, y = 0), as the planner and the mesh generator place them.
void check_mirror_planes(const TetMesh& mesh, const std::vector<Needle3d>& needles,
                         const std::vector<NeedleShape>& shapes, double extent) {
  const double tolerance = 1e-6 * extent + 1e-12;
  for (std::size_t n = 0; n < needles.size(); ++n) {
    const std::string where = "3-D reduced model: needle '" + needles[n].name + "'";
    if ((mesh.mirror_x0 && needles[n].x < 0.0) || (mesh.mirror_y0 && needles[n].y < 0.0))
      throw InputError(where + " at (" + micrometres(needles[n].x) + ", " +
                       micrometres(needles[n].y) +
                       ") lies in the mirrored part: give only the needles with x, y >= 0 on "
                       "a mirror plane");
    if (mesh.mirror_y0 && needles[n].y == 0.0 && !shapes[n].mirror_symmetric_y(tolerance))
      throw InputError(where + " is not mirror-symmetric about y = 0 (use the full model)");
    if (mesh.mirror_x0 && needles[n].x == 0.0 && !shapes[n].mirror_symmetric_x(tolerance))
      throw InputError(where + " is not mirror-symmetric about x = 0 (use the full model)");
  }
}

}  // namespace

Indentation3d::Indentation3d(const TetMesh& mesh, std::vector<Needle3d> needles, double max_depth,
                             const Indentation3dOptions& options)
    : impl_(std::make_unique<Impl>(mesh, std::move(needles), options)) {
  if (impl_->needles.empty()) throw InputError("3-D indentation: no needle given");
  if (!(max_depth > 0.0)) throw InputError("3-D indentation: depth must be positive");
  if (!(options.tolerance > 0.0) || !(options.tolerance < 1.0))
    throw InputError("3-D indentation: tolerance must lie in (0, 1)");
  if (mesh.fixed.size() != mesh.nodes.size() || mesh.nodes.empty())
    throw InputError("3-D indentation: mesh has no nodes or no boundary flags");
  impl_->select_candidates(max_depth);
  if (impl_->frictionless()) impl_->setup_frictionless();
  const double extent = mesh_extent(mesh);
  check_mirror_planes(mesh, impl_->needles, impl_->shapes, extent);
  impl_->fixed_dof.assign(static_cast<std::size_t>(impl_->model.dof_count()), 0);
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    if (mesh.fixed[n])
      for (int j = 0; j < 3; ++j) impl_->fixed_dof[3 * n + static_cast<std::size_t>(j)] = 1;
    // symmetry: no displacement across a mirror plane
    if (mesh.mirror_x0 && std::abs(mesh.nodes[n].x()) <= 1e-12 * extent)
      impl_->fixed_dof[3 * n] = 1;
    if (mesh.mirror_y0 && std::abs(mesh.nodes[n].y()) <= 1e-12 * extent)
      impl_->fixed_dof[3 * n + 1] = 1;
  }
}

Indentation3d::~Indentation3d() = default;

void Indentation3d::hold_contact_of(const Indentation3d& leader, std::vector<int> leader_node) {
  if (impl_->frictionless() || leader.impl_->frictionless())
    throw InputError("3-D indentation: a held contact needs sticking contact");
  if (leader_node.size() != impl_->mesh.nodes.size())
    throw InputError("3-D indentation: held contact: one leader node per node expected");
  for (int node : leader_node)
    if (node < 0 || static_cast<std::size_t>(node) >= leader.impl_->mesh.nodes.size())
      throw InputError("3-D indentation: held contact: leader node out of range");
  impl_->leader = leader.impl_.get();
  impl_->leader_node = std::move(leader_node);
}

void Indentation3d::set_crack_faces(std::vector<CrackFacePair> pairs, bool contact) {
  if (impl_->depth > 0.0 || impl_->compliance.cols() > 0 || !impl_->column_cache.empty() ||
      impl_->u.size() > 0)  // the nonlinear path's pattern and pair state are set at its start
    throw InputError("3-D indentation: crack-face contact must be set before the first depth");
  const auto nodes = static_cast<int>(impl_->mesh.nodes.size());
  for (const CrackFacePair& pair : pairs) {
    if (pair.negative_node < 0 || pair.negative_node >= nodes || pair.positive_node < 0 ||
        pair.positive_node >= nodes || pair.negative_node == pair.positive_node)
      throw InputError("3-D indentation: crack-face pair: node out of range");
    if (!pair.normal.allFinite() || std::abs(pair.normal.norm() - 1.0) > 1e-9)
      throw InputError("3-D indentation: crack-face pair: the normal must be a unit vector");
  }
  impl_->pairs = std::move(pairs);
  impl_->pair_contact = contact;
  impl_->pair_column.assign(impl_->pairs.size(), -1);
}

Step3d Indentation3d::advance_to(double depth) {
  if (!(depth >= impl_->depth) || !std::isfinite(depth))
    throw InputError("3-D indentation: depths must grow (asked " + micrometres(depth) + " after " +
                     micrometres(impl_->depth) + ")");
  const auto start = Clock::now();
  int solves = 0;
  if (impl_->model.is_linear()) {
    try {
      solves = impl_->frictionless() ? impl_->advance_frictionless_linear(depth)
                                     : impl_->advance_linear(depth);
    } catch (const SolverError& error) {
      const std::string what = error.what();
      if (what.rfind("3-D solve", 0) == 0) throw;
      const std::string where = "3-D solve: stopped at depth " + micrometres(impl_->depth) + ": ";
      if (dynamic_cast<const OutOfMemoryError*>(&error) != nullptr)
        throw OutOfMemoryError(where + what);
      throw SolverError(where + what);
    }
    impl_->depth = depth;
  } else {
    solves = impl_->advance_nonlinear(depth);
  }
  Step3d step = impl_->report(depth, solves);
  impl_->timing.total_s += seconds_since(start);
  return step;
}

Eigen::VectorXd Indentation3d::displacement() const {
  return impl_->field();
}

void Indentation3d::watch_nodes(std::vector<int> nodes) {
  if (impl_->depth > 0.0 || impl_->compliance.cols() > 0 || !impl_->column_cache.empty())
    throw InputError("3-D indentation: watched nodes must be set before the first depth");
  for (int node : nodes)
    if (node < 0 || static_cast<std::size_t>(node) >= impl_->mesh.nodes.size())
      throw InputError("3-D indentation: watched node out of range");
  impl_->watched = std::move(nodes);
}

Eigen::VectorXd Indentation3d::watched_displacement() const {
  const Impl& m = *impl_;
  const auto rows = 3 * static_cast<Eigen::Index>(m.watched.size());
  // The kept rows hold the captured nodes' columns only: crack-face loads, frictionless contact
  // and the nonlinear path read the whole field.
  if (m.model.is_linear() && !m.frictionless() && !m.watched_overflow && m.active_pairs.empty() &&
      m.watched_compliance.rows() == rows &&
      m.watched_compliance.cols() == 3 * static_cast<Eigen::Index>(m.captured.size()) &&
      m.multipliers.size() == m.watched_compliance.cols()) {
    if (m.captured.empty()) return Eigen::VectorXd::Zero(rows);
    return m.watched_compliance * m.multipliers;
  }
  const Eigen::VectorXd u = m.field();
  Eigen::VectorXd out(rows);
  for (std::size_t w = 0; w < m.watched.size(); ++w)
    out.segment<3>(3 * static_cast<Eigen::Index>(w)) = u.segment<3>(3 * m.watched[w]);
  return out;
}

bool Indentation3d::watched_by_back_solve() const {
  const Impl& m = *impl_;
  const bool rows_kept =
      !m.watched_overflow &&
      m.watched_compliance.rows() == 3 * static_cast<Eigen::Index>(m.watched.size()) &&
      m.watched_compliance.cols() == 3 * static_cast<Eigen::Index>(m.captured.size()) &&
      m.multipliers.size() == m.watched_compliance.cols();
  return m.model.is_linear() && !m.frictionless() && m.active_pairs.empty() && !rows_kept &&
         !m.captured.empty() && m.solver.has_trailing_block();
}

Eigen::VectorXd Indentation3d::watched_trailing_loads() const {
  if (!watched_by_back_solve())
    throw InputError("3-D indentation: the watched rows of this depth need no back substitution");
  const Impl& m = *impl_;
  Eigen::VectorXd trailing = Eigen::VectorXd::Zero(m.surface_rows());
  for (std::size_t i = 0; i < m.captured.size(); ++i)
    trailing.segment<3>(3 * m.candidate_index[static_cast<std::size_t>(m.captured[i].node)]) =
        m.multipliers.segment<3>(3 * static_cast<Eigen::Index>(i));
  return trailing;
}

Eigen::MatrixXd Indentation3d::watched_displacements(const Eigen::MatrixXd& loads) const {
  const Impl& m = *impl_;
  if (!m.solver.has_trailing_block() || loads.rows() != m.surface_rows())
    throw InputError("3-D indentation: trailing loads of the wrong size, or no trailing block");
  Eigen::MatrixXd out(3 * static_cast<Eigen::Index>(m.watched.size()), loads.cols());
  // At most kBackSolveColumns at a time, and fewer where the field is large: a back
  // substitution holds about four dense copies of the field per column (the load, CHOLMOD's two
  // results and ours), kept within kBackSolveBudget; streaming the factor once for eight columns
  // already costs about what it costs for one.
  const double per_column = 4.0 * 8.0 * static_cast<double>(m.model.dof_count());
  const Eigen::Index batch = std::clamp<Eigen::Index>(
      static_cast<Eigen::Index>(kBackSolveBudget / per_column), 1, kBackSolveColumns);
  for (Eigen::Index first = 0; first < loads.cols(); first += batch) {
    const Eigen::Index count = std::min<Eigen::Index>(batch, loads.cols() - first);
    const Eigen::MatrixXd u = m.solver.solve_trailing_loads(loads.middleCols(first, count));
    for (std::size_t w = 0; w < m.watched.size(); ++w)
      out.block(3 * static_cast<Eigen::Index>(w), first, 3, count) =
          u.middleRows<3>(3 * m.watched[w]);
  }
  return out;
}

const Timing3d& Indentation3d::timing() const {
  return impl_->timing;
}

std::string Indentation3d::solver_backend() const {
  return impl_->solver.backend();
}

bool Indentation3d::uses_contact_block() const {
  return impl_->solver.has_trailing_block();
}

InpExport Indentation3d::write_inp(const std::string& path,
                                   const std::vector<std::string>& comment) const {
  if (impl_->frictionless())
    throw InputError(
        "export: the .inp deck prescribes the needle's sticking contact; the run "
        "uses frictionless contact");
  InpProblem problem;
  problem.mesh = &impl_->mesh;
  problem.comment_lines = comment;
  const Eigen::VectorXd u = displacement();
  const Eigen::VectorXd force = impl_->internal_force(u);  // held crack faces' forces included
  InpExport result;
  for (const CapturedNode& c : impl_->captured) {
    problem.prescribed_nodes.push_back(c.node);
    problem.prescribed_u.emplace_back(u.segment<3>(3 * static_cast<Eigen::Index>(c.node)));
    result.reaction_N += force.segment<3>(3 * static_cast<Eigen::Index>(c.node));
  }
  write_inp_deck(path, problem);
  result.path = path;
  result.depth_m = impl_->depth;
  result.nodes = static_cast<int>(impl_->mesh.nodes.size());
  result.elements = static_cast<int>(impl_->mesh.elements.size());
  result.prescribed_nodes = static_cast<int>(problem.prescribed_nodes.size());
  return result;
}

void Indentation3d::write_vtu(const std::string& path, double depth_m,
                              const std::string& comment) const {
  TissueStep3d step;
  step.mesh = &impl_->mesh;
  step.u = displacement();
  impl_->model.assemble(step.u, nullptr, &step.internal_force);
  step.in_contact = impl_->touched_nodes();
  step.stress = impl_->model.cauchy_stress(step.u);
  step.energy_density = impl_->model.energy_density(step.u);
  VtuFile file = tissue_vtu(step, depth_m);
  file.comment = comment;
  fe::write_vtu(path, file);
}

namespace {

// Every needle's crack, one after the other on the same mesh; returns the total area (one
// face, of the meshed part) and each needle's share; `original_node` maps every node of the
// cracked mesh to its node in `mesh`.
TetMesh cracked_copy(const TetMesh& mesh, const std::vector<Needle3d>& needles,
                     const std::vector<Eigen::Vector2d>& tips, double depth,
                     std::vector<double>* areas, std::vector<int>* original_node,
                     std::vector<CrackFacePair>* pairs) {
  TetMesh cracked = mesh;
  original_node->resize(mesh.nodes.size());
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) (*original_node)[n] = static_cast<int>(n);
  for (std::size_t n = 0; n < needles.size(); ++n) {
    PlanarCrack crack;
    crack.origin_m = crack_origin_under(mesh, Eigen::Vector2d(needles[n].x, needles[n].y), tips[n]);
    crack.normal = Eigen::Vector3d::UnitX();
    crack.depth_m = depth;
    double area = 0.0;
    std::vector<int> previous;
    const std::size_t before = cracked.nodes.size();
    cracked = crack_mesh(cracked, crack, &area, &previous);
    // crack_mesh appends one copy per opened node, on the side the normal points to.
    for (std::size_t copy = before; copy < cracked.nodes.size(); ++copy)
      pairs->push_back({previous[copy], static_cast<int>(copy), crack.normal});
    for (int& node : previous) node = (*original_node)[static_cast<std::size_t>(node)];
    *original_node = std::move(previous);
    areas->push_back(area);
  }
  cracked.mirror_x0 = mesh.mirror_x0;
  cracked.mirror_y0 = mesh.mirror_y0;
  return cracked;
}

void check_options(const Simulation3dOptions& options) {
  if (!(options.depth > 0.0) || !std::isfinite(options.depth))
    throw InputError("simulate_3d: depth must be positive");
  if (options.steps < 1) throw InputError("simulate_3d: steps must be >= 1");
  if (options.overrides.steps && *options.overrides.steps < 1)
    throw InputError("simulate_3d: overrides.steps must be >= 1");
  if (options.overrides.domain_scale &&
      (!(*options.overrides.domain_scale > 0.0) || !std::isfinite(*options.overrides.domain_scale)))
    throw InputError("simulate_3d: overrides.domain_scale must be positive");
  if (!(options.stress_average_length_m >= 0.0) || !std::isfinite(options.stress_average_length_m))
    throw InputError("simulate_3d: stress_average_length_m must be >= 0");
  if (!(options.crack_depth_m >= 0.0) || !std::isfinite(options.crack_depth_m))
    throw InputError("simulate_3d: crack_depth_m must be >= 0");
}

}  // namespace

Simulation3dResult simulate_3d(TissueBlockSpec block, const std::vector<Needle3d>& all_needles,
                               const Simulation3dOptions& options) {
  check_options(options);
  const auto start = Clock::now();
  const MirrorSelection selection =
      select_mirrored_part(all_needles, options.mirror_x, options.half_model);
  const std::vector<Needle3d>& needles = selection.kept;
  // (A needle symmetric about x = 0 touches first on its axis, so its crack is there too.)
  if (options.mirror_x && options.crack_depth_m > 0.0)
    for (const Needle3d& needle : needles)
      if (needle.x == 0.0)
        throw InputError("simulate_3d: needle '" + needle.name +
                         "': its crack (normal x) would lie on the mirror plane x = 0 (use the "
                         "model without the x mirror)");
  // The grid is the whole scene's, so a reduced model meshes exactly its share of it.
  block.sites.clear();
  std::vector<Eigen::Vector2d> tips;  // first contact points of the whole scene's needles
  for (const Needle3d& needle : all_needles) {
    const NeedleShape shape(needle.mesh);
    const Eigen::Vector2d axis(needle.x, needle.y);
    tips.push_back(axis + shape.first_contact_xy(1e-9));
    fe::NeedleSite site{needle.x, needle.y, shape.max_radius_up_to(options.depth), std::nullopt};
    if ((tips.back() - axis).norm() > 1e-3 * site.radius) site.tip = tips.back();
    for (const Eigen::Vector2d& corner : shape.first_contact_outline(1e-9))
      site.first_contact.push_back(axis + corner);
    // Lowest vertices within 1 nm of each other, over less than kPointContactPerRadius of the
    // radius and with no face among them, are one rounded point (a rounded tip's finely spaced
    // vertices), not a flat (docs/model.md, "Tissue block and mesh").
    double extent = 0.0;
    for (const Eigen::Vector2d& a : site.first_contact)
      for (const Eigen::Vector2d& b : site.first_contact) extent = std::max(extent, (a - b).norm());
    if (site.first_contact.size() > 1 && extent < kPointContactPerRadius * site.radius &&
        !shape.first_contact_has_a_face(1e-9))
      site.first_contact = {tips.back()};
    block.sites.push_back(site);
  }
  std::vector<Eigen::Vector2d> first_contact;  // of the kept needles
  for (std::size_t i : selection.kept_from) first_contact.push_back(tips[i]);
  block.fidelity = options.fidelity;
  block.order = options.overrides.order.value_or(options.order);
  block.insertion_depth = options.depth;
  block.overrides = options.overrides;
  block.criterion_length = options.stress_average_length_m;
  block.half_x = options.mirror_x;
  block.half_y = options.half_model;
  if (options.overrides.domain_scale) {
    block.size_x *= *options.overrides.domain_scale;
    block.size_y *= *options.overrides.domain_scale;
  }
  const int steps = options.overrides.steps.value_or(options.steps);
  const TetMesh mesh = generate_tissue_mesh(block);
  std::vector<double> crack_areas;
  TetMesh cracked;
  std::vector<int> original_node;
  std::vector<CrackFacePair> face_pairs;
  if (options.crack_depth_m > 0.0)
    cracked = cracked_copy(mesh, needles, first_contact, options.crack_depth_m, &crack_areas,
                           &original_node, &face_pairs);
  const double meshing = seconds_since(start);

  Simulation3dResult result;
  result.nodes = static_cast<int>(mesh.nodes.size());
  result.elements = static_cast<int>(mesh.elements.size());
  result.order = mesh.order;
  result.quality = mesh_quality(mesh);
  result.contact_zone_m = mesh.contact_zone_m;
  result.unresolved_flats = mesh.unresolved_flats;
  if (options.on_mesh) options.on_mesh(result);
  Indentation3dOptions solver_options;
  solver_options.contact = options.contact;
  if (options.overrides.tolerance) solver_options.tolerance = *options.overrides.tolerance;
  Indentation3d run(mesh, needles, options.depth, solver_options);
  std::unique_ptr<Indentation3d> cracked_run;
  if (options.crack_depth_m > 0.0)
    cracked_run = std::make_unique<Indentation3d>(cracked, needles, options.depth, solver_options);
  // With sticking contact the cracked twin holds the intact run's captured nodes: left to its
  // own search it captures a different set and U_intact - U_cracked loses its sign.
  if (cracked_run && options.contact == ContactMode::Sticking)
    cracked_run->hold_contact_of(run, std::move(original_node));
  if (cracked_run) cracked_run->set_crack_faces(std::move(face_pairs), options.crack_face_contact);
  // Every mirror image of the meshed part holds the same cracks.
  const double whole = (mesh.mirror_x0 ? 2.0 : 1.0) * (mesh.mirror_y0 ? 2.0 : 1.0);
  double total_crack_area = 0.0;
  for (double a : crack_areas) total_crack_area += whole * a;
  if (cracked_run && !(total_crack_area > 0.0))
    throw SolverError("simulate_3d: the crack opened no mesh face (crack_depth_m too small?)");
  std::vector<PvdEntry> collection;
  if (!options.vtu_directory.empty()) {
    create_output_folder(options.vtu_directory, "--vtu");
    clear_step_files(options.vtu_directory);
  }
  // The stress criterion's probe searches the top layer within the needle's outline at the
  // tip's depth plus two averaging lengths (docs/model.md, "Criteria", stress).
  std::optional<PeakStressProbe> stress_probe;
  double stress_seconds = 0.0;
  // Both runs' phases: the cracked twin factorises and assembles as often as the intact run.
  const auto runs_timing = [&] {
    Timing3d timing = run.timing();
    if (cracked_run) {
      const Timing3d& twin = cracked_run->timing();
      timing.assembly_s += twin.assembly_s;
      timing.factorization_s += twin.factorization_s;
      timing.contact_s += twin.contact_s;
      timing.factorizations += twin.factorizations;
      timing.shifted_factorizations += twin.shifted_factorizations;
    }
    return timing;
  };
  // A run that ends by an exception from here on still says what its phases cost
  // (Simulation3dOptions::on_stop_timing); a finished one sets result.timing instead.
  bool finished = false;
  struct OnExit {
    std::function<void()> call;
    ~OnExit() { call(); }
  } timing_on_stop{[&] {
    if (finished || !options.on_stop_timing) return;
    Timing3d timing = runs_timing();
    timing.meshing_s = meshing;
    timing.stress_s = stress_seconds;
    timing.total_s = seconds_since(start);
    options.on_stop_timing(timing);
  }};
  std::vector<NeedleShape> probe_shapes;
  const double stress_length = options.stress_average_length_m;
  const auto search_radii = [&](double depth) {
    std::vector<double> radii;
    for (const NeedleShape& shape : probe_shapes)
      radii.push_back(shape.max_radius_up_to(depth) + 2.0 * stress_length);
    return radii;
  };
  if (stress_length > 0.0) {
    std::vector<Eigen::Vector2d> axes;
    for (const Needle3d& needle : needles) {
      probe_shapes.emplace_back(needle.mesh);
      axes.emplace_back(needle.x, needle.y);
    }
    const std::vector<double> radii = search_radii(options.depth);
    // Centres as deep as the tip can reach plus the search radius: the needle presses the layer
    // no deeper than that (in reference coordinates), and a thick layer's probe stays small.
    const double search_depth = options.depth + *std::max_element(radii.begin(), radii.end());
    const auto probe_start = Clock::now();
    stress_probe.emplace(mesh, std::move(axes), radii, search_depth, stress_length, 0);
    stress_seconds += seconds_since(probe_start);
    // The probe reads its elements' nodes only: their rows of the compliance columns are kept, so
    // no step solves for the whole field (docs/performance.md, "The stress criterion's cost").
    run.watch_nodes(stress_probe->nodes());
  }
  // The probe's tip stress of one depth from the watched nodes' displacement.
  const auto probe_step = [&](Step3d& step, double depth, const Eigen::VectorXd& watched) {
    const auto probe_start = Clock::now();
    Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(mesh.nodes.size()));
    const std::vector<int>& probed = stress_probe->nodes();
    for (std::size_t w = 0; w < probed.size(); ++w)
      u.segment<3>(3 * probed[w]) = watched.segment<3>(3 * static_cast<Eigen::Index>(w));
    const std::vector<double> peak = stress_probe->peak(u, search_radii(depth));
    for (std::size_t n = 0; n < needles.size(); ++n) step.needles[n].tip_stress_Pa = peak[n];
    stress_seconds += seconds_since(probe_start);
  };
  // The watched nodes' displacement at the last depth, its cost counted as the probe's.
  const auto timed_watched = [&]() {
    const auto read_start = Clock::now();
    Eigen::VectorXd watched = run.watched_displacement();
    stress_seconds += seconds_since(read_start);
    return watched;
  };
  // Once the watched rows cost a back substitution per depth (a flat face's many captures), the
  // rest of the depths are advanced first and read in one back substitution of several columns:
  // the factor is streamed once instead of once per depth (docs/performance.md, "The stress
  // criterion's cost"). Advancing past the crossing costs contact-block solves only. Not where a
  // depth writes files or a cracked twin advances in lock-step.
  const bool look_ahead =
      stress_probe && !cracked_run && options.vtu_directory.empty() && options.inp_path.empty();
  bool vtu_past = false;  // a step at or beyond vtu_depth_m was written
  for (int k = 1; k <= steps; ++k) {
    const double depth = options.depth * k / steps;
    Step3d step = run.advance_to(depth);
    if (look_ahead && run.watched_by_back_solve()) {
      // Each depth's watched rows: a column of `loads` for the back substitution, or (were the
      // rows kept again) read at once.
      std::vector<Step3d> ahead;
      std::vector<double> depths;
      std::vector<Eigen::Index> column;  // -1: read at once, into `direct`
      std::vector<Eigen::VectorXd> direct;
      Eigen::MatrixXd loads(run.watched_trailing_loads().size(), steps - k + 1);
      Eigen::Index used = 0;
      // Recorded only once its rows are in hand, so a failure leaves the lists aligned.
      const auto collect = [&](Step3d advanced, double at) {
        Eigen::Index at_column = -1;
        Eigen::VectorXd read;
        if (run.watched_by_back_solve()) {
          loads.col(used) = run.watched_trailing_loads();
          at_column = used++;
        } else {
          read = timed_watched();
        }
        ahead.push_back(std::move(advanced));
        depths.push_back(at);
        column.push_back(at_column);
        direct.push_back(std::move(read));
      };
      collect(std::move(step), depth);
      // A depth past the caller's stop must not end the run: its failure is kept and raised
      // only if the caller asks for that depth.
      std::exception_ptr failed;
      for (int j = k + 1; j <= steps && !failed; ++j) {
        const double next = options.depth * j / steps;
        try {
          collect(run.advance_to(next), next);
        } catch (const std::exception&) {
          failed = std::current_exception();
        }
      }
      const auto solve_start = Clock::now();
      const Eigen::MatrixXd watched = run.watched_displacements(loads.leftCols(used));
      stress_seconds += seconds_since(solve_start);
      bool stopped = false;
      for (std::size_t i = 0; i < ahead.size() && !stopped; ++i) {
        probe_step(ahead[i], depths[i],
                   column[i] >= 0 ? Eigen::VectorXd(watched.col(column[i])) : direct[i]);
        result.steps.push_back(whole_scene_step(ahead[i], selection, all_needles));
        stopped = options.on_step && !options.on_step(result.steps.back());
      }
      if (failed && !stopped) std::rethrow_exception(failed);
      break;
    }
    if (stress_probe) probe_step(step, depth, timed_watched());
    if (cracked_run) {
      const Step3d opened = cracked_run->advance_to(depth);
      const double release = (step.strain_energy_J - opened.strain_energy_J) / total_crack_area;
      step.crack_face_overlap_m = opened.crack_face_overlap_m;
      step.crack_face_contacts = opened.crack_face_contacts;
      for (std::size_t n = 0; n < needles.size(); ++n) {
        step.needles[n].energy_release_rate_J_per_m2 = release;
        step.needles[n].crack_area_m2 =
            (needles[n].y == 0.0 && mesh.mirror_y0 ? 2.0 : 1.0) * crack_areas[n];
      }
    }
    const bool written = !options.vtu_directory.empty() && !vtu_past;
    if (options.vtu_depth_m > 0.0 && depth >= options.vtu_depth_m * (1.0 - 1e-12)) vtu_past = true;
    if (written) {
      const std::filesystem::path dir(options.vtu_directory);
      const std::string tissue = "step_" + std::to_string(k) + ".vtu",
                        needles_file = "needles_" + std::to_string(k) + ".vtu";
      run.write_vtu((dir / tissue).string(), depth, options.vtu_comment);
      VtuFile surfaces = needles_vtu(all_needles, depth);
      surfaces.comment = options.vtu_comment;
      write_vtu((dir / needles_file).string(), surfaces);
      collection.push_back({depth, 0, tissue});
      collection.push_back({depth, 1, needles_file});
      write_pvd((dir / "steps.pvd").string(), collection, options.vtu_comment);
    }
    if (!options.inp_path.empty() && depth <= options.inp_depth_m * (1.0 + 1e-12))
      result.exported = run.write_inp(options.inp_path, options.inp_comment);
    result.steps.push_back(whole_scene_step(step, selection, all_needles));
    if (options.on_step && !options.on_step(result.steps.back())) break;
  }
  finished = true;
  result.timing = runs_timing();
  result.timing.meshing_s = meshing;
  result.timing.stress_s = stress_seconds;
  result.timing.total_s = seconds_since(start);
  result.solver_backend = run.solver_backend();
  return result;
}

}  // namespace mneedle::fe
