#pragma once
// The footprint of a needle on the tissue: the convex hull (CGAL, 2-D) of the part of the needle
// below the tissue surface, projected on the surface. Paper A maps this hull onto the tissue to
// find its contact nodes (Fig. 3).

#include <vector>

#include "mneedle/geometry/cross_section.h"
#include "mneedle/needle/mesh.h"

namespace mneedle {

struct Footprint {
  double depth_m = 0.0;      ///< tip depth below the surface
  std::vector<Point2> hull;  ///< counter-clockwise (x, y), empty above the surface
  double area_m2 = 0.0;
};

/// Hull of the needle-frame mesh (axis along z, tip = lowest vertex) cut at height depth_m above
/// the tip: vertices below the plane and the points where edges cross it, projected on (x, y).
/// A negative or NaN depth gives an empty footprint.
Footprint footprint(const TriangleMesh& mesh, double depth_m);

}  // namespace mneedle
