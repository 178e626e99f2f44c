#pragma once
// 3-D pre-puncture stage (paper A §2.1): rigid needles pressed along -z into a layered tissue
// block. Sticking contact (a surface node captured by the needle moves with it for good) or
// frictionless contact (augmented Lagrangian at surface quadrature points; docs/model.md).

#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/fe/fidelity.h"
#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/needle/mesh.h"

namespace mneedle::fe {

/// A rigid needle: closed surface in the needle frame (tip at the origin, body along +z), entering
/// the block at (x, y) relative to the block centre (m).
struct Needle3d {
  std::string name;
  TriangleMesh mesh;
  double x = 0.0;
  double y = 0.0;
};

struct NeedleStep3d {
  std::string name;
  double force_N = 0.0;                     ///< axial force of the tissue on the needle (+z up)
  std::array<double, 2> lateral_force_N{};  ///< (fx, fy) of the tissue on the needle
  double contact_area_m2 = 0.0;             ///< captured surface projected on the z = 0 plane
  double contact_pressure_Pa = 0.0;         ///< force_N / contact_area_m2 (0 without contact)
  int captured_nodes = 0;  ///< sticking: captured nodes; frictionless: nodes of touching faces
  /// The stress criterion's measure: the peak over the top layer near the needle of its maximum
  /// principal stress averaged over stress_average_length_m (fe::PeakStressProbe; Pa; 0 when
  /// the option is off).
  double tip_stress_Pa = 0.0;
  /// G = (U_intact - U_cracked) / total crack area over all needles (J/m^2; 0 when off).
  double energy_release_rate_J_per_m2 = 0.0;
  double crack_area_m2 = 0.0;  ///< area of this needle's crack (one face, whole needle)
};

struct Step3d {
  double depth_m = 0.0;
  std::vector<NeedleStep3d> needles;
  double strain_energy_J = 0.0;
  /// Linear solves of the step: when linear, 1 and 2 per capture event (1 per capture round where
  /// captures are taken at the step's end: a cracked twin, crack faces in contact).
  int newton_iterations = 0;
  /// Crack faces (a run with set_crack_faces): the deepest one face has passed through
  /// the other at a node pair (m, >= 0; 0 when none or no crack) and the pairs in contact.
  double crack_face_overlap_m = 0.0;
  int crack_face_contacts = 0;
};

/// Two nodes of a crack's opposite faces that coincide in the reference state (crack_mesh: the
/// original on the negative side, its copy on the side the unit `normal` points to). The faces
/// overlap when normal . (u_positive - u_negative) < 0.
struct CrackFacePair {
  int negative_node = -1;
  int positive_node = -1;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

/// Wall-clock split of the work (s).
struct Timing3d {
  double meshing_s = 0.0;
  double assembly_s = 0.0;
  double factorization_s = 0.0;
  double contact_s = 0.0;  ///< capture searches, compliance columns and contact solves
  double stress_s = 0.0;   ///< simulate_3d: the stress criterion's probe (PeakStressProbe)
  double total_s = 0.0;
  int factorizations = 0;
  /// Factorisations of a shifted tangent (past a bifurcation, docs/model.md "Solver").
  int shifted_factorizations = 0;
};

/// Solver choices of one Indentation3d.
struct Indentation3dOptions {
  ContactMode contact = ContactMode::Sticking;
  double tolerance = 1e-8;  ///< Newton: free residual / reaction force
  /// Linear sticking contact: the surface rows eliminated last, their compliance read from the
  /// dense factor of the Schur complement (docs/performance.md, "The contact block"), where it
  /// fits. False: every compliance column from a sparse solve (the same numbers to round-off;
  /// for comparisons).
  bool contact_block = true;
};

/// What write_inp wrote: the depth, and the sum of the tissue's internal forces at the
/// prescribed nodes — the reaction an independent solver of the deck must reproduce (N, meshed
/// part only: a half model's is half the needle's).
struct InpExport {
  std::string path;
  double depth_m = 0.0;
  Eigen::Vector3d reaction_N = Eigen::Vector3d::Zero();
  int nodes = 0;
  int elements = 0;
  int prescribed_nodes = 0;
};

/// Repeated solves on one mesh: advance_to() a growing sequence of depths.
/// Linear materials: the stiffness is factorised once; contact is solved on the captured
/// surface nodes through their condensed compliance (columns of K⁻¹ computed as nodes are
/// found inside a needle), capturing them in depth order. Nonlinear materials: Newton–Raphson
/// with line search and adaptive depth steps, one symbolic analysis for the whole insertion.
/// Errors: SolverError naming the depth and the cause. The run keeps its own copy of the mesh.
class Indentation3d {
 public:
  /// max_depth bounds the needle travel (m): it fixes the candidate contact nodes.
  /// A mesh with mirror_y0 (mirror_x0) set is the y >= 0 (x >= 0) part of a symmetric problem:
  /// nodes on the plane get no normal displacement; the needles are those of the modelled part
  /// (InputError for one at y < 0, or one on y = 0 that is not symmetric about it). Energy is
  /// reported for the whole problem, forces and contact area for each whole needle.
  Indentation3d(const TetMesh& mesh, std::vector<Needle3d> needles, double max_depth,
                const Indentation3dOptions& options = {});
  ~Indentation3d();
  Indentation3d(const Indentation3d&) = delete;
  Indentation3d& operator=(const Indentation3d&) = delete;

