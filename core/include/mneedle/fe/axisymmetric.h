#pragma once
// Axisymmetric (r, z) finite element model of a layered tissue cylinder indented along its axis
// by a rigid axisymmetric needle: 6-node triangles, total Lagrangian, Newton-Raphson.
// SI units throughout: metres, newtons, pascals, joules.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/fe/cohesive_law.h"
#include "mneedle/fe/fidelity.h"
#include "mneedle/fe/material.h"

namespace mneedle::fe {

/// One tissue layer, listed from the surface downward.
struct AxisymmetricLayer {
  double thickness_m = 0.0;
  MaterialParameters material;
};

/// Rigid needle of revolution in its own frame: tip at height 0, body toward +h. The solid
/// section at height h is the annulus bore_radius <= r <= outer radius(h), the outer radius
/// piecewise linear and non-decreasing in h (a flat punch starts at its full radius).
struct AxisymmetricNeedle {
  std::vector<double> heights_m;  ///< ascending, first 0
  std::vector<double> radii_m;    ///< outer radius at each height
  double bore_radius_m = 0.0;     ///< 0 for a solid needle

  static AxisymmetricNeedle flat_punch(double radius_m, double bore_radius_m = 0.0);
  /// Cone of the given half-angle from the axis, widening to base_radius_m (then a cylinder).
  static AxisymmetricNeedle cone(double half_angle_rad, double base_radius_m,
                                 double bore_radius_m = 0.0);

  double max_radius() const;
  /// Lowest height at which the solid section reaches radius r; +infinity when it never does
  /// (r beyond the outer radius or inside the bore).
  double lowest_height_at(double r) const;
};

/// Structured graded mesh controls. Element size h_m is used within fine_radius_m of the axis
/// and down to fine_depth_m; beyond, sizes grow geometrically by `growth` up to max_size_m.
struct AxisymmetricMeshOptions {
  double radius_m = 0.0;  ///< tissue cylinder radius
  double h_m = 0.0;
  double fine_radius_m = 0.0;
  double fine_depth_m = 0.0;
  double growth = 1.25;
  double max_size_m = std::numeric_limits<double>::infinity();
  int min_elements_per_layer = 2;
  std::vector<double> radial_breaks_m;  ///< radii that must be node columns (punch edge, bore)
  std::vector<double> depth_breaks_m;   ///< depths below the surface that must be node rows
  int elements_through_top = 0;         ///< minimum elements through layer 0 (0: the general one)
  /// A band of finer cells (band_size_m < h_m; 0: none) along the column r = band_radius_m (a
  /// radial break) down to the depth break band_depth_m: the node columns on either side grade
  /// from band_size_m to h_m by `growth`, and the rows above band_depth_m are band_size_m apart
  /// (the cohesive ring's process zone, docs/model.md "The cohesive criterion").
  double band_radius_m = 0.0;
  double band_size_m = 0.0;
  double band_depth_m = 0.0;
};

/// Reference coordinates (r, z): z = 0 is the free surface, tissue at z < 0, axis at r = 0.
struct AxisymmetricMesh {
  std::vector<Eigen::Vector2d> nodes;
  /// Corners counter-clockwise in (r, z), then mid-edge nodes 1-2, 2-3, 3-1.
  std::vector<std::array<std::uint32_t, 6>> elements;
  std::vector<int> element_layer;            ///< index into the layer list
  std::vector<std::uint32_t> surface_nodes;  ///< z = 0, sorted by r
  std::vector<std::uint32_t> axis_nodes;     ///< r = 0
  std::vector<std::uint32_t> fixed_nodes;    ///< bottom and outer side (clamped)
  double min_angle_deg = 0.0;                ///< smallest corner angle of any element
  double max_aspect_ratio = 0.0;             ///< longest edge / shortest altitude
};

/// Layers meshed top to bottom; every interface is a row of element edges.
AxisymmetricMesh make_axisymmetric_mesh(const std::vector<AxisymmetricLayer>& layers,
                                        const AxisymmetricMeshOptions& options);

/// The mesh with a ring (cylindrical) crack opened: every node on the line r = radius_m,
/// -depth_m < z <= 0 is doubled (the copy goes to the elements outside the ring); the node at
/// (radius_m, -depth_m), the crack front, stays shared. The outer copy of the surface node is
/// not a surface (contact) node: the needle presses the inside of the ring. `area_m2` receives
/// 2 pi radius depth (one face). Throws InputError unless that line is a column of element edges
/// ending at a node. `face_pairs`, when given, receives each doubled node with its outer copy
/// ({inner, outer}): the faces overlap where u_r(outer) < u_r(inner).
AxisymmetricMesh crack_axisymmetric_mesh(
    const AxisymmetricMesh& mesh, double radius_m, double depth_m, double* area_m2,
    std::vector<std::array<std::uint32_t, 2>>* face_pairs = nullptr);

/// The crack-face penalty relative to a pair's own radial stiffness: each multiplier update
/// leaves about 1 / kFacePenalty of an overlap, and the factor adds about that much to the
/// stiffness's condition number.
inline constexpr double kFacePenalty = 1e3;

/// Result of one equilibrium solve.
struct Equilibrium {
  Eigen::VectorXd displacement;  ///< 2 per node: u_r, u_z
  Eigen::VectorXd reaction;      ///< internal force at every degree of freedom (N, full ring)
  double strain_energy_J = 0.0;
  int newton_iterations = 0;
};

/// Newton-Raphson settings.
struct NewtonOptions {
  int max_iterations = 25;
  double residual_tolerance = 1e-8;  ///< on |R_free| relative to |reactions|
  /// Also converged when |R_free| <= this * |reactions| and the last iteration did not halve it
  /// (the round-off floor of the assembled forces, ~1e-7 relative near a punch edge).
  double stagnation_tolerance = 1e-5;
  /// Reuse the last factorisation (of this solve, or of an earlier one with the same constrained
  /// dofs) while the residual falls by 4x per iteration.
  bool modified_newton = true;
  /// Past a bifurcation the tangent is indefinite and Newton heads for the unstable branch: its
  /// diagonal is then shifted until it is positive definite and the step is taken where the
  /// potential energy falls (docs/model.md, "Solver"). Once a model has taken such a step, each of
  /// its later solves may take up to this many iterations (the way to the stable branch is long).
  int max_descent_iterations = 400;
};

/// Assembly and equilibrium on a fixed mesh; reuses the sparsity pattern and its symbolic
/// factorisation across every solve.
class AxisymmetricModel {
 public:
  AxisymmetricModel(AxisymmetricMesh mesh, const std::vector<MaterialParameters>& layer_materials);
  ~AxisymmetricModel();
  AxisymmetricModel(AxisymmetricModel&&) noexcept;
  AxisymmetricModel& operator=(AxisymmetricModel&&) noexcept;

