#pragma once
// Cross-sections of a needle mesh perpendicular to its axis, sliced by CGAL's
// Polygon_mesh_slicer: the sliced A(h) any STL gets, the analytic one's check (tip_area.h).

#include <array>
#include <memory>
#include <vector>

#include "mneedle/needle/mesh.h"

namespace mneedle {

using Point2 = std::array<double, 2>;

struct CrossSection {
  double height_m = 0.0;                      ///< above the tip (the mesh's lowest vertex)
  std::vector<std::vector<Point2>> polygons;  ///< closed loops in (x, y), first point not repeated
  double area_m2 = 0.0;                       ///< outer loops minus the holes they contain (bores)
  /// Area of the section's convex hull: the needle's outline at this height with the bore (and
  /// a hollow bevel's crescent) filled, the area the pressure criterion divides by
  /// (docs/model.md, "Criteria").
  double outline_area_m2 = 0.0;
};

/// Net area of nested loops: each loop's |shoelace area| counted + when an even number of the
/// other loops contain it and - when odd, so a bore inside a shaft is subtracted.
double nested_polygon_area(const std::vector<std::vector<Point2>>& polygons);

/// Area of the convex hull of every loop's points (holes, crescents and notches filled).
double outline_area(const std::vector<std::vector<Point2>>& polygons);

/// Thinnest wall of a section (m): for a material loop with holes (a bore) the smallest distance
/// between the loop and its holes; for a solid loop the distance from its area centroid to its
/// nearest edge. 0 for an empty section.
double thinnest_wall(const std::vector<std::vector<Point2>>& polygons);

/// +1 when loop `i` is material, -1 when it is a hole (inside an odd number of the other loops),
/// the rule nested_polygon_area applies; 0 for a loop of fewer than three points.
int nested_loop_sign(const std::vector<std::vector<Point2>>& polygons, std::size_t i);

/// Slices one mesh at many heights, building CGAL's AABB tree once. The mesh must be in the
/// needle frame (axis along z, body toward +z) and halfedge-representable (closed, manifold);
/// otherwise the constructor throws InputError.
class CrossSectionSlicer {
 public:
  explicit CrossSectionSlicer(const TriangleMesh& mesh);
  ~CrossSectionSlicer();
  CrossSectionSlicer(CrossSectionSlicer&&) noexcept;
  CrossSectionSlicer& operator=(CrossSectionSlicer&&) noexcept;

  /// Section by the plane z = z_tip + height_m.
  CrossSection slice(double height_m) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-off section at a single height (see CrossSectionSlicer).
CrossSection cross_section(const TriangleMesh& mesh, double height_m);

}  // namespace mneedle
