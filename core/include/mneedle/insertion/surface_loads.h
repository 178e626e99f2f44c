#pragma once
// Paper A's post-puncture force (section 3): the tissue loads each forward-facing triangle of
// the part of the needle below the surface, uniformly on alpha flats (eq. 18) and linearly on
// beta slopes (pentahedron resultants, eqs. 19-20), plus friction on the shaft (paper B section
// 3.3, Coulomb; or paper C eq. 2, linear growth). docs/model.md gives the reconstruction.

#include <array>
#include <optional>
#include <vector>

#include "mneedle/geometry/surface_groups.h"
#include "mneedle/needle/mesh.h"

namespace mneedle {

struct Scene;

enum class ShaftFriction { none, coulomb, linear_growth };

/// One tissue layer, listed from the surface down; the last one extends without end.
struct LoadLayer {
  double thickness_m = 0.0;
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
};

/// The constants of the model, independent of the scene file (Scene's [loads] maps onto this).
struct LoadConstants {
  double scale = 0.168;                ///< S, paper A Fig. 22 (its sharp bevel in silicone)
  std::optional<double> stiffness_Pa;  ///< K for every layer; derived per layer when absent
  ShaftFriction friction = ShaftFriction::coulomb;
  double friction_coefficient = 0.2;                  ///< mu, paper B (needle on liver)
  std::optional<double> friction_max_force_N;         ///< F_max of the linear-growth law
  std::optional<double> friction_saturation_depth_m;  ///< d of the linear-growth law
  std::vector<LoadLayer> layers;                      ///< from the surface down
};

/// The scene's [loads] table and tissue layers as load constants (friction_max_force and
/// friction_saturation_depth are passed on only for the linear-growth law).
LoadConstants load_constants(const Scene& scene);

/// K of a layer: its plane-strain modulus E / (1 - nu^2), in Pa (derivation in docs/model.md).
double layer_stiffness(const LoadLayer& layer);

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

  std::vector<LoadSample> curve(const std::vector<double>& depths_m) const;

  /// Sum of forward faces' areas projected on the plane normal to the axis, m^2.
  double frontal_area_m2() const { return frontal_area_m2_; }
  /// sqrt(frontal area / pi): the length over which a beta face's load rises to K S.
  double reference_radius_m() const { return reference_radius_m_; }

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
  void add_face(const Face& face, double depth_m, LoadSample& sample) const;
  void add_piece(const Face& face, const std::vector<Vertex>& polygon, double k_Pa,
                 LoadSample& sample) const;

  LoadConstants constants_;
  std::vector<Face> faces_;
  std::vector<double> layer_bottom_m_;  ///< depth below the surface of each layer's bottom
  std::vector<double> layer_k_Pa_;
  double frontal_area_m2_ = 0.0;
  double reference_radius_m_ = 0.0;
};

/// One-off evaluation at a single depth (see SurfaceLoadModel).
LoadSample surface_load(const TriangleMesh& mesh, const LoadConstants& constants, double depth_m,
                        const Vec3& direction = kNeedleFrameInsertion);

}  // namespace mneedle
