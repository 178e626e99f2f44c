// Built-in tip shape: a conical taper of semi-apical angle half_angle that ends where it
// meets the shaft, its point rounded by a tangent spherical cap of radius tip_radius
// (0 = sharp). A bore turns the point into a knife-edge ring, which then lies at z = 0.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <vector>

#include "plugin_glue.h"

namespace {

using namespace mneedle::shape_kit;

constexpr mneedle_parameter kParameters[] = {
    kDiameterParameter,
    kLengthParameter,
    kBoreParameter,
    kResolutionParameter,
    {"half_angle", "rad", 15 * std::numbers::pi / 180, 1 * std::numbers::pi / 180,
     89 * std::numbers::pi / 180, "semi-apical angle of the taper (from the axis)"},
    {"tip_radius", "m", 0.0, 0.0, 5e-3,
     "radius of the spherical cap rounding the point; 0 = sharp"},
};
constexpr std::size_t kParameterCount = std::size(kParameters);

// Geometry before shifting the lowest point to z = 0: the apex region starts at z = 0.
struct Cone {
  TubeParameters tube;
  double half_angle;
  double cap_radius;  // ρ
  double tangent_r;   // where the cap meets the cone
  double tangent_z;
  double shaft_z;  // where the taper meets the shaft
  double edge_z;   // lowest point of the solid (the bore's edge for a hollow cone)

  double outer_radius(double z) const {
    if (z < tangent_z)
      return std::sqrt(
          std::max(0.0, cap_radius * cap_radius - (cap_radius - z) * (cap_radius - z)));
    if (z < shaft_z) return tangent_r + (z - tangent_z) * std::tan(half_angle);
    return tube.radius_m;
  }
};

Cone read(const double* params) {
  Cone cone{read_tube_parameters(params), params[4], params[5], 0, 0, 0, 0};
  if (!(cone.half_angle > 0 && cone.half_angle < std::numbers::pi / 2)) {
    throw ParameterError("half_angle must lie in (0, 90) degrees");
  }
  if (!(cone.cap_radius >= 0)) throw ParameterError("tip_radius must not be negative");
  cone.tangent_r = cone.cap_radius * std::cos(cone.half_angle);
  cone.tangent_z = cone.cap_radius * (1 - std::sin(cone.half_angle));
  if (cone.tangent_r >= cone.tube.radius_m) {
    throw ParameterError("tip_radius is too large: the cap would be wider than diameter");
  }
  const double tan_a = std::tan(cone.half_angle);
  cone.shaft_z = cone.tangent_z + (cone.tube.radius_m - cone.tangent_r) / tan_a;
  const double rb = cone.tube.bore_radius_m;
  if (rb <= 0) {
    cone.edge_z = 0;
  } else if (rb <= cone.tangent_r) {
    cone.edge_z = cone.cap_radius - std::sqrt(cone.cap_radius * cone.cap_radius - rb * rb);
  } else {
    cone.edge_z = cone.tangent_z + (rb - cone.tangent_r) / tan_a;
  }
  if (!(cone.shaft_z - cone.edge_z < cone.tube.length_m)) {
    throw ParameterError("the taper is longer than length: increase half_angle or length");
  }
  return cone;
}

// The closed (r, z) profile: up the outside from the point, across the base, down the bore.
std::vector<ProfilePoint> profile(const Cone& cone) {
  const double rb = cone.tube.bore_radius_m;
  const double top = cone.edge_z + cone.tube.length_m;
  std::vector<ProfilePoint> loop{{rb, cone.edge_z}};
  if (cone.cap_radius > 0) {
    const double cap_angle = std::numbers::pi / 2 - cone.half_angle;
    const double step = 2 * std::numbers::pi / cone.tube.segments;
    const int arcs = std::max(2, static_cast<int>(std::ceil(cap_angle / step)));
    for (int k = 1; k <= arcs; ++k) {
      const double psi = cap_angle * k / arcs;
      const ProfilePoint p{cone.cap_radius * std::sin(psi), cone.cap_radius * (1 - std::cos(psi))};
      if (p.r > rb * (1 + 1e-9)) loop.push_back(p);
    }
  }
  loop.push_back({cone.tube.radius_m, cone.shaft_z});
  loop.push_back({cone.tube.radius_m, top});
  loop.push_back({rb, top});
  for (auto& p : loop) p.z -= cone.edge_z;
  return loop;
}

MeshBuilder make_mesh(const double* params) {
  const Cone cone = read(params);
  return build_revolved(profile(cone), cone.tube.segments);
}

SectionProperties section(const double* params, double h) {
  const Cone cone = read(params);
  if (h < 0 || h > cone.tube.length_m) return {0, 0};
  const double r = std::max(cone.outer_radius(h + cone.edge_z), cone.tube.bore_radius_m);
  return annulus_properties(r, cone.tube.bore_radius_m);
}

constexpr mneedle_shape kShapes[] = {{
    "cone",
    "conical taper of half_angle meeting the shaft, point rounded by tip_radius",
    kParameters,
    kParameterCount,
    1,
    generate_hook<make_mesh, kParameterCount>,
    section_area_hook<section, kParameterCount>,
    section_properties_hook<section, kParameterCount>,
}};

constexpr mneedle_plugin kPlugin{MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR,
                                 "mneedle.builtin.cone", kShapes, std::size(kShapes)};

}  // namespace

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
