#pragma once
// Paper A's post-puncture force (section 3): the tissue loads each forward-facing triangle of
// the part of the needle below the surface, uniformly on alpha flats (eq. 18) and linearly on
// beta slopes (pentahedron resultants, eqs. 19-20), plus friction on the shaft (paper B section
// 3.3, Coulomb; or paper C eq. 2, linear growth). docs/model.md gives the reconstruction.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/geometry/surface_groups.h"
#include "mneedle/needle/mesh.h"

namespace mneedle {

struct Scene;

enum class ShaftFriction { none, coulomb, linear_growth };

/// distributed: each layer's pressure scale q is given or S E / (1 - nu^2), and the beta load
/// rises over the length l (default R_ref). paper_a_fig17: paper A's Fig. 17 as published,
/// K = E D / (4 H) of its cylindrical phantom and l = 1 um (docs/model.md, "Pressure scale").
enum class LoadModelMode { distributed, paper_a_fig17 };

/// One tissue layer, listed from the surface down; the last one reaches the tissue's bottom
/// (LoadConstants::tissue_depth_m) or, without one, extends without end.
struct LoadLayer {
  double thickness_m = 0.0;
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
  std::optional<double> pressure_scale_Pa;  ///< q of this layer when given (a fit)
  std::string pressure_scale_source;        ///< its provenance, required with it
  /// Caps the lateral wall pressure (beta faces, shaft): a hole pressed wider than the layer's
  /// tensile strength splits it (hoop stress = wall pressure, Lame). Empty: no cap.
  std::optional<double> tensile_strength_Pa;
  /// Caps the pressure on alpha faces (ahead of the tip): the tissue there cuts at its critical
  /// pressure, the pressure criterion's threshold. Empty: no cap.
  std::optional<double> critical_pressure_Pa;
};

/// A layer's resolved pressure scale, the cap on its wall pressure, and where q comes from.
struct LayerPressure {
  double pressure_scale_Pa = 0.0;        ///< q = K S, Pa
  double wall_pressure_cap_Pa = 0.0;     ///< strength: caps beta loads and friction; +inf: none
  double cutting_pressure_cap_Pa = 0.0;  ///< P_c: caps alpha loads; +inf: none
  std::string source;
};

/// The constants of the model, independent of the scene file (Scene's [loads] maps onto this).
struct LoadConstants {
  LoadModelMode mode = LoadModelMode::distributed;
  double scale = 0.168;                 ///< S, paper A Fig. 22 (its sharp bevel in silicone)
  std::optional<double> stiffness_Pa;   ///< K for every layer; derived per layer when absent
  std::optional<double> beta_length_m;  ///< l of the beta load; empty: R_ref (distributed mode)
  std::optional<double> specimen_diameter_m;  ///< D, paper_a_fig17 only
  std::optional<double> specimen_height_m;    ///< H, paper_a_fig17 only
  ShaftFriction friction = ShaftFriction::coulomb;
  double friction_coefficient = 0.2;                  ///< mu, paper B (needle on liver)
  std::optional<double> friction_max_force_N;         ///< F_max of the linear-growth law
  std::optional<double> friction_saturation_depth_m;  ///< d of the linear-growth law
  std::vector<LoadLayer> layers;                      ///< from the surface down
  /// Depth of the tissue's bottom face: below it the needle is out of the tissue and carries
  /// no load (a needle passing through a sample). Empty: the last layer extends without end.
  std::optional<double> tissue_depth_m;
};

/// The scene's [loads] table and tissue layers as load constants (friction_max_force and
/// friction_saturation_depth are passed on only for the linear-growth law).
LoadConstants load_constants(const Scene& scene);

/// K of a layer: its plane-strain modulus E / (1 - nu^2), in Pa (derivation in docs/model.md).
double layer_stiffness(const LoadLayer& layer);

/// The pressure scale of every layer (one entry per layer; one entry when there are no layers
/// and `stiffness_Pa` is given), with its provenance. Throws InputError for invalid constants.
std::vector<LayerPressure> layer_pressures(const LoadConstants& constants);

/// The beta-load length l of paper_a_fig17 mode: paper A's numbers are in micrometres.
inline constexpr double kPaperAFig17BetaLength_m = 1e-6;

/// One point of the post-puncture curve; forces along the insertion direction, in N.
struct LoadSample {
  double depth_m = 0.0;     ///< the tip's travel below the undeformed surface
  double alpha_N = 0.0;     ///< uniform load on alpha faces, eq. 18
  double beta_N = 0.0;      ///< linearly distributed load on beta faces, eqs. 19-20
  double friction_N = 0.0;  ///< shaft friction
  double force_N = 0.0;     ///< the sum
};

/// Resultant of a linearly distributed load on a triangle (eqs. 19-20): the volume of the
/// pentahedron over the triangle whose heights are the vertex loads (Pa), summed from one
/// tetrahedron (two vertices unloaded), two (one unloaded) or three (none). Returns N.
double pentahedron_load(const std::array<Vec3, 3>& triangle,
                        const std::array<double, 3>& vertex_loads_Pa);

/// The model for repeated evaluation of one needle: per-face data (group, heights above the tip,
/// local coordinates, inclination) are computed once; at() then costs one pass over the faces.
/// The mesh must be closed and outward-oriented; it may sit anywhere and point anywhere as long
/// as `direction` is its insertion direction.
class SurfaceLoadModel {
 public:
  /// Throws InputError for invalid constants, a missing K (neither stiffness nor layers), or a
  /// mesh without faces looking along `direction`.
  SurfaceLoadModel(const TriangleMesh& mesh, const LoadConstants& constants,
                   const Vec3& direction = kNeedleFrameInsertion,
                   const GroupTolerances& tolerances = {});

