// Plane-strain insertion along a cut (paper C §6, docs/model.md "Plane-strain insertion"): a
// graded grid of bilinear rectangles, factorised once; the contact of the cut's nodes with the
// needle (frictionless tip, Coulomb shaft) and with their mirror image solved step by step on the
// cut's compliance by an active set.
#include "mneedle/fe/plane_strain_insertion.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/fe/sparse_solver.h"
#include "plane_strain_element.h"

namespace mneedle::fe {
namespace {

// A node counts as inside the needle (or its mirror) beyond this fraction of w, and a contact
// force as tensile beyond this fraction of the largest force: round-off must not toggle a node.
constexpr double kGapTolerance = 1e-9;
constexpr double kForceTolerance = 1e-10;
// An arc node's normal has converged when it moves by less than this (unit vectors): the gap
// error is then of order rho * 1e-12, the force's direction off by 1e-6. The update converges
// linearly (ratio up to 0.95 on paper C's shoulder), so a tighter value costs hundreds of solves.
constexpr double kNormalTolerance = 1e-6;
// A cohesive node's secant has converged when it moves by less than this fraction of the law's
// initial stiffness.
constexpr double kSecantTolerance = 1e-9;
// With viscosity the damage approaches 1 geometrically: a cell counts as failed (and is removed)
// within this much of it.
constexpr double kFailedDamage = 1e-3;

[[noreturn]] void bad(const std::string& field, const std::string& what) {
  throw InputError("plane-strain insertion: " + field + " " + what);
}

double element_size(const PlaneStrainInsertionProblem& p) {
  return p.element_size_m > 0.0 ? p.element_size_m : p.needle_width_m / 8.0;
}
double uniform_zone(const PlaneStrainInsertionProblem& p) {
  const double zone = p.uniform_zone_m > 0.0 ? p.uniform_zone_m : 4.0 * p.needle_width_m;
  return std::min(zone, 0.5 * p.block_width_m);
}
double shoulder_radius(const PlaneStrainInsertionProblem& p) {
  return p.shoulder_radius_m > 0.0 ? p.shoulder_radius_m : 0.25 * p.needle_width_m;
}
double tip_length(const PlaneStrainInsertionProblem& p) {
  return 0.5 * p.needle_width_m / std::tan(0.5 * p.tip_angle_rad);
}

void check(const PlaneStrainInsertionProblem& p) {
  auto positive = [](const char* field, double v) {
    if (!std::isfinite(v) || v <= 0.0) bad(field, "must be positive and finite, got " + str(v));
  };
  positive("youngs_modulus_Pa", p.youngs_modulus_Pa);
  if (!std::isfinite(p.poisson_ratio) || p.poisson_ratio < 0.0 || p.poisson_ratio >= 0.5)
    bad("poisson_ratio", "must be in [0, 0.5), got " + str(p.poisson_ratio));
  positive("block_width_m", p.block_width_m);
  positive("block_depth_m", p.block_depth_m);
  positive("thickness_m", p.thickness_m);
  positive("needle_width_m", p.needle_width_m);
  if (!std::isfinite(p.tip_angle_rad) || p.tip_angle_rad <= 0.0 ||
      p.tip_angle_rad >= std::numbers::pi)
    bad("tip_angle_rad", "must be in (0, pi), got " + str(p.tip_angle_rad));
  // Above 0.6 the sliding state's assumption (the cut faces slip up along the needle) fails:
  // stick and slip cycle and the contact set does not settle (measured at 0.7 and above on
  // paper C's case; docs/model.md, "Plane-strain insertion along a cut").
  if (!std::isfinite(p.friction_coefficient) || p.friction_coefficient < 0.0 ||
      p.friction_coefficient > kInsertionMaxFriction)
    bad("friction_coefficient",
        "must be in [0, " + str(kInsertionMaxFriction) + "], got " + str(p.friction_coefficient));
  positive("travel_m", p.travel_m);
  const CohesiveLaw& c = p.cohesion;
  if (!std::isfinite(c.toughness_J_per_m2) || c.toughness_J_per_m2 < 0.0)
    bad("cohesion.toughness_J_per_m2",
        "must be finite and not negative, got " + str(c.toughness_J_per_m2));
  if (c.toughness_J_per_m2 > 0.0) {
    if (!std::isfinite(c.peak_opening_m) || c.peak_opening_m <= 0.0)
      bad("cohesion.peak_opening_m", "must be positive and finite, got " + str(c.peak_opening_m));
    if (!std::isfinite(c.failure_opening_m) || c.failure_opening_m <= c.peak_opening_m)
      bad("cohesion.failure_opening_m", "must be finite and above peak_opening_m " +
                                            str(c.peak_opening_m) + " m, got " +
                                            str(c.failure_opening_m));
    if (!std::isfinite(c.initial_cut_m) || c.initial_cut_m < 0.0 ||
        c.initial_cut_m >= p.block_depth_m)
      bad("cohesion.initial_cut_m", "must be in [0, block_depth_m), got " + str(c.initial_cut_m));
    if (!std::isfinite(c.viscosity_m) || c.viscosity_m < 0.0)
      bad("cohesion.viscosity_m", "must be finite and not negative, got " + str(c.viscosity_m));
  }
  if (!std::isfinite(p.shoulder_radius_m) || p.shoulder_radius_m < 0.0 ||
      p.shoulder_radius_m > 0.25 * p.needle_width_m)
    bad("shoulder_radius_m",
        "must be in (0, needle_width_m / 4] (or 0 for w / 4), got " + str(p.shoulder_radius_m));
  if (p.travel_m > 2.0 * p.block_depth_m)
    bad("travel_m",
        str(p.travel_m) + " m is more than twice block_depth_m " + str(p.block_depth_m) + " m");
  if (p.block_width_m < 4.0 * p.needle_width_m)
    bad("block_width_m", str(p.block_width_m) + " m is less than 4 needle widths (" +
                             str(4.0 * p.needle_width_m) + " m)");
  for (const auto& [field, v] :
       {std::pair{"element_size_m", p.element_size_m}, std::pair{"step_m", p.step_m},
        std::pair{"uniform_zone_m", p.uniform_zone_m}})
    if (!std::isfinite(v) || v < 0.0)
      bad(field, "must be positive (or 0 for the default), got " + str(v));
  const double h_requested = element_size(p);
  if (p.uniform_zone_m != 0.0 && p.uniform_zone_m < h_requested)
    bad("uniform_zone_m", str(p.uniform_zone_m) + " m is below the cell size " + str(h_requested) +
                              " m (0 for the default)");
  // The cells along the cut divide the depth evenly: at most the requested size.
  const double h = p.block_depth_m / std::ceil(p.block_depth_m / h_requested - 1e-9);
  if (h > p.needle_width_m / 4.0)
    bad("element_size_m", str(h) + " m leaves fewer than 2 cells across the needle's half width " +
                              str(0.5 * p.needle_width_m) + " m");
  if (h > 0.5 * tip_length(p))
    bad("element_size_m", str(h) + " m leaves fewer than 2 cells along the tip's length " +
                              str(tip_length(p)) + " m");
  if (c.toughness_J_per_m2 > 0.0) {
    // The cohesive zone must be resolved: Hillerborg's length E G_c / sigma_max^2 (the scale of
    // the process zone) at least kInsertionMinCellsPerCohesiveLength cells, or the puncture
    // depth follows the mesh (docs/model.md, "Cohesive interface").
    const double peak = cohesive_peak_traction(c);
    const double length = p.youngs_modulus_Pa * c.toughness_J_per_m2 / (peak * peak);
    if (length < kInsertionMinCellsPerCohesiveLength * h)
      bad("element_size_m",
          str(h) + " m does not resolve the cohesive length E G_c / sigma_max^2 = " + str(length) +
              " m: at most " + str(length / kInsertionMinCellsPerCohesiveLength) + " m");
  }
  const double step = p.step_m > 0.0 ? p.step_m : kInsertionDefaultStepFraction * h;
  if (step > h)
    bad("step_m", str(step) + " m is longer than a cell (" + str(h) +
                      " m): a cut node would cross the tip within one step");
  // Counted before anything is allocated: a tiny size must not start unbounded work.
  const double cut = std::ceil(p.block_depth_m / h) + 1.0;
  if (cut > kInsertionMaxCutNodes)
    bad("element_size_m", str(h) + " m puts " + str(cut) + " nodes on the cut, more than " +
                              str(kInsertionMaxCutNodes));
  const double zone = uniform_zone(p);
  const double across =
      std::ceil(zone / h) + graded_count(0.5 * p.block_width_m - zone, h, kInsertionGridGrowth) + 1;
  if (across * cut > kInsertionMaxNodes)
    bad("element_size_m", str(h) + " m would need about " + str(across * cut) +
                              " nodes, more than the limit " + str(kInsertionMaxNodes));
  if (std::ceil(p.travel_m / step) > kInsertionMaxSteps)
    bad("step_m", str(step) + " m would need more than " + str(kInsertionMaxSteps) + " steps");
}

struct Grid {
  std::vector<double> x;  // 0 (the cut) .. width/2
  std::vector<double> y;  // 0 (top) .. -depth
  int nx() const { return static_cast<int>(x.size()); }
  int ny() const { return static_cast<int>(y.size()); }
  int node(int i, int j) const { return j * nx() + i; }
};

Grid make_grid(const PlaneStrainInsertionProblem& p) {
  Grid g;
  const double zone = uniform_zone(p);
  const int n = static_cast<int>(std::ceil(zone / element_size(p) - 1e-9));
  const double hx = zone / n;
  for (int i = 0; i <= n; ++i) g.x.push_back(zone * i / n);
  if (zone < 0.5 * p.block_width_m)
    append_graded(g.x, zone, 0.5 * p.block_width_m, hx, kInsertionGridGrowth);
  const int m = static_cast<int>(std::ceil(p.block_depth_m / element_size(p) - 1e-9));
  for (int j = 0; j <= m; ++j) g.y.push_back(-p.block_depth_m * j / m);
  return g;
}

// Contact states of a cut node. Slide: on the needle's smooth outline (flank, shoulder arc,
// shaft), held along the outline's normal through the node and sliding against mu(n) N (zero on
// the flank, the tip being frictionless; mu on the shaft; growing along the arc). Stick: on the
// shaft, moving with the needle. Apex: held at the tip, where the flank meets the mirror plane;
// its force may point anywhere between the two normals (a node ahead of the tip meets it there).
// Bonded: held to its mirror image by the cohesive law (traction along x only).
enum class State { Free, Mirror, Bonded, Slide, Apex, Stick };
bool on_needle(State s) {
  return s == State::Slide || s == State::Apex || s == State::Stick;
}

// The block: stiffness factorised once, and the compliance of the cut's dofs.
class Block {
 public:
  explicit Block(const PlaneStrainInsertionProblem& p) : grid_(make_grid(p)) {
    const int nx = grid_.nx(), ny = grid_.ny();
    const int dofs = 2 * nx * ny;
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(64) * (nx - 1) * (ny - 1));
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        // The rectangle's node order (0,0), (hx,0), (hx,hy), (0,hy) with y up: row j+1 is below.
        const Eigen::Matrix<double, 8, 8> k = plane_strain_rectangle_stiffness(
            grid_.x[i + 1] - grid_.x[i], grid_.y[j] - grid_.y[j + 1], p.youngs_modulus_Pa,
            p.poisson_ratio);
        const std::array<int, 4> n{grid_.node(i, j + 1), grid_.node(i + 1, j + 1),
                                   grid_.node(i + 1, j), grid_.node(i, j)};
        for (int a = 0; a < 8; ++a)
          for (int b = 0; b < 8; ++b)
            t.emplace_back(2 * n[a / 2] + a % 2, 2 * n[b / 2] + b % 2, k(a, b));
      }
    Eigen::SparseMatrix<double> K(dofs, dofs);
    K.setFromTriplets(t.begin(), t.end());
    fixed_.assign(dofs, 0);
    for (int j = 0; j < ny; ++j)
      for (int c = 0; c < 2; ++c) fixed_[2 * grid_.node(nx - 1, j) + c] = 1;  // pinned side
    for (int i = 0; i < nx; ++i) fixed_[2 * grid_.node(i, ny - 1) + 1] = 1;   // bottom rollers
    // Supports as unit rows and columns: the loads below are zero on them, so they stay zero.
    for (Eigen::Index col = 0; col < K.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
        if (fixed_[it.row()] || fixed_[col]) it.valueRef() = it.row() == col ? 1.0 : 0.0;
    K.makeCompressed();
    solver_.factorize(K);
    if (!solver_.ok())
      throw SolverError("plane-strain insertion: the stiffness matrix could not be factorised");
  }