  const AxisymmetricMesh& mesh() const;
  std::size_t dof_count() const;
  bool is_linear() const;
  /// Numeric factorisations performed by solve() so far.
  int factorization_count() const;
  /// The per-layer constants the model was built with.
  const std::vector<MaterialParameters>& layer_materials() const;

  /// Per element: mean over its quadrature points of the von Mises Cauchy stress (Pa) and of
  /// the strain energy density (J/m^3 of reference volume) at displacement u.
  std::vector<double> von_mises(const Eigen::VectorXd& u) const;
  std::vector<double> energy_density(const Eigen::VectorXd& u) const;
  /// Volume-weighted (2 pi r dA, reference) mean of the maximum principal Cauchy stress (hoop
  /// stress included) over the part of `layer` within length_m of point_m in the (r, z) plane:
  /// a ball for a point on the axis, a torus round the axis for one off it (the peak below
  /// averages over a ball everywhere). Returns 0 when no part of the layer is within reach.
  double averaged_max_principal_stress(const Eigen::VectorXd& u, const Eigen::Vector2d& point_m,
                                       double length_m, int layer) const;
  /// The stress criterion's measure (docs/model.md, "Criteria", stress): the largest, over
  /// centres at the nodes of `layer` with r <= search_radius_m, of the mean of the maximum
  /// principal stress over the part of `layer` within length_m of the centre in 3-D (a ball, as
  /// the 3-D probe's; the volume method of the theory of critical distances). Each element
  /// within reach is split into 16 equal sub-triangles carrying the stress at their centroids,
  /// each weighted by 2 pi r dA times the fraction of its ring inside the ball. Returns 0 when no
  /// centre is within reach.
  double peak_averaged_max_principal_stress(const Eigen::VectorXd& u, double search_radius_m,
                                            double length_m, int layer) const;
  /// Binary VTU (ParaView): the (r, z) mesh as quadratic triangles in the plane y = 0 (x = r,
  /// z = z), point data displacement_m (u_r, 0, u_z), cell data von_mises_Pa,
  /// principal_stress_Pa (largest first, σ_θθ among them), energy_density_J_per_m3 and layer;
  /// field data depth_m and axisymmetric = 1; `comment` as an XML comment. Throws InputError
  /// when the file cannot be written.
  void write_vtu(const std::string& path, const Eigen::VectorXd& u, double depth_m,
                 const std::string& comment = "") const;

  /// Internal force vector at displacement u; tangent stiffness when `tangent` is not null.
  /// Throws SolverError on an inverted element.
  Eigen::VectorXd internal_force(const Eigen::VectorXd& u, double* strain_energy_J,
                                 Eigen::SparseMatrix<double>* tangent) const;

