#pragma once
// Where a needle comes from: a mesh file, a plugin with --set values, or a scene's [[needles]]
// entry. Every path ends in a validated mesh in the needle frame.

#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/fe/axisymmetric.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"

namespace mneedle {

/// The default axis choice for mesh files: automatic.
inline AxisChoice automatic_axis() {
  AxisChoice a;
  a.kind = AxisChoice::Kind::automatic;
  return a;
}

struct NeedleSource {
  std::string name;
  TriangleMesh mesh;                     // metres, needle frame
  std::optional<std::string> plugin;     // the shape, when made by a plugin
  std::map<std::string, double> params;  // SI, the shape's parameters (defaults filled in)
  /// Mesh files: how the axis and tip were found and whether a holder was cut off; empty when
  /// the input z was the axis and the whole mesh is the needle (nothing worth saying).
  std::string frame_note;
};

/// "key=value" settings (values with units, e.g. diameter=230um) → SI values checked against the
/// shape's parameter units. InputError names the setting and the problem.
std::map<std::string, double> parse_parameter_settings(const PluginShapeInfo& shape,
                                                       const std::vector<std::string>& settings);

/// Parsed quantities (a scene's or a design list's) → SI values for the shape; `where` prefixes
/// the key in messages.
std::map<std::string, double> scene_parameters(const PluginShapeInfo& shape,
                                               const std::map<std::string, Quantity>& given,
                                               const std::string& where);

/// Loads, validates and places a mesh file in the needle frame (`axis`: see AxisChoice; the
/// default finds the principal axis, tip at the narrower end) and cuts off a holder or base the
/// needle stands on (geometry/holder.h), placing the needle alone again. `repair` runs
/// repair_mesh first (outward orientation, degenerate faces, borders) and notes what it changed.
NeedleSource needle_from_file(const std::filesystem::path& file, double metres_per_unit,
                              const AxisChoice& axis = automatic_axis(), bool repair = false);

NeedleSource needle_from_plugin(const PluginRegistry& registry, const std::string& shape,
                                const std::map<std::string, double>& params_si);

/// The scene's needle built from its plugin or mesh file; InputError messages start with `where`
/// (scene_needle_where: the scene's file and the entry's line).
NeedleSource needle_from_scene(const PluginRegistry& registry, const NeedleSpec& spec,
                               const std::string& where);
/// "FILE:LINE: needle 'NAME'" for the scene's [[needles]] entry `spec`.
std::string scene_needle_where(const Scene& scene, const NeedleSpec& spec);

/// The outer profile of a body-of-revolution plugin needle (the cylinder and cone plugins),
/// sampled from the plugin's section area A(h) = pi (r_out^2 - r_bore^2); nullopt for any other
/// shape (round meshes: revolution_profile, below). `where` prefixes messages.
std::optional<fe::AxisymmetricNeedle> axisymmetric_profile(const PluginRegistry& registry,
                                                           const NeedleSource& needle,
                                                           const std::string& where);

/// Largest angle between neighbouring vertices of one ring for a mesh to count as a body of
/// revolution: 30 deg, twelve facets round (the STLs mneedle writes have 64).
inline constexpr double kLargestRevolutionGap_rad = std::numbers::pi / 6.0;

/// The profile of a mesh needle (in its needle frame: axis z) that is a solid body of
/// revolution: every height's vertices off the axis lie on one circle all the way round (no gap
/// above kLargestRevolutionGap_rad), and half-way between two such heights the faces cut one
/// loop that goes round too. The profile runs through the rings, each at its polygon's
/// equal-area radius; a flat punch when the end is flat. nullopt otherwise: a bevel (its rings
/// are open), a hollow or stepped needle (two radii at one height), a pyramid (square sections),
/// a sealed cavity (two loops), an open surface.
std::optional<fe::AxisymmetricNeedle> revolution_profile(const TriangleMesh& mesh);

/// True when the mirror image (x, -y, z) of every vertex is a vertex (within 1e-6 of the mesh
/// size): the needle is symmetric about its y = 0 plane (bevels, bodies of revolution).
bool mirror_symmetric_y0(const TriangleMesh& mesh);
/// The same for the image (-x, y, z): symmetric about its x = 0 plane (bodies of revolution).
bool mirror_symmetric_x0(const TriangleMesh& mesh);

/// What a needle's shape lets the pre-puncture model reduce (docs/model.md, "Half and quarter
/// models"): the body-of-revolution profile and the mirror planes through its axis.
struct NeedleSymmetry {
  std::optional<fe::AxisymmetricNeedle> axisymmetric;  // cylinder and cone plugins, round meshes
  bool mirror_y0 = false;                              // symmetric about its y = 0 plane
  bool mirror_x0 = false;                              // symmetric about its x = 0 plane
};

/// The symmetry of a needle, taken the same way for every command (simulate, screen, optimize,
/// uncertainty), so that one needle solves one reduced model and gives one number on every path.
NeedleSymmetry needle_symmetry(const PluginRegistry& registry, const NeedleSource& needle,
                               const std::string& where);

/// Copies a needle's symmetry into the planner's description of it.
void apply_symmetry(const NeedleSymmetry& symmetry, PreparedNeedle& needle);

/// True when a needle of the scene is a plugin shape: STL-only scenes run without plugins.
bool needs_plugins(const Scene& scene);

/// The number of needles a scene may hold unless the caller says otherwise: each one is a mesh
/// to build or read and a curve to compute, so a scene of 10 000 needles would work for minutes
/// before anything else could refuse it.
inline constexpr std::size_t kDefaultMaxNeedles = 1000;

/// Every needle of the scene ready for run_insertion, in the scene's order. Throws InputError
/// before any needle is built when the scene holds more than `max_needles`.
std::vector<PreparedNeedle> prepare_needles(const PluginRegistry& registry, const Scene& scene,
                                            std::size_t max_needles = kDefaultMaxNeedles);

}  // namespace mneedle