  const Grid& grid() const { return grid_; }
  bool y_fixed(int j) const { return fixed_[2 * grid_.node(0, j) + 1] != 0; }

  // C(2j + c, 2k + d): u_c of cut node j under a unit force d on cut node k (0 on supports).
  Eigen::MatrixXd cut_compliance() const {
    const int m = 2 * grid_.ny();
    constexpr int kBlock = 64;
    Eigen::MatrixXd C(m, m);
    for (int first = 0; first < m; first += kBlock) {
      const int b = std::min(kBlock, m - first);
      Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(fixed_.size(), b);
      for (int k = 0; k < b; ++k) {
        const int dof = 2 * grid_.node(0, (first + k) / 2) + (first + k) % 2;
        if (!fixed_[dof]) rhs(dof, k) = 1.0;
      }
      const Eigen::MatrixXd u = solver_.solve_many(rhs);
      for (int r = 0; r < m; ++r) {
        const int dof = 2 * grid_.node(0, r / 2) + r % 2;
        if (fixed_[dof])
          C.block(r, first, 1, b).setZero();
        else
          C.block(r, first, 1, b) = u.block(dof, 0, 1, b);
      }
    }
    return C;
  }

 private:
  Grid grid_;
  std::vector<char> fixed_;
  SparseSolver solver_;
};

}  // namespace

