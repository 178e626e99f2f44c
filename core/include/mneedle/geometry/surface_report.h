#pragma once
// The surface analysis of one needle as `mneedle inspect` reports it: the four face groups and
// the sliced tip cross-section A(h) at a set of heights.

#include <vector>

#include "mneedle/geometry/surface_groups.h"
#include "mneedle/needle/mesh.h"

namespace mneedle {

struct TipAreaPoint {
  double height_m = 0.0;
  double area_m2 = 0.0;
};

struct SurfaceReport {
  SurfaceGroups groups;
  std::vector<TipAreaPoint> tip_area;
};

/// The documented default heights: 5, 10, 20, 50, 100, 200, 500 and 1000 um, keeping those below
/// the needle's length along z (the mesh in the needle frame).
std::vector<double> default_tip_area_heights(const TriangleMesh& mesh);

/// Groups (needle-frame insertion direction, default tolerances) and sliced A(h) at `heights_m`
/// (the defaults when empty). The mesh must be in the needle frame and closed; throws InputError
/// otherwise or for a negative height.
SurfaceReport surface_report(const TriangleMesh& mesh, const std::vector<double>& heights_m = {});

}  // namespace mneedle