  /// Crack-face node pairs {inner, outer} (crack_axisymmetric_mesh) that set_pair_state may hold
  /// in frictionless contact, u_r(outer) = u_r(inner), by an augmented Lagrangian: the energy
  /// lambda g + k g^2 / 2 (g = u_r(outer) - u_r(inner)) of a closed pair adds t = lambda + k g to
  /// the outer node's internal force and -t to the inner one's (the pair pushes the outer node by
  /// -t: outward when t < 0), k = kFacePenalty x the pair's mean radial stiffness at u = 0. Adds
  /// the pairs' couplings to the stiffness pattern; every pair starts open. Used on nonlinear
  /// layers (the linear path holds pairs exactly on its condensed surface). Throws InputError on a
  /// node outside the mesh.
  void set_face_pairs(std::vector<std::array<std::uint32_t, 2>> pairs);
  /// Which pairs are closed (1) and their multipliers lambda (N, full ring; a compressed pair has
  /// lambda < 0). Open pairs carry no force.
  void set_pair_state(std::vector<char> closed, Eigen::VectorXd multipliers);
  /// t = lambda + k g of every closed pair at u, 0 for an open one (N, full ring).
  Eigen::VectorXd pair_forces(const Eigen::VectorXd& u) const;
  /// k of every pair (N/m, full ring).
  Eigen::VectorXd pair_penalties() const;