PlaneStrainInsertionResult simulate_plane_strain_insertion(const PlaneStrainInsertionProblem& p) {
  check(p);
  const Block block(p);
  const Grid& g = block.grid();
  const Eigen::MatrixXd C = block.cut_compliance();
  const int m = g.ny();
  const double w2 = 0.5 * p.needle_width_m;
  const double mu = p.friction_coefficient;
  const double half_angle = 0.5 * p.tip_angle_rad;
  // The right flank: tangent from the tip towards the shoulder, outward normal into the block.
  const Eigen::Vector2d tangent(std::sin(half_angle), std::cos(half_angle));
  const Eigen::Vector2d flank_normal(std::cos(half_angle), -std::sin(half_angle));
  const double gap_tol = kGapTolerance * p.needle_width_m;
  const double scale = 2.0 * p.thickness_m;  // half model per metre -> whole block
  // The shoulder: an arc of radius rho about `centre` (relative to the apex), tangent to the
  // flank at arc_start (along the flank) and to the shaft, which starts at height centre.y().
  const double rho = shoulder_radius(p);
  const Eigen::Vector2d centre(w2 - rho,
                               (std::cos(half_angle) * (w2 - rho) + rho) / std::sin(half_angle));
  const double arc_start = tangent.dot(centre);
  // Friction along the outline grows with the normal's turn from the flank's (0: the tip is
  // frictionless) to the shaft's (mu): a jump in mu where two faces meet would trap a node there,
  // dragged down by friction on one side and sliding up frictionless on the other.
  auto friction_of = [&](const Eigen::Vector2d& n) {
    const double turn = std::atan2(n.y(), n.x()) + half_angle;
    return mu * std::clamp(turn / half_angle, 0.0, 1.0);
  };

  // The cohesive law, per cut node: its share L_j of the cut's length, whether it is bonded at all
  // (below the initial cut), the largest opening it has reached (history) and the secant
  // stiffness t(delta)/delta of the current iterate, so that its force on the half model is
  // f_x = -2 L_j s_j u_x (the opening delta = 2 u_x: both halves move apart).
  const CohesiveLaw& law = p.cohesion;
  const bool cohesive = law.toughness_J_per_m2 > 0.0;
  const double peak_traction = cohesive_peak_traction(law);
  std::vector<double> share(m, 0.0), opened(m, 0.0), secant(m, 0.0), damage(m, 0.0);
  const double stiffness0 = cohesive ? peak_traction / law.peak_opening_m : 0.0;
  // The law's damage at the largest opening reached: t = (1 - D) K delta on unloading.
  auto law_damage = [&](double reached) { return cohesive_damage(law, reached); };
  double relax = 0.0;  // travel of this step over the viscosity (0: none)
  std::vector<char> bonded(m, 0);
  for (int j = 0; j < m; ++j) {
    share[j] =
        0.5 * ((j > 0 ? g.y[j - 1] - g.y[j] : 0.0) + (j + 1 < m ? g.y[j] - g.y[j + 1] : 0.0));
    bonded[j] = cohesive && -g.y[j] > law.initial_cut_m + 1e-12 * p.block_depth_m;
    if (bonded[j]) secant[j] = peak_traction / law.peak_opening_m;
  }
  // The secant at the opening delta with the node's history: loading along the envelope,
  // unloading to the origin from the largest opening reached.
  // With a viscosity eta (travel), the damage relaxes towards the law's over the step:
  // D = (D_old + r D_law) / (1 + r), r = step / eta (backward Euler; Abaqus's viscous
  // regularisation, with the needle's travel as time).
  auto secant_at = [&](int j, double delta) {
    const double reached = std::max(delta, opened[j]);
    const double d_law = law_damage(reached);
    const double d = law.viscosity_m > 0.0 ? (damage[j] + relax * d_law) / (1.0 + relax) : d_law;
    return (1.0 - d) * stiffness0;
  };
  auto holding = [&](int j) { return bonded[j] && secant[j] > 0.0; };

  PlaneStrainInsertionResult out;
  out.nodes = g.nx() * g.ny();
  out.elements = (g.nx() - 1) * (g.ny() - 1);
  out.cut_nodes = m;
  out.element_size_m = -g.y[1];
  out.step_m = p.step_m > 0.0 ? p.step_m : kInsertionDefaultStepFraction * out.element_size_m;
  out.tip_length_m = tip_length(p);
  out.shoulder_radius_m = rho;
  const int steps = static_cast<int>(std::ceil(p.travel_m / out.step_m - 1e-9));
  out.steps.reserve(steps + 1);
  out.steps.push_back({});
  if (cohesive) out.steps[0].crack_depth_m = law.initial_cut_m;

  std::vector<State> state(m, State::Free);
  for (int j = 0; j < m; ++j)
    if (bonded[j]) state[j] = State::Bonded;
  // A sliding node's face (2 shaft, 3 arc, 1 flank) and normal, fixed for a solve and updated
  // from its new position until they stop changing.
  std::vector<int> face_of(m, 1);
  std::vector<Eigen::Vector2d> normal_of(m, flank_normal);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(2 * m), u = Eigen::VectorXd::Zero(2 * m);
  // Softening cohesion adds secant iterations: a crack running through many cells in one step
  // fails them one after another.
  const int max_iterations = cohesive ? 50 + 20 * m : 50 + 4 * m;
  for (int s = 1; s <= steps; ++s) {
    const double travel = std::min(p.travel_m, s * out.step_m);
    const double dd = travel - out.steps.back().travel_m;
    const Eigen::Vector2d apex(0.0, -travel);
    const Eigen::VectorXd f_prev = f, u_prev = u;
    const std::vector<double> secant_prev = secant;
    relax = law.viscosity_m > 0.0 ? dd / law.viscosity_m : 0.0;
    const std::vector<State> state_prev = state;
    // Which face of the outline a node at (ux, Y + uy) faces (2 shaft, 3 arc, 1 flank, 0 below
    // the tip), that face's outward normal there and the node's gap to it.
    struct Facing {
      int face;
      Eigen::Vector2d normal;
      double gap;
    };
    auto facing = [&](int j, double ux, double uy) -> Facing {
      const Eigen::Vector2d q = Eigen::Vector2d(ux, g.y[j] + uy) - apex;
      if (q.y() >= centre.y()) return {2, Eigen::Vector2d::UnitX(), ux - w2};
      if (tangent.dot(q) >= arc_start) {
        const Eigen::Vector2d d = q - centre;
        const double r = d.norm();
        return {3, d / r, r - rho};
      }
      if (q.y() >= 0.0) return {1, flank_normal, flank_normal.dot(q)};
      return {0, Eigen::Vector2d::UnitX(), std::numeric_limits<double>::infinity()};
    };
    auto start_sliding = [&](int j, const Facing& at) {
      state[j] = State::Slide;
      face_of[j] = at.face;
      normal_of[j] = at.normal;
    };
    // The apex moves with the needle: a node held there at the last step now lies beside the
    // flank that trails it.
    for (int j = 0; j < m; ++j)
      if (state[j] == State::Apex) start_sliding(j, {1, flank_normal, 0.0});
    std::vector<int> apex_visits(m, 0), face_changes(m, 0);
    std::vector<double> relaxation(m, 1.0), last_turn(m, 0.0);
    int iterations = 0;
    for (;;) {
      if (iterations == max_iterations)
        throw SolverError("plane-strain insertion: the contact set did not settle at travel " +
                          str(travel * 1e3) + " mm in " + std::to_string(max_iterations) +
                          " active-set iterations");
      ++iterations;
      std::vector<int> act;
      for (int j = 0; j < m; ++j)
        if (state[j] != State::Free) act.push_back(j);
      const int a = static_cast<int>(act.size());
      std::vector<int> dof(2 * a);
      for (int k = 0; k < a; ++k) dof[2 * k] = 2 * act[k], dof[2 * k + 1] = 2 * act[k] + 1;
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * a, 2 * a);
      Eigen::VectorXd b = Eigen::VectorXd::Zero(2 * a);
      auto u_row = [&](int r) {  // the row giving cut dof r's displacement from the active forces
        Eigen::RowVectorXd row(2 * a);
        for (int c = 0; c < 2 * a; ++c) row[c] = C(r, dof[c]);
        return row;
      };
      for (int k = 0; k < a; ++k) {
        const int j = act[k];
        const int rx = 2 * k, ry = 2 * k + 1;
        const Eigen::Vector2d x0 = Eigen::Vector2d(0.0, g.y[j]) - apex;  // reference, from apex
        // The cohesive force the node also feels, f_coh,x = -coh u_x: the needle's force on it is
        // f - f_coh, so the needle's own conditions add coh u_x to f_x.
        const double coh = holding(j) ? 2.0 * share[j] * secant[j] : 0.0;
        switch (state[j]) {
          case State::Mirror:  // u_x = 0, frictionless
            A.row(rx) = u_row(2 * j);
            A(ry, ry) = 1.0;
            break;
          case State::Bonded:  // f_x = -coh u_x, no shear
            A.row(rx) = coh * u_row(2 * j);
            A(rx, rx) += 1.0;
            A(ry, ry) = 1.0;
            break;
          case State::Slide: {
            const Eigen::Vector2d& n = normal_of[j];
            const Eigen::Vector2d t(-n.y(), n.x());  // along the outline, towards the shaft
            // On the face's line through the node's normal: n . q = level.
            const double level = face_of[j] == 2 ? w2 : face_of[j] == 3 ? rho + n.dot(centre) : 0.0;
            A.row(rx) = n.x() * u_row(2 * j) + n.y() * u_row(2 * j + 1);
            b[rx] = level - n.dot(x0);
            // Along the outline: friction mu(n) N against the upward slip.
            const double k_f = friction_of(n);
            A.row(ry) = (t.x() + k_f * n.x()) * coh * u_row(2 * j);
            A(ry, rx) += t.x() + k_f * n.x();
            A(ry, ry) += t.y() + k_f * n.y();
            break;
          }
          case State::Apex:  // at the tip point
            A.row(rx) = u_row(2 * j);
            A.row(ry) = u_row(2 * j + 1);
            b[ry] = apex.y() - g.y[j];
            break;
          case State::Stick:  // on the shaft, moving with the needle
            A.row(rx) = u_row(2 * j);
            b[rx] = w2;
            A.row(ry) = u_row(2 * j + 1);
            b[ry] = u_prev[2 * j + 1] - dd;
            break;
          case State::Free:
            break;
        }
      }
      f.setZero();
      if (a > 0) {
        const Eigen::VectorXd x = A.partialPivLu().solve(b);
        if (!x.allFinite())
          throw SolverError("plane-strain insertion: singular contact system at travel " +
                            str(travel * 1e3) + " mm");
        for (int c = 0; c < 2 * a; ++c) f[dof[c]] = x[c];
      }
      u = C * f;
      const double force_tol = kForceTolerance * std::max(f.cwiseAbs().maxCoeff(), 1e-300);
      bool changed = false;
      for (int j = 0; j < m; ++j) {
        // fx: the needle's (or the mirror's) share of the node's force, cohesion taken out.
        const double ux = u[2 * j], uy = u[2 * j + 1], fy = f[2 * j + 1];
        const double fx = f[2 * j] + (holding(j) ? 2.0 * share[j] * secant[j] * ux : 0.0);
        const Facing at = facing(j, ux, uy);
        const State before = state[j];
        if (bonded[j]) {
          // The secant through this iterate's opening (a fixed point: a crack that runs fails
          // its cells one after another within the step).
          const double s_new = secant_at(j, 2.0 * std::max(ux, 0.0));
          if (std::abs(s_new - secant[j]) >
              kSecantTolerance * (peak_traction / law.peak_opening_m)) {
            secant[j] = s_new;
            changed = true;
          }
        }
        switch (state[j]) {
          case State::Free:
          case State::Mirror:
          case State::Bonded:
            if (at.gap < -gap_tol)
              start_sliding(j, at);
            else if (state[j] != State::Mirror && ux < -gap_tol)
              state[j] = State::Mirror;
            else if (state[j] == State::Mirror && fx < -force_tol)
              state[j] = holding(j) ? State::Bonded : State::Free;
            else if (state[j] == State::Bonded && !holding(j))
              state[j] = State::Free;
            break;
          case State::Slide: {
            const double lambda = normal_of[j].dot(Eigen::Vector2d(fx, fy));
            // Relative slip of the node along the shaft over the step (positive: the node moves
            // up relative to the needle, as the friction force -mu N assumes).
            const double rel = (uy - u_prev[2 * j + 1]) + dd;
            if (lambda < -force_tol) {
              state[j] = holding(j) ? State::Bonded : State::Free;
            } else if (at.face == 0) {
              state[j] = State::Apex;
            } else if ((at.face != face_of[j] && face_changes[j] < 3) ||
                       (at.face == face_of[j] &&
                        (at.normal - normal_of[j]).norm() > kNormalTolerance)) {
              // The face and normal through the node's new position. Where the arc meets the
              // flank or the shaft the curvature jumps, so a node right at the junction can be
              // sent across it by either face's linearisation: after three changes of face in
              // a step it keeps the last (its normal is then the junction's to within the
              // step's slide, and its gap to the other face second order in it).
              // On the arc the update is relaxed where it overshoots: with friction the normal's
              // fixed point can oscillate (mu 1: +-0.09 rad, growing); a reversal of the turn
              // halves the node's relaxation factor.
              if (at.face == 3 && face_of[j] == 3) {
                const double from = std::atan2(normal_of[j].y(), normal_of[j].x());
                const double turn = std::atan2(at.normal.y(), at.normal.x()) - from;
                if (turn * last_turn[j] < 0.0)
                  relaxation[j] = std::max(1.0 / 64.0, 0.5 * relaxation[j]);
                last_turn[j] = turn;
                const double to = from + relaxation[j] * turn;
                normal_of[j] = Eigen::Vector2d(std::cos(to), std::sin(to));
              } else {
                normal_of[j] = at.normal;
              }
              face_changes[j] += at.face != face_of[j];
              face_of[j] = at.face;
              changed = true;
            } else if (at.face == 2 && mu > 0.0 && rel < -gap_tol && !block.y_fixed(j)) {
              state[j] = State::Stick;
            }
            break;
          }
          case State::Apex: {
            // f = a n + b e_x: a the flank's share, b the mirror plane's; both must push. A node
            // that has come back to the apex twice in this step stays there: its force leans
            // just past one normal while that face's own solution puts it beyond the apex (the
            // sharp vertex's discretisation; docs/model.md, "Plane-strain insertion along a cut").
            const double on_flank = -fy / std::sin(half_angle);  // fy: the needle's alone
            const double on_mirror = fx - on_flank * flank_normal.x();
            if (apex_visits[j] > 2) break;
            if (on_flank < -force_tol && on_mirror < -force_tol)
              state[j] = holding(j) ? State::Bonded : State::Free;
            else if (on_flank < -force_tol)
              state[j] = State::Mirror;
            else if (on_mirror < -force_tol)
              start_sliding(j, {1, flank_normal, 0.0});
            break;
          }
          case State::Stick:
            if (fx < -force_tol)
              state[j] = holding(j) ? State::Bonded : State::Free;
            else if (std::abs(fy) > mu * fx + force_tol)
              start_sliding(j, {2, Eigen::Vector2d::UnitX(), 0.0});
            break;
        }
        if (state[j] == State::Apex && before != State::Apex) ++apex_visits[j];
        changed = changed || state[j] != before;
      }
      if (!changed) {
        PlaneStrainInsertionStep st;
        st.travel_m = travel;
        st.active_set_iterations = iterations;
        double friction_work = 0.0, cohesive_work = 0.0, cohesive_stored = 0.0;
        // The needle's share of a node's x force at the end and at the start of the step.
        auto needle_fx = [&](const Eigen::VectorXd& ff, const Eigen::VectorXd& uu,
                             const std::vector<double>& ss, int j) {
          return ff[2 * j] + (bonded[j] ? 2.0 * share[j] * ss[j] * uu[2 * j] : 0.0);
        };
        for (int j = 0; j < m; ++j) {
          if (bonded[j]) {
            // Work into the interface, trapezoidal in the opening (exact on each linear branch),
            // and what it stores: half the model's share, times 2 t for the whole block.
            const double d0 = 2.0 * std::max(0.0, u_prev[2 * j]),
                         d1 = 2.0 * std::max(0.0, u[2 * j]);
            const double t0 = secant_prev[j] * d0, t1 = secant[j] * d1;
            cohesive_work += 0.5 * scale * share[j] * 0.5 * (t0 + t1) * (d1 - d0);
            cohesive_stored += 0.5 * scale * share[j] * 0.5 * t1 * d1;
          }
          const double fx = needle_fx(f, u, secant, j), fy = f[2 * j + 1];
          out.max_penetration_m =
              std::max({out.max_penetration_m, -facing(j, u[2 * j], u[2 * j + 1]).gap, -u[2 * j]});
          if (!on_needle(state[j])) continue;
          st.force_N -= scale * fy;
          const bool shaft = state[j] == State::Stick || face_of[j] == 2;
          if (!shaft || state[j] == State::Apex) {
            ++st.tip_contacts;
          } else {
            ++st.shaft_contacts;
            st.friction_force_N -= scale * fy;
            st.normal_force_N += scale * fx;
          }
          if (state[j] != State::Slide) {
            st.sticking += state[j] == State::Stick;
            continue;
          }
          // mu(n) N times the slip along the outline relative to the needle; N averaged over the
          // step where the node slid at both ends (the trapezoid of the external work).
          const Eigen::Vector2d& n = normal_of[j];
          const Eigen::Vector2d t(-n.y(), n.x());
          const double rel =
              t.x() * (u[2 * j] - u_prev[2 * j]) + t.y() * (u[2 * j + 1] - u_prev[2 * j + 1] + dd);
          const double normal_now = n.dot(Eigen::Vector2d(fx, fy));
          const double normal_mean =
              state_prev[j] == State::Slide
                  ? 0.5 * (normal_now +
                           n.dot(Eigen::Vector2d(needle_fx(f_prev, u_prev, secant_prev, j),
                                                 f_prev[2 * j + 1])))
                  : normal_now;
          friction_work += scale * friction_of(n) * normal_mean * std::abs(rel);
        }
        const PlaneStrainInsertionStep& last = out.steps.back();
        st.external_work_J = last.external_work_J + 0.5 * (last.force_N + st.force_N) * dd;
        st.friction_work_J = last.friction_work_J + friction_work;
        st.cohesive_work_J = last.cohesive_work_J + cohesive_work;
        st.strain_energy_J = 0.5 * scale * f.dot(u);
        // The interface's history: the largest opening; a node opened past delta_0 has failed.
        for (int j = 0; j < m; ++j) {
          if (!bonded[j]) continue;
          opened[j] = std::max(opened[j], 2.0 * u[2 * j]);
          damage[j] = 1.0 - secant[j] / stiffness0;
          if (opened[j] >= law.failure_opening_m && damage[j] > 1.0 - kFailedDamage) {
            bonded[j] = 0;
            secant[j] = 0.0;
            if (state[j] == State::Bonded) state[j] = State::Free;
          }
        }
        st.fracture_energy_J = st.cohesive_work_J - cohesive_stored;
        // The crack: the initial cut and every failed cell below it, down to the first cell
        // still bonded.
        if (cohesive) {
          st.crack_depth_m = law.initial_cut_m;
          for (int j = 0; j < m && !bonded[j]; ++j)
            st.crack_depth_m = std::max(st.crack_depth_m, -g.y[j]);
        }
        if (st.external_work_J > 0.0)
          st.balance_error =
              (st.external_work_J - st.strain_energy_J - st.friction_work_J - st.cohesive_work_J) /
              st.external_work_J;
        out.steps.push_back(st);
        break;
      }
    }
  }
  // Puncture: the first cell of the interface to fail, where the crack starts to run from the
  // initial cut; its force the largest up to there.
  double largest = 0.0;
  for (const PlaneStrainInsertionStep& st : out.steps) {
    largest = std::max(largest, st.force_N);
    if (cohesive && st.crack_depth_m > law.initial_cut_m + 1e-12 * p.block_depth_m) {
      out.puncture_travel_m = st.travel_m;
      out.puncture_force_N = largest;
      break;
    }
  }
  const double final_work = out.steps.back().external_work_J;
  for (const PlaneStrainInsertionStep& st : out.steps)
    if (st.external_work_J > 1e-3 * final_work)
      out.max_abs_balance_error = std::max(out.max_abs_balance_error, std::abs(st.balance_error));
  return out;
}

}  // namespace mneedle::fe