  /// Load with the tip depth_m below the surface (0 above it). Throws InputError for NaN.
  LoadSample at(double depth_m) const;
  /// The same, and each layer's share of it in `by_layer` (one sample per layer, from the top;
  /// a paper C friction law, not a layer's, is in the total only).
  LoadSample at(double depth_m, std::vector<LoadSample>* by_layer) const;

  std::vector<LoadSample> curve(const std::vector<double>& depths_m) const;

  /// Sum of forward faces' areas projected on the plane normal to the axis, m^2.
  double frontal_area_m2() const { return frontal_area_m2_; }
  /// sqrt(frontal area / pi): the default beta length l.
  double reference_radius_m() const { return reference_radius_m_; }
  /// l: the height above the tip (times tan theta) over which a beta face's load rises to q.
  double beta_length_m() const { return beta_length_m_; }
  const std::vector<LayerPressure>& layers() const { return layers_; }

  struct Vertex {
    double u, v;    ///< in the face's own plane, m
    double height;  ///< above the tip along the axis, m
  };
  struct Face {
    SurfaceGroup group;
    double along;      ///< n.d
    double tan_theta;  ///< tangent of the face's inclination to the axis (beta faces)
    std::array<Vertex, 3> vertex;
    double lowest, highest;
    bool in_bore;  ///< a side face looking toward the axis: a bore wall, no tissue contact
  };

 private:
  void add_face(const Face& face, double depth_m, LoadSample& sample,
                std::vector<LoadSample>* by_layer) const;
  void add_piece(const Face& face, const std::vector<Vertex>& polygon, const LayerPressure& layer,
                 LoadSample& sample) const;
  void add_beta(const Face& face, const std::vector<Vertex>& polygon, const LayerPressure& layer,
                LoadSample& sample) const;

  LoadConstants constants_;
  std::vector<Face> faces_;
  std::vector<double> layer_bottom_m_;  ///< depth below the surface of each layer's bottom
  std::vector<LayerPressure> layers_;
  double frontal_area_m2_ = 0.0;
  double reference_radius_m_ = 0.0;
  double beta_length_m_ = 0.0;
};

/// One-off evaluation at a single depth (see SurfaceLoadModel).
LoadSample surface_load(const TriangleMesh& mesh, const LoadConstants& constants, double depth_m,
                        const Vec3& direction = kNeedleFrameInsertion);

}  // namespace mneedle