  /// Equilibrium with u[dof] = value on `prescribed_dofs`, zero external force elsewhere,
  /// Newton from `start`. Throws SolverError when Newton does not converge.
  Equilibrium solve(const std::vector<std::uint32_t>& prescribed_dofs,
                    const Eigen::VectorXd& prescribed_values, const Eigen::VectorXd& start,
                    const NewtonOptions& options = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The energy criterion's cracked twin failed where the intact model had solved; the message
/// names the twin and its crack.
class CrackedTwinError : public SolverError {
 public:
  using SolverError::SolverError;
};

/// One converged depth of an insertion.
struct InsertionStep {
  double depth_m = 0.0;
  double force_N = 0.0;          ///< axial force resisting the needle (positive)
  double contact_area_m2 = 0.0;  ///< projected on the surface plane
  double contact_pressure_Pa = 0.0;
  double strain_energy_J = 0.0;
  int newton_iterations = 0;  ///< summed over the sub-steps since the previous output
  int contact_nodes = 0;
  /// The stress criterion's measure: AxisymmetricModel::peak_averaged_max_principal_stress of
  /// the top layer (layer 0) over centres within the needle's outline plus two
  /// stress_average_length_m (Pa; 0 when the option is off).
  double tip_stress_Pa = 0.0;
  /// G = (U_intact - U_cracked) / crack_area_m2 at the same needle position, the cracked model
  /// advanced in lock-step (J/m^2; 0 when crack_depth_m is 0). The crack is a ring (cylindrical)
  /// crack at radius ring_crack_radius() from the surface down crack_depth_m.
  double energy_release_rate_J_per_m2 = 0.0;
  double crack_area_m2 = 0.0;  ///< 2 pi r_c c (one face)
  /// The ring crack's faces (crack_depth_m > 0): how far the inner face has passed through the
  /// outer one at a node pair (m, >= 0), and the pairs in contact (docs/model.md, "Crack faces
  /// in contact").
  double crack_face_overlap_m = 0.0;
  int crack_face_contacts = 0;
  /// The cohesive ring crack (cohesive_depth_m > 0; docs/model.md, "Cohesive ring crack"):
  /// depth below the surface of its deepest failed face pair (damage 1) and the lower end of
  /// its deepest damaged cell (an edge of the crack line with a damaged node; m, reference),
  /// the cells of the process zone (edges with a damaged node that has not failed), the energy
  /// its law has dissipated (J, the whole ring) and the damage rounds solved since the previous
  /// output.
  double cohesive_crack_m = 0.0;
  double cohesive_zone_m = 0.0;
  int process_zone_cells = 0;
  double fracture_energy_J = 0.0;
  int cohesive_rounds = 0;
  /// The share of the ring's face area whose pairs have failed (0..1; 1: the line is cut through
  /// but for its front node, which stays shared).
  double cohesive_failed_fraction = 0.0;
};

struct InsertionOptions {
  double depth_m = 0.0;  ///< final tip depth below the undeformed surface
  int output_steps = 20;
  /// Frictionless: linear layers only; the small-strain contact of Sneddon's theory (vertical
  /// gap above each node's reference radius, vertical force, radial sliding free).
  ContactMode contact = ContactMode::Sticking;
  NewtonOptions newton;
  double stress_average_length_m = 0.0;  ///< tip_stress_Pa averaging length (0 = off)
  /// Depth of the ring crack for G (0 = off). The mesh must have a node column at the crack
  /// radius (ring_crack_radius of the needle) reaching at least this depth; a second, cracked
  /// model runs in lock-step with the intact one.
  double crack_depth_m = 0.0;
  /// The ring crack's faces in frictionless node-to-node contact with sticking needle contact
  /// (exact on linear layers, an augmented Lagrangian on nonlinear ones; with frictionless needle
  /// contact the faces stay free and only their overlap is reported); false leaves them free.
  bool crack_face_contact = true;
  /// A cohesive ring crack (docs/model.md, "Cohesive ring crack"): when cohesive_depth_m > 0 the
  /// tissue is split along r = cohesive_ring_radius(needle) from the surface down this
  /// deep and its faces held by `cohesive` (paper C's bilinear law on the mixed-mode opening;
  /// in compression a penalty of the law's initial stiffness). Linear layers and sticking
  /// contact only; the mesh needs the node column and row as for crack_depth_m.
  double cohesive_depth_m = 0.0;
  CohesiveLaw cohesive;
  /// Called after each output step; returning false stops the insertion there.
  std::function<bool(const InsertionStep&)> on_step;
  /// When set, step_<k>.vtu (k = 1..output steps) is written there (AxisymmetricModel::write_vtu)
  /// and steps.pvd updated (the collection, depth as time); an earlier run's files go first.
  std::string vtu_directory;
  std::string vtu_comment;  ///< written into every VTU and the .pvd (the run's provenance)
};

struct InsertionResult {
  std::vector<InsertionStep> steps;
  std::size_t nodes = 0;
  std::size_t elements = 0;
  int factorizations = 0;
  double mesh_seconds = 0.0;
  double solve_seconds = 0.0;
};

/// Presses the needle into the model to options.depth_m. A linear model factorises once and
/// condenses the tissue's stiffness onto the surface nodes the needle can reach.
InsertionResult insert_needle(AxisymmetricModel& model, const AxisymmetricNeedle& needle,
                              const InsertionOptions& options);

/// The one-off case: mesh sized from the fidelity and the needle, then insert.
/// Cylinder radius: the caller's choice (see docs/model.md, "The tissue cylinder", for the block
/// equivalent).
struct AxisymmetricProblem {
  std::vector<AxisymmetricLayer> layers;
  double radius_m = 0.0;
  AxisymmetricNeedle needle;
  double depth_m = 0.0;
  Fidelity fidelity = Fidelity::Standard;
  ContactMode contact = ContactMode::Sticking;
  int output_steps = 0;  ///< 0: from the fidelity
  /// Honoured: tip_size_m, growth, domain_scale (cylinder radius), tolerance, steps; order must
  /// be 2 (6-node triangles) when set, else InputError; elements_through_top sets the minimum
  /// elements per layer.
  FidelityOverrides overrides;
  double stress_average_length_m = 0.0;  ///< as InsertionOptions
  double crack_depth_m = 0.0;            ///< as InsertionOptions
  bool crack_face_contact = true;        ///< as InsertionOptions
  double cohesive_depth_m = 0.0;         ///< as InsertionOptions
  CohesiveLaw cohesive;                  ///< as InsertionOptions
  /// The cohesive ring's cells (m; 0: the mesh's own): a band of them along the ring, graded to
  /// the mesh's own size on either side (AxisymmetricMeshOptions::band_size_m).
  double cohesive_cell_m = 0.0;
  std::function<bool(const InsertionStep&)> on_step;
  /// Called once the mesh is built, before the first step, with the result's nodes, elements and
  /// mesh_seconds filled and no steps: a caller that keeps what a run reached before it stopped
  /// keeps the mesh it ran on too.
  std::function<void(const InsertionResult&)> on_mesh;
  std::string vtu_directory;
  std::string vtu_comment;
};

InsertionResult simulate_axisymmetric(const AxisymmetricProblem& problem);

/// Mesh controls used by simulate_axisymmetric for this problem.
AxisymmetricMeshOptions mesh_options_for(const AxisymmetricProblem& problem);

/// Radius of the cylinder whose cross-section has the area of a square block of side `width_m`.
double equal_area_radius(double width_m);

/// Radius of the ring crack used for the energy release rate: a flat punch's (outer) edge; for a
/// tapered needle (cone) the radius of its section at height `depth_m` above the tip (the
/// needle's footprint on the undeformed surface at that depth), at least kRingCrackMinFraction
/// of the needle's largest radius so that a sharp cone still gets a resolvable ring.
double ring_crack_radius(const AxisymmetricNeedle& needle, double depth_m);

/// Radius of the cohesive ring crack: the needle's outer radius, a property of the needle alone
/// (a flat punch's rim; the outline a tapered tip's full section pushes ahead of it).
double cohesive_ring_radius(const AxisymmetricNeedle& needle);

}  // namespace mneedle::fe
