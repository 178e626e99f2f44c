// Built-in tip shape: a flat-ended cylinder (or tube), the tip face at z = 0.
#include <iterator>

#include "plugin_glue.h"

namespace {

using namespace mneedle::shape_kit;

constexpr mneedle_parameter kParameters[] = {
    kDiameterParameter,
    kLengthParameter,
    kBoreParameter,
    kResolutionParameter,
};
constexpr std::size_t kParameterCount = std::size(kParameters);

MeshBuilder make_mesh(const double* params) {
  const TubeParameters tube = read_tube_parameters(params);
  CutPrism prism;
  prism.outer_radius_m = tube.radius_m;
  prism.bore_radius_m = tube.bore_radius_m;
  prism.segments = tube.segments;
  prism.top_z_m = tube.length_m;
  prism.bottom_z_m = [](double) { return 0.0; };
  return build_cut_prism(prism);
}

SectionProperties section(const double* params, double h) {
  const TubeParameters tube = read_tube_parameters(params);
  if (h < 0 || h > tube.length_m) return {0, 0};
  return annulus_properties(tube.radius_m, tube.bore_radius_m);
}

constexpr mneedle_shape kShapes[] = {{
    "cylinder",
    "flat-ended cylinder (a tube when bore > 0)",
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
