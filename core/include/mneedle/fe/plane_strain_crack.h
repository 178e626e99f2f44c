#pragma once
// Plane-strain model of paper C §4 (Oldfield et al. 2013, after Shergold & Fleck 2004): the strain
// energy per unit length stored when a pre-existing straight slit of width w̄ in a large linear
// elastic block is forced open by a rigid circular needle of radius r at the slit's centre, until
// the needle sits fully inside the opened crack. This is the recoverable energy U_ε the cohesive
// model subtracts from the work of insertion.
// Quarter model x >= 0, y >= 0: slit on y = 0, 0 <= x <= w̄/2; u_x = 0 on x = 0; u_y = 0 on y = 0
// from the crack tip outward. Small-strain linear elasticity, bilinear quadrilaterals with
// selective reduced integration (no volumetric locking at nu -> 0.5) on a tensor-product grid
// graded geometrically from the slit. SI units: metres, pascals, joules per metre of needle.

namespace mneedle::fe {

/// How a slit-face node is kept outside the needle's circle (frictionless either way).
enum class CrackContactGap {
  /// Radial: the node is held on the circle along the normal through its current position,
  /// free to slide along the tangent; the normal is updated until it stops changing. This is
  /// frictionless contact with the exact circle.
  Radial,
  /// Linearised vertical gap u_y >= sqrt(r^2 - x^2) at the node's reference x (x < r), u_x free:
  /// the small-slope contact of Sneddon-type analyses. Nodes still slide in x, so the deformed
  /// node can end slightly inside the circle; the result reports by how much.
  Vertical,
};

/// The block's outer edges x = L/2 and y = L/2 (paper C does not say which it used).
enum class OuterEdges {
  TractionFree,  ///< a block resting free: only the symmetry planes hold it
  Pinned,        ///< u = 0 on both outer edges
};

struct CrackOpeningProblem {
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
  double crack_width_m = 0.0;    ///< full slit width w̄, tip to tip
  double needle_radius_m = 0.0;  ///< must be below w̄/2: a wider needle would extend the crack
  double block_size_m = 0.64;    ///< side of the square block, slit at its centre; >= 10 w̄
  /// Cell size along the slit (uniform on 0 <= x <= w̄/2 and the first row above it); cells
  /// grow geometrically (ratio kCrackGridGrowth) from there to the block edge. 0: w̄/300.
  double element_size_m = 0.0;
  OuterEdges outer_edges = OuterEdges::TractionFree;
  CrackContactGap contact_gap = CrackContactGap::Radial;
};

/// Growth ratio of neighbouring cells away from the slit.
inline constexpr double kCrackGridGrowth = 1.1;
/// Default cell size along the slit, as a fraction of the slit width w̄.
inline constexpr double kCrackDefaultElementFraction = 1.0 / 300.0;
/// Largest mesh accepted (nodes): bounds the work an input can ask for.
inline constexpr double kCrackMaxNodes = 2.0e6;

struct CrackOpeningResult {
  double strain_energy_J_per_m = 0.0;  ///< whole block (4 x the quarter model)
  int nodes = 0;                       ///< of the quarter model
  int elements = 0;
  double element_size_m = 0.0;    ///< cell size along the slit actually used
  int contact_nodes = 0;          ///< slit-face nodes held by the needle at the end
  double contact_extent_m = 0.0;  ///< largest reference x of a contact node
  int active_set_iterations = 0;  ///< linear solves until the contact set and normals settled
  /// Largest depth of a slit-face node inside the exact circle after the solve (0 when none).
  double max_penetration_m = 0.0;
  /// Smallest u_y of a slit-face node: negative would mean the face crossed its mirror image.
  double min_face_opening_m = 0.0;
};

/// Opens the slit over the needle and returns the stored strain energy. Throws InputError (one
/// line naming the field) on a bad problem and SolverError when the contact set does not settle.
CrackOpeningResult crack_opening_strain_energy(const CrackOpeningProblem& problem);

/// The same mesh, supports and assembly, the slit loaded by a uniform pressure instead of the
/// needle (the needle fields are checked but unused): for the Griffith closed form
/// U = pi p^2 a^2 (1 - nu^2) / E, a = w̄/2. Returns the whole block's energy (J/m).
/// `opening_at_centre_m`, when given, receives the full opening 2 u_y at x = 0.
double pressurised_slit_strain_energy(const CrackOpeningProblem& geometry_and_material,
                                      double pressure_Pa, double* opening_at_centre_m = nullptr);

}  // namespace mneedle::fe
