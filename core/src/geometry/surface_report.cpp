#include "mneedle/geometry/surface_report.h"

#include <cmath>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/geometry/cross_section.h"

namespace mneedle {

std::vector<double> default_tip_area_heights(const TriangleMesh& mesh) {
  const BoundingBox box = bounding_box(mesh);
  const double length = box.max[2] - box.min[2];
  std::vector<double> heights;
  for (double um : {5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0}) {
    // Strictly inside: a plane through the needle's end face gives no proper section.
    if (um * 1e-6 < length * (1.0 - 1e-9)) heights.push_back(um * 1e-6);
  }
  return heights;
}

SurfaceReport surface_report(const TriangleMesh& mesh, const std::vector<double>& heights_m) {
  SurfaceReport report;
  report.groups = classify_surface(mesh);
  const std::vector<double> heights =
      heights_m.empty() ? default_tip_area_heights(mesh) : heights_m;
  for (double h : heights) {
    if (!(h >= 0.0) || !std::isfinite(h)) {
      throw InputError("tip area heights: " + std::to_string(h) + " m is not a height >= 0");
    }
  }
  if (heights.empty()) return report;
  const CrossSectionSlicer slicer(mesh);
  for (double h : heights) report.tip_area.push_back({h, slicer.slice(h).area_m2});
  return report;
}

}  // namespace mneedle
