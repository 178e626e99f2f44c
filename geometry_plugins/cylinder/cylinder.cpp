// Built-in tip shape: a flat-ended cylinder (or tube), the tip face at z = 0, its rim optionally
// rounded by a quarter torus of radius edge_radius (0 = a sharp edge).
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
    {"edge_radius", "m", 0.0, 0.0, 5e-3,
     "radius of the quarter torus rounding the flat end's outer rim; 0 = a sharp edge"},
};
constexpr std::size_t kParameterCount = std::size(kParameters);

struct Cylinder {
  TubeParameters tube;
  double edge_radius;  // ρ: the rim's rounding

  // Outer radius of the section at height z above the flat end.
  double outer_radius(double z) const {
    if (z >= edge_radius) return tube.radius_m;
    const double rise = edge_radius - z;
    return tube.radius_m - edge_radius + std::sqrt(edge_radius * edge_radius - rise * rise);
  }
};

Cylinder read(const double* params) {
  const Cylinder c{read_tube_parameters(params), params[4]};
  if (!(c.edge_radius >= 0)) throw ParameterError("edge_radius must not be negative");
  if (c.edge_radius > c.tube.radius_m - c.tube.bore_radius_m) {
    throw ParameterError("edge_radius is too large: the rounding would be wider than the wall");
  }
  if (!(c.edge_radius < c.tube.length_m)) {
    throw ParameterError("edge_radius must be below length");
  }
  return c;
}

MeshBuilder make_mesh(const double* params) {
  const Cylinder c = read(params);
  if (c.edge_radius == 0.0) {
    CutPrism prism;
    prism.outer_radius_m = c.tube.radius_m;
    prism.bore_radius_m = c.tube.bore_radius_m;
    prism.segments = c.tube.segments;
    prism.top_z_m = c.tube.length_m;
    prism.bottom_z_m = [](double) { return 0.0; };
    return build_cut_prism(prism);
  }
  // The closed (r, z) profile: across the flat, round the rim's quarter circle in steps no
  // coarser than the polygon's, up the outside, across the base, down the bore.
  const double rho = c.edge_radius, R = c.tube.radius_m, rb = c.tube.bore_radius_m;
  std::vector<ProfilePoint> loop{{rb, 0.0}};
  if (R - rho > rb * (1 + 1e-9)) loop.push_back({R - rho, 0.0});
  const double step = 2 * std::numbers::pi / c.tube.segments;
  const int arcs = std::max(2, static_cast<int>(std::ceil(std::numbers::pi / 2 / step)));
  for (int k = 1; k <= arcs; ++k) {
    const double psi = std::numbers::pi / 2 * k / arcs;
    loop.push_back({R - rho + rho * std::sin(psi), rho * (1 - std::cos(psi))});
  }
  loop.push_back({R, c.tube.length_m});
  loop.push_back({rb, c.tube.length_m});
  return build_revolved(loop, c.tube.segments);
}

SectionProperties section(const double* params, double h) {
  const Cylinder c = read(params);
  if (h < 0 || h > c.tube.length_m) return {0, 0};
  return annulus_properties(c.outer_radius(h), c.tube.bore_radius_m);
}

constexpr mneedle_shape kShapes[] = {{
    "cylinder",
    "flat-ended cylinder (a tube when bore > 0), its rim rounded by edge_radius",
    kParameters,
    kParameterCount,
    1,
    generate_hook<make_mesh, kParameterCount>,
    section_area_hook<section, kParameterCount>,
    section_properties_hook<section, kParameterCount>,
}};

constexpr mneedle_plugin kPlugin{MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR,
                                 "mneedle.builtin.cylinder", kShapes, std::size(kShapes)};

}  // namespace

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
