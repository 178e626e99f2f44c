#pragma once
// A scene: everything one evaluation needs (tissue block, needles, insertion, model options,
// post-puncture load constants, requirements, user materials), read from a TOML file and
// validated. The format is described in docs/scene.md. Every value here is SI.
//
// Frame: the tissue's undeformed top surface is the plane z = 0; the block spans
// [-size[0]/2, size[0]/2] x [-size[1]/2, size[1]/2] x [-size[2], 0]; needles stand above it at
// their (x, y) and insert toward -z.

#include <array>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "mneedle/base/material_model.h"
#include "mneedle/base/units.h"

namespace mneedle {

/// Elastic constants of one tissue layer.
struct TissueMaterial {
  MaterialModel model = MaterialModel::Linear;
  /// Pa. For Mooney–Rivlin the small-strain value 2 mu (1 + nu), mu = 2 (C10 + C01).
  double youngs_modulus = 0.0;
  /// In (-1, 0.5). For Mooney–Rivlin derived from K when the scene gives K.
  double poisson_ratio = 0.0;
  double c10 = 0.0;  ///< Pa, Mooney–Rivlin only
  double c01 = 0.0;  ///< Pa, Mooney–Rivlin only

  double shear_modulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }
  double bulk_modulus() const { return youngs_modulus / (3.0 * (1.0 - 2.0 * poisson_ratio)); }
};

struct Fracture {
  double toughness = 0.0;          ///< J/m^2 (= N/m), Griffith energy per crack area
  double critical_pressure = 0.0;  ///< Pa, pressure-criterion threshold P_c
  /// The cohesive criterion's traction-separation law (docs/model.md, "The cohesive
  /// criterion"): its peak traction sigma_c (Pa; absent: the layer has no cohesive law) and the
  /// opening at the peak as a fraction of the opening at failure, delta_y / delta_0 in (0, 1).
  std::optional<double> cohesive_strength;
  double cohesive_peak_ratio = 0.01;
};

/// For the stress puncture criterion: the strength the averaged maximum principal stress must
/// reach, and the material length it is averaged over.
struct LayerStrength {
  double strength = 0.0;  ///< Pa
  double length = 0.0;    ///< m
};

struct TissueLayer {
  std::string name;
  double thickness = 0.0;  ///< m
  double top = 0.0;        ///< m, depth of the layer's top face below the surface (>= 0)
  TissueMaterial material;
  /// The layer's own `fracture`, else the tissue's `[tissue.fracture]`, else none.
  std::optional<Fracture> fracture;
  bool fracture_is_own = false;
  std::optional<LayerStrength> strength;
  /// q, Pa: the post-puncture pressure scale of this layer (docs/model.md, "Pressure scale");
  /// absent = derived from [loads]. Given only with its provenance.
  std::optional<double> pressure_scale;
  std::string pressure_scale_source;  ///< where q comes from (a fit, a paper), free text
  int line = 0;  ///< line of the layer in the scene file, for later error messages
};

enum class Boundary { Fixed };

struct Tissue {
  std::array<double, 3> size{};  ///< m: x, y, depth
  Boundary boundary = Boundary::Fixed;
  std::vector<TissueLayer> layers;   ///< top first; thicknesses sum to size[2]
  std::optional<Fracture> fracture;  ///< `[tissue.fracture]` as given (already copied to layers)

  double depth() const { return size[2]; }
};

/// Index of the layer containing the point `depth` below the surface (0 = surface); a point on an
/// interface belongs to the deeper layer; depths beyond the block give the last layer.
std::size_t layer_index_at_depth(const Tissue& tissue, double depth);

/// A needle made by a tip-shape plugin. The plugin knows each parameter's dimension, so the
/// values stay as parsed quantities (convert with quantity_in()).
struct PluginGeometry {
  std::string plugin;
  std::map<std::string, Quantity> parameters;
};

struct StlGeometry {
  std::filesystem::path path;  ///< resolved against the scene file's folder
  std::string unit;            ///< "um" | "mm" | "m"
  double unit_scale = 1e-3;    ///< metres per file unit
  /// The needle's axis in the file: "auto" (principal axis, tip at the narrower end), "x", "y",
  /// "z", or a tip direction "a,b,c" (needle/needle_frame.h, parse_axis_choice).
  std::string axis = "auto";
};

struct NeedleSpec {
  std::string name;  ///< unique in the scene
  std::variant<PluginGeometry, StlGeometry> geometry;
  std::array<double, 2> at{};           ///< m, (x, y) of the needle's axis on the surface
  std::optional<std::string> material;  ///< checked against the material library later
  int line = 0;                         ///< line of the [[needles]] entry
};

struct Insertion {
  double depth = 0.0;                 ///< m, tip travel below the undeformed surface
  double speed = 1e-3;                ///< m/s
  double angle = 1.5707963267948966;  ///< rad, needle axis to surface; only pi/2 is modelled
};

