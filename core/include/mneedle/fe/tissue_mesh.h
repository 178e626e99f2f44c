#pragma once
// Graded, layer-conforming tetrahedral mesh of a layered tissue block (paper A §2.1: each
// tetrahedron knows its layer, its material and its four face neighbours).

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mneedle/fe/fidelity.h"
#include "mneedle/fe/material.h"

namespace mneedle::fe {

/// Parses "fast", "standard" or "fine"; throws InputError naming `field` otherwise.
Fidelity parse_fidelity(const std::string& text, const std::string& field = "fidelity");
std::string to_string(Fidelity fidelity);

struct TissueLayer {
  std::string name;
  double thickness = 0.0;  ///< m
  MaterialParameters material;
};

/// Where a needle enters the block: (x, y) relative to the block centre (m) and the largest
/// needle radius over the insertion depth (m), which sets the finest element size there.
struct NeedleSite {
  NeedleSite() = default;
  NeedleSite(double x_m, double y_m, double radius_m,
             std::optional<Eigen::Vector2d> tip_m = std::nullopt)
      : x(x_m), y(y_m), radius(radius_m), tip(std::move(tip_m)) {}

  double x = 0.0;
  double y = 0.0;
  double radius = 0.0;
  /// Where the needle first touches the surface when that is off its axis (a bevel's tip), m:
  /// the grid gets lines through it too.
  std::optional<Eigen::Vector2d> tip;
  /// Convex outline (x, y; m, block frame) of the needle's lowest points, counter-clockwise: one
  /// point for a pointed tip, a polygon for a flat end; empty: unknown. Under a criterion length
  /// the top layer is refined around it (docs/model.md, "Tissue block and mesh").
  std::vector<Eigen::Vector2d> first_contact;
};

/// The block spans x in [-size_x/2, size_x/2], y likewise and z in [-total thickness, 0]; the top
/// surface is z = 0. Layers are listed from the top surface down.
struct TissueBlockSpec {
  double size_x = 0.0;  ///< m
  double size_y = 0.0;  ///< m
  std::vector<TissueLayer> layers;
  std::vector<NeedleSite> sites;
  Fidelity fidelity = Fidelity::Standard;
  int order = 2;                 ///< 1: 4-node tetrahedra, 2: 10-node tetrahedra
  double insertion_depth = 0.0;  ///< m; the vertical grading keeps fine elements down to here
  /// Each set field replaces the fidelity's choice (domain_scale, tolerance and steps are
  /// applied by simulate_3d, not here).
  FidelityOverrides overrides;
  /// m; the length over which the puncture criterion averages near the sites (the stress
  /// criterion's L; 0: none). Resolved at every fidelity: mesh_sizing, below.
  double criterion_length = 0.0;
  /// Mesh only y >= 0 (mirror plane y = 0; the sites and off-axis tips must be symmetric about
  /// it as a set): the result is exactly the y >= 0 part of the full mesh, with mirror_y0 set.
  bool half_y = false;
  /// The same for x >= 0 and the plane x = 0 (mirror_x0); with half_y, a quarter model.
  bool half_x = false;
};

/// Element sizes chosen for a fidelity and needle radius (m, growth ratios dimensionless).
struct MeshSizing {
  double fine_size = 0.0;        ///< lateral element size at a needle site
  double fine_half_width = 0.0;  ///< half-width of the uniformly fine zone around a site
  double growth = 1.0;           ///< size ratio between neighbouring elements away from a site
  double max_size = 0.0;         ///< coarsest element size
  int elements_through_top = 1;  ///< elements through the (thin, stiff) top layer
};
/// Halvings of the grid along the needle's path by local bisection when overrides leave
/// refinement_levels unset (docs/model.md, "Tissue block and mesh"); a criterion length
/// (m, > 0) asks for at least two with 10-node elements.
int default_refinement_levels(Fidelity fidelity, int order, double criterion_length = 0.0);

/// Widest needle radius, in criterion lengths L, whose flat first contact every level meshes
/// with cells of 2 L (docs/model.md, "Tissue block and mesh"): 250 um in skin's L = 10 um.
inline constexpr double kMostFlatRadiusPerLength = 25.0;

/// Widest tip element (TET10; half for TET4) per criterion length: docs/model.md, "Tissue block
/// and mesh", "The stress criterion's length".
inline constexpr double kTipElementsPerCriterionLength = 5.5;

/// Overrides honoured here: tip_size_m (fine_size), growth, elements_through_top. A criterion
/// length (m, > 0) caps the tip element at kTipElementsPerCriterionLength of it, rounded to
/// the next half-integer node spacing per radius.
MeshSizing mesh_sizing(Fidelity fidelity, int order, double needle_radius, double block_size,
                       const FidelityOverrides& overrides = {}, double criterion_length = 0.0);

/// Tetrahedral mesh. 10-node node order: corners 0-3, then edges 01, 12, 20, 03, 13, 23
/// (VTK_QUADRATIC_TETRA order); midside nodes are shared between neighbours.
struct TetMesh {
  int order = 1;
  std::vector<Eigen::Vector3d> nodes;          ///< reference coordinates (m)
  std::vector<std::array<int, 10>> elements;   ///< order 1 uses the first four entries
  std::vector<int> element_layer;              ///< index into layers
  std::vector<std::array<int, 4>> neighbours;  ///< across the face opposite corner i; -1 none
  std::vector<std::array<int, 6>> top_faces;   ///< faces on z = 0: 3 corners, 3 midsides
  std::vector<char> fixed;                     ///< node on the bottom or a side face
  std::vector<TissueLayer> layers;
  std::array<int, 3> grid_cells{};  ///< hexahedral cells in x, y, z
  /// The y >= 0 half of a mirror-symmetric block: nodes on y = 0 lie on the symmetry plane
  /// (not in `fixed`; the solver sets u_y = 0 there).
  bool mirror_y0 = false;
  /// Likewise x >= 0 and the plane x = 0 (u_x = 0 there).
  bool mirror_x0 = false;
  /// m; the contact zone's cell size (a scene's, fine's own or every level's over a flat; 0:
  /// none) and the flat first contacts that a criterion length asked a zone for and did not get
  /// (wider than kMostFlatRadiusPerLength L): docs/model.md, "Tissue block and mesh".
  double contact_zone_m = 0.0;
  int unresolved_flats = 0;