  Step3d advance_to(double depth);
  /// Makes this run a cracked twin of `leader` for the energy release rate: this run's mesh is
  /// the leader's with nodes added (crack_mesh), leader_node[n] the leader's node for node n.
  /// From now on this run captures exactly the nodes the leader has captured (copies included)
  /// instead of searching its own, so at one depth the two solutions differ by the crack alone
  /// and U_cracked <= U_intact. Advance the leader to each depth first. Sticking contact only
  /// (InputError otherwise); `leader` must outlive this run.
  void hold_contact_of(const Indentation3d& leader, std::vector<int> leader_node);
  /// The node pairs of a crack's faces, whose overlap every Step3d reports. With `contact`, the
  /// faces are in frictionless contact (docs/model.md, "Crack faces in contact"): at each pair
  /// they may open and slide but not pass through each other, and a pair in contact carries a
  /// compressive normal force only. Contact is solved (node to node, an active set on the
  /// condensed compliance) for linear tissue with sticking needle contact; with frictionless needle
  /// contact or nonlinear tissue the faces stay free (traction-free) and only their overlap is
  /// reported. Call before the first advance_to. InputError for a node out of range or a
  /// non-unit normal.
  void set_crack_faces(std::vector<CrackFacePair> pairs, bool contact);
  /// Nodal displacement (3 per node, m) at the last depth.
  Eigen::VectorXd displacement() const;
  /// Nodes whose displacement is read at every step (the stress criterion's probe): on the
  /// linear sticking path their rows of every compliance column are kept, so
  /// watched_displacement() costs no solve. Call before the first advance_to; InputError for a
  /// node out of range or a call after it.
  void watch_nodes(std::vector<int> nodes);
  /// Displacement (3 per watched node, in watch_nodes' order, m) at the last depth; equal to
  /// displacement()'s rows to round-off, and taken from it where no rows are kept (frictionless
  /// contact, nonlinear tissue, crack faces in contact).
  Eigen::VectorXd watched_displacement() const;
  /// True when watched_displacement() at the last depth costs a back substitution through the
  /// whole factor: the linear sticking path with more captured nodes than it keeps rows for,
  /// through the contact block (its loads lie on the factor's trailing block). The state of such
  /// a depth is then watched_trailing_loads(), and watched_displacements() reads several depths'
  /// watched rows in one back substitution (docs/performance.md, "The stress criterion's cost").
  bool watched_by_back_solve() const;
  /// The last depth's contact loads on the trailing block (N, candidates' numbering); InputError
  /// unless watched_by_back_solve().
  Eigen::VectorXd watched_trailing_loads() const;
  /// The watched rows (as watched_displacement(), m) of the states whose trailing loads are the
  /// columns of `loads`, one column each; equal to watched_displacement() at each state to
  /// round-off. InputError for a column of the wrong size or without a trailing block.
  Eigen::MatrixXd watched_displacements(const Eigen::MatrixXd& loads) const;
  const Timing3d& timing() const;
  std::string solver_backend() const;
  /// True when the linear sticking path reads its compliance from the contact block
  /// (Indentation3dOptions::contact_block, and the block fits).
  bool uses_contact_block() const;
  /// Writes the problem of the last depth as a CalculiX/Abaqus deck (fe/inp_writer.h): mesh,
  /// linear layers, fixed faces, mirror planes and every captured node's displacement
  /// prescribed. Sticking contact only (InputError otherwise); `comment` as "** " lines.
  InpExport write_inp(const std::string& path, const std::vector<std::string>& comment) const;
  /// Writes the tissue at the last depth as a binary VTU of the whole block (a half or quarter
  /// model reflected back): displacement, contact force, traction and pressure, von Mises and
  /// principal stresses, strain energy density, layer (docs/cli.md, "Fields"). `comment` goes
  /// into the file as an XML comment (the run's provenance).
  void write_vtu(const std::string& path, double depth_m, const std::string& comment = "") const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct Simulation3dResult;

struct Simulation3dOptions {
  Fidelity fidelity = Fidelity::Standard;
  int order = 2;       ///< 1: TET4, 2: TET10 (overrides.order wins when set)
  double depth = 0.0;  ///< final tip depth below the undeformed surface (m)
  int steps = 10;      ///< equal output steps in depth (overrides.steps wins when set)
  /// When set, every step writes step_<k>.vtu (tissue) and needles_<k>.vtu there and updates
  /// steps.pvd (the collection, depth as time); files of an earlier run are removed first.
  std::string vtu_directory;
  std::string vtu_comment;  ///< written into every VTU and the .pvd (the run's provenance)
  /// Steps after the first at or beyond this depth (m) write no VTU files (0: every step does):
  /// a run that goes on past what its caller shows.
  double vtu_depth_m = 0.0;
  ContactMode contact = ContactMode::Sticking;
  /// Honoured: order, tip_size_m, growth, domain_scale (block size x and y), tolerance, steps,
  /// elements_through_top.
  FidelityOverrides overrides;
  /// Mesh only y >= 0, with the mirror plane y = 0: every needle must be symmetric about its
  /// own y = 0 plane and a needle at y != 0 needs one of the same mesh at -y (InputError
  /// otherwise). Results are for the whole scene, one entry per needle as given.
  bool half_model = false;
  /// The same across x = 0 (with half_model: a quarter model). Not with a crack on x = 0.
  bool mirror_x = false;
  double stress_average_length_m = 0.0;  ///< tip_stress_Pa averaging length (0 = off)
  /// Depth of the planar crack (normal x) through each needle's axis for G (0 = off); a second,
  /// cracked model runs in lock-step with the intact one.
  double crack_depth_m = 0.0;
  /// The crack's faces in frictionless contact (Indentation3d::set_crack_faces); false
  /// leaves them traction-free, free to pass through each other (for comparison only).
  bool crack_face_contact = true;
  /// Called after each output step; returning false stops the insertion there.
  std::function<bool(const Step3d&)> on_step;
  /// Called once the mesh is built, before the first step, with Simulation3dResult's mesh
  /// summary filled (nodes, elements, order, quality, contact zone, unresolved flats) and no
  /// steps: a caller that keeps what a run reached before it stopped keeps the mesh it ran on too.
  std::function<void(const Simulation3dResult&)> on_mesh;
  /// Called when the run ends by an exception after the mesh was built and the solver set up (a
  /// SolverError at some step, or one thrown by on_step), with what each phase cost up to there:
  /// a caller that keeps what a stopped run reached keeps its timings too. Must not throw.
  std::function<void(const Timing3d&)> on_stop_timing;
  /// When set, the problem at the last step not deeper than inp_depth_m is written there
  /// as a CalculiX/Abaqus deck (Indentation3d::write_inp; linear layers, sticking contact).
  std::string inp_path;
  double inp_depth_m = 0.0;
  std::vector<std::string> inp_comment;  ///< "** " lines of the deck (the run's provenance)
};

struct Simulation3dResult {
  std::vector<Step3d> steps;
  int nodes = 0;
  int elements = 0;
  int order = 2;
  MeshQuality quality;
  double contact_zone_m = 0.0;  ///< TetMesh::contact_zone_m of the mesh solved
  int unresolved_flats = 0;     ///< TetMesh::unresolved_flats
  Timing3d timing;
  std::string solver_backend;
  std::optional<InpExport> exported;  ///< set when options.inp_path was written
};

/// One call for the CLI: meshes `block` graded toward every needle (sites, fidelity, order and
/// fine depth are filled in from the needles and options) and presses all needles together.
Simulation3dResult simulate_3d(TissueBlockSpec block, const std::vector<Needle3d>& needles,
                               const Simulation3dOptions& options);

}  // namespace mneedle::fe