enum class Fidelity { Fast, Standard, Fine };
enum class Output { Puncture, ForceCurve, Fields };
enum class PunctureCriterion { Pressure, Energy, Stress, Penetration, Cohesive };
enum class Contact { Sticking, Frictionless };
/// The energy criterion's crack faces: in frictionless contact, or free to pass through each
/// other (for comparison, or where held faces stop Newton; docs/model.md "Crack faces in contact").
enum class CrackFaces { Contact, Free };

/// Largest `[model] mesh_refinement` (each level halves the element size along the path).
inline constexpr int kMaxMeshRefinement = 3;

struct ModelOptions {
  Fidelity fidelity = Fidelity::Standard;
  std::vector<Output> outputs{Output::Puncture, Output::ForceCurve};
  PunctureCriterion criterion = PunctureCriterion::Pressure;
  Contact contact = Contact::Sticking;
  CrackFaces crack_faces = CrackFaces::Contact;
  /// 3-D TET10 tissue mesh: halvings of its grid along the needles' paths (docs/model.md,
  /// "Tissue block and mesh"); empty: the fidelity's default (2 at fine, 0 below).
  std::optional<int> mesh_refinement;
  /// 3-D TET10 tissue mesh: element size (m) in the top layer around each needle's first
  /// contact, and the size it grades down to toward a pointed one (docs/model.md, "Tissue block
  /// and mesh", contact zone; docs/validation.md, "The 3-D model under a point load, resolved");
  /// empty: the level's own (fine's under a pointed tip, every level's over a flat); 0 (the
  /// scene's "none"): no zone at all.
  std::optional<double> contact_zone;
  std::optional<double> contact_zone_tip;

  bool wants(Output o) const;
};

enum class FrictionLaw { Coulomb, LinearGrowth, None };

/// How the layer pressure scales of the post-puncture model are obtained (docs/model.md).
enum class LoadMode {
  Distributed,  ///< q per layer: given, or S E / (1 - nu^2); beta length from the needle
  PaperAFig17,  ///< paper A Fig. 17: K = E D / (4 H) of its phantom, beta length 1 um
};

/// Constants of paper A's post-puncture distributed-load model (provenance in docs/scene.md).
struct Loads {
  LoadMode mode = LoadMode::Distributed;
  double scale = 0.168;                     ///< S, paper A Fig. 22 (sharp bevel in silicone)
  std::optional<double> stiffness;          ///< K, Pa; absent = derived from the layer modulus
  std::optional<double> beta_length;        ///< l, m; absent = the needle's R_ref
  std::optional<double> specimen_diameter;  ///< m, paper_a_fig17 only (paper A: 44.107 mm)
  std::optional<double> specimen_height;    ///< m, paper_a_fig17 only (paper A: 21.145 mm)
  FrictionLaw friction = FrictionLaw::Coulomb;
  double friction_coefficient = 0.2;       ///< mu, paper B (needle-tissue)
  double friction_max_force = 0.0;         ///< N, linear_growth only (paper C eq. 2, F_max)
  double friction_saturation_depth = 0.0;  ///< m, linear_growth only (paper C eq. 2, d)
};

struct Requirements {
  std::optional<double> target_depth;  ///< m
  double safety_factor = 1.5;          ///< capacity / peak force must reach this
};

/// A needle material defined in the scene (`[[materials]]`).
struct UserMaterial {
  std::string name;
  double youngs_modulus = 0.0;  ///< Pa
  double poisson_ratio = 0.0;
  double strength = 0.0;          ///< Pa (yield or fracture strength)
  std::optional<double> density;  ///< kg/m^3
  int line = 0;
};

struct Scene {
  std::string source_name;  ///< the file as named by the user, for messages
  Tissue tissue;
  std::vector<NeedleSpec> needles;  ///< at least one
  Insertion insertion;
  ModelOptions model;
  Loads loads;
  Requirements requirements;
  std::vector<UserMaterial> materials;
};

/// Reads and validates a scene file. Throws InputError "<file>:<line>: <key path>: <problem>".
Scene load_scene(const std::filesystem::path& file);

/// Same for TOML text; `source_name` names it in messages and its folder anchors relative STL
/// paths.
Scene parse_scene(std::string_view toml, std::string source_name);

std::string_view to_string(Boundary b);  ///< "fixed"
std::string_view to_string(Fidelity f);  ///< "fast", "standard", "fine"
std::string_view to_string(Output o);    ///< "puncture", "force_curve", "fields"
/// "pressure", "energy", "stress", "penetration", "cohesive"
std::string_view to_string(PunctureCriterion c);
std::string_view to_string(Contact c);      ///< "sticking", "frictionless"
std::string_view to_string(CrackFaces c);   ///< "contact", "free"
std::string_view to_string(FrictionLaw f);  ///< "coulomb", "linear_growth", "none"

}  // namespace mneedle