  int nodes_per_element() const { return order == 1 ? 4 : 10; }
  const MaterialParameters& material_of(int element) const {
    return layers[static_cast<std::size_t>(element_layer[static_cast<std::size_t>(element)])]
        .material;
  }
};

/// Builds the block mesh: a structured hexahedral grid graded toward each needle site in x and
/// y, conforming to every layer interface in z, each hexahedron split into six tetrahedra
/// (Kuhn/Freudenthal split, conforming across cells). Throws InputError on a bad spec.
TetMesh generate_tissue_mesh(const TissueBlockSpec& spec);

struct MeshQuality {
  double min_dihedral_deg = 0.0;
  double max_aspect_ratio = 0.0;  ///< longest edge / (2 sqrt(6) inradius): 1 for a regular tet
  double min_volume = 0.0;        ///< m^3
};
MeshQuality mesh_quality(const TetMesh& mesh);

/// Largest ratio of lateral cell size to the thinnest cell height of the grid: a thin stiff
/// top layer forces flat cells all across the block, and this cap bounds how flat.
inline constexpr double kMaxCellAspect = 20.0;

/// Largest ratio of the refined grid's starting lateral size at a site to the unrefined grid's
/// thinnest cell height. Bisection keeps the shapes of the cells it starts from, so a base grid
/// many levels coarser over a thin layer would start (and stay) flatter than the floor below
/// allows; beyond this ratio the grid starts finer and fewer levels are actually used.
inline constexpr double kMaxRefinedCellAspect = 40.0;

/// Documented quality floor of the generator (docs/model.md, "Tissue block and mesh"): with the
/// aspect cap every mesh it makes keeps min dihedral >= kMinDihedralFloorDeg and aspect ratio <=
/// kMaxAspectRatioCeiling (longest edge over 2 sqrt(6) inradius).
inline constexpr double kMinDihedralFloorDeg = 1.2;
inline constexpr double kMaxAspectRatioCeiling = 60.0;

}  // namespace mneedle::fe
