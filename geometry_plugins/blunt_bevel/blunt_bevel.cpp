// Built-in tip shape: paper A's blunt bevel, a sharp bevel whose tip is cut flat
// (perpendicular to the axis) where the flat is flat_width wide, measured from the rim
// toward the axis (the sagitta of the flat). The flat lies at z = 0; with tip_radius > 0 every
// edge of the cut is rounded to it (shape_kit's RoundedBevel with a flat).
#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>

#include "plugin_glue.h"

namespace {

using namespace mneedle::shape_kit;

constexpr mneedle_parameter kParameters[] = {
    kDiameterParameter,
    kLengthParameter,
    kBoreParameter,
    kResolutionParameter,
    {"bevel_angle", "rad", std::numbers::pi / 6, 5 * std::numbers::pi / 180,
     85 * std::numbers::pi / 180, "angle between the bevel face and the needle axis"},
    {"flat_width", "m", 50e-6, 0.0, 10e-3,
     "width of the flat at the tip, from the rim toward the axis (sagitta)"},
    {"tip_radius", "m", 0.0, 0.0, 5e-3,
     "radius every edge of the cut is rounded to (the flat's rim, the crease, the cutting edge "
     "and the bore's rim); 0 = sharp edges"},
};
constexpr std::size_t kParameterCount = std::size(kParameters);

struct BluntBevel {
  TubeParameters tube;
  double tan_angle;
  double flat_width_m;
  double tip_radius;
};

BluntBevel read(const double* params) {
  const BluntBevel bevel{read_tube_parameters(params), std::tan(params[4]), params[5], params[6]};
  if (!(bevel.tan_angle > 0)) throw ParameterError("bevel_angle must lie in (0, 90) degrees");
  if (!(bevel.flat_width_m >= 0) || bevel.flat_width_m >= 2 * bevel.tube.radius_m) {
    throw ParameterError("flat_width must be smaller than diameter");
  }
  if (!(bevel.tip_radius >= 0)) throw ParameterError("tip_radius must not be negative");
  return bevel;
}

// With no flat the rounded shape is the rounded sharp bevel, its tip at z = 0 as well.
RoundedBevel rounded(const BluntBevel& bevel) {
  return rounded_bevel_of(bevel.tube, bevel.tan_angle, bevel.tip_radius, bevel.flat_width_m);
}

MeshBuilder make_mesh(const double* params) {
  const BluntBevel bevel = read(params);
  if (bevel.tip_radius > 0) return build_rounded_bevel(rounded(bevel));
  const double crease_x = bevel.tube.radius_m - bevel.flat_width_m;
  CutPrism prism;
  prism.outer_radius_m = bevel.tube.radius_m;
  prism.bore_radius_m = bevel.tube.bore_radius_m;
  prism.segments = bevel.tube.segments;
  prism.top_z_m = bevel.tube.length_m;
  prism.creases_x_m = {crease_x};
  prism.bottom_z_m = [crease_x, t = bevel.tan_angle](double x) {
    return std::max(0.0, (crease_x - x) / t);
  };
  if (!((2 * bevel.tube.radius_m - bevel.flat_width_m) / bevel.tan_angle < bevel.tube.length_m)) {
    throw ParameterError("the bevel is longer than length");
  }
  return build_cut_prism(prism);
}

// The sharp bevel's section shifted down by the height of the cut-off tip, w / tanθ.
SectionProperties section(const double* params, double h) {
  const BluntBevel bevel = read(params);
  if (h < 0 || h > bevel.tube.length_m) return {0, 0};
  if (bevel.tip_radius > 0) return rounded_bevel_section(rounded(bevel), h);
  const double b = bevel.tube.radius_m - bevel.flat_width_m - h * bevel.tan_angle;
  return annulus_segment_properties(bevel.tube.radius_m, bevel.tube.bore_radius_m, b);
}

constexpr mneedle_shape kShapes[] = {{
    "blunt_bevel",
    "sharp bevel with its tip cut flat, flat_width wide from the rim; its edges rounded to "
    "tip_radius",
    kParameters,
    kParameterCount,
    1,
    generate_hook<make_mesh, kParameterCount>,
    section_area_hook<section, kParameterCount>,
    section_properties_hook<section, kParameterCount>,
}};

constexpr mneedle_plugin kPlugin{MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR,
                                 "mneedle.builtin.blunt_bevel", kShapes, std::size(kShapes)};

}  // namespace

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
