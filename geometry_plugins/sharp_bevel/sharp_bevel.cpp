// Built-in tip shape: a tube cut by one plane at bevel_angle to the axis (paper A's sharp
// bevel). The tip is the rim point on +x at z = 0; with tip_radius > 0 every edge of the cut is
// rounded to it (shape_kit's RoundedBevel) and the tip is the rounded edge's lowest point.
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
    {"tip_radius", "m", 0.0, 0.0, 5e-3,
     "radius every edge of the bevel is rounded to (its tip, cutting edge and bore rim); 0 = "
     "sharp"},
};
constexpr std::size_t kParameterCount = std::size(kParameters);

struct Bevel {
  TubeParameters tube;
  double tan_angle;
  double tip_radius;
};

Bevel read(const double* params) {
  const Bevel bevel{read_tube_parameters(params), std::tan(params[4]), params[5]};
  if (!(bevel.tan_angle > 0)) throw ParameterError("bevel_angle must lie in (0, 90) degrees");
  if (!(bevel.tip_radius >= 0)) throw ParameterError("tip_radius must not be negative");
  return bevel;
}

RoundedBevel rounded(const Bevel& bevel) {
  return rounded_bevel_of(bevel.tube, bevel.tan_angle, bevel.tip_radius);
}

MeshBuilder make_mesh(const double* params) {
  const Bevel bevel = read(params);
  if (bevel.tip_radius > 0) return build_rounded_bevel(rounded(bevel));
  const double r = bevel.tube.radius_m;
  CutPrism prism;
  prism.outer_radius_m = r;
  prism.bore_radius_m = bevel.tube.bore_radius_m;
  prism.segments = bevel.tube.segments;
  prism.top_z_m = bevel.tube.length_m;
  prism.bottom_z_m = [r, t = bevel.tan_angle](double x) { return (r - x) / t; };
  if (!(2 * r / bevel.tan_angle < bevel.tube.length_m)) {
    throw ParameterError("the bevel (diameter / tan(bevel_angle)) is longer than length");
  }
  return build_cut_prism(prism);
}

// At height h the bevel plane has moved h·tanθ in from the rim: the section is the part
// x >= R - h·tanθ of the annulus.
SectionProperties section(const double* params, double h) {
  const Bevel bevel = read(params);
  if (h < 0 || h > bevel.tube.length_m) return {0, 0};
  if (bevel.tip_radius > 0) return rounded_bevel_section(rounded(bevel), h);
  const double b = bevel.tube.radius_m - h * bevel.tan_angle;
  return annulus_segment_properties(bevel.tube.radius_m, bevel.tube.bore_radius_m, b);
}

constexpr mneedle_shape kShapes[] = {{
    "sharp_bevel",
    "tube cut by one plane at bevel_angle to the axis; the tip is a point on the rim, its edges "
    "rounded to tip_radius",
    kParameters,
    kParameterCount,
    1,
    generate_hook<make_mesh, kParameterCount>,
    section_area_hook<section, kParameterCount>,
    section_properties_hook<section, kParameterCount>,
}};

constexpr mneedle_plugin kPlugin{MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR,
                                 "mneedle.builtin.sharp_bevel", kShapes, std::size(kShapes)};

}  // namespace

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
