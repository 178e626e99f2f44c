#pragma once
// 3-D pre-puncture stage (paper A §2.1): rigid needles pressed along -z into a layered tissue
// block, sticking contact (a surface node captured by the needle moves with it for good).

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "mneedle/fe/tissue_mesh.h"
#include "mneedle/mesh.h"

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
  int captured_nodes = 0;
};

struct Step3d {
  double depth_m = 0.0;
  std::vector<NeedleStep3d> needles;
  double strain_energy_J = 0.0;
  int newton_iterations = 0;  ///< linear solves of the step (1 per capture round when linear)
};

/// Wall-clock split of the work (s).
struct Timing3d {
  double meshing_s = 0.0;
  double assembly_s = 0.0;
  double factorization_s = 0.0;
  double contact_s = 0.0;  ///< capture searches, compliance columns and contact solves
  double total_s = 0.0;
  int factorizations = 0;
};

/// Repeated solves on one mesh: advance_to() a growing sequence of depths.
/// Linear materials: the stiffness is factorised once; contact is solved on the captured
/// surface nodes through their condensed compliance (columns of K⁻¹ added as nodes are
/// captured). Nonlinear materials: Newton–Raphson with line search and adaptive depth steps, one
/// symbolic analysis for the whole insertion. Errors: SolverError naming the depth and the cause.
class Indentation3d {
 public:
  /// max_depth bounds the needle travel (m): it fixes the candidate contact nodes.
  Indentation3d(const TetMesh& mesh, std::vector<Needle3d> needles, double max_depth);
  ~Indentation3d();
  Indentation3d(const Indentation3d&) = delete;
  Indentation3d& operator=(const Indentation3d&) = delete;

  Step3d advance_to(double depth);
  /// Nodal displacement (3 per node, m) at the last depth.
  Eigen::VectorXd displacement() const;
  const Timing3d& timing() const;
  std::string solver_backend() const;
  /// Writes an ASCII VTU (displacement, von Mises stress, strain energy density, layer id).
  void write_vtu(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct Simulation3dOptions {
  Fidelity fidelity = Fidelity::Standard;
  int order = 2;              ///< 1: TET4, 2: TET10
  double depth = 0.0;         ///< final tip depth below the undeformed surface (m)
  int steps = 10;             ///< equal output steps in depth
  std::string vtu_directory;  ///< when set, step_<k>.vtu is written there for every step
};

struct Simulation3dResult {
  std::vector<Step3d> steps;
  int nodes = 0;
  int elements = 0;
  int order = 2;
  MeshQuality quality;
  Timing3d timing;
  std::string solver_backend;
};

/// One call for the CLI: meshes `block` graded toward every needle (sites, fidelity, order and
/// fine depth are filled in from the needles and options) and presses all needles together.
Simulation3dResult simulate_3d(TissueBlockSpec block, const std::vector<Needle3d>& needles,
                               const Simulation3dOptions& options);

}  // namespace mneedle::fe
