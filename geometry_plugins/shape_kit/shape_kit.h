#pragma once
// Geometry kit shared by the built-in tip plugins: welded triangle meshes, prisms cut by a
// piecewise-planar bottom, solids of revolution, and analytic cross-section formulas.
// Plain C++ (no CGAL, no mneedle::core) so each plugin stays small and self-contained.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <tuple>
#include <vector>

namespace mneedle::shape_kit {

struct Point3 {
  double x, y, z;
};

/// A parameter combination the shape cannot build; becomes MNEEDLE_STATUS_INVALID_PARAMETER.
class ParameterError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Collects triangles, joining vertices closer than the weld tolerance and dropping
/// triangles that collapse to a point or a line.
class MeshBuilder {
 public:
  explicit MeshBuilder(double weld_tolerance_m);

  std::uint32_t vertex(Point3 p);
  void add_triangle(Point3 a, Point3 b, Point3 c);
  /// Fan-triangulates a convex polygon given counter-clockwise as seen from its outside.
  void add_convex_polygon(const std::vector<Point3>& polygon);

  /// Reverses every triangle, turning an inward-oriented closed mesh outward.
  void flip();
  double signed_volume() const;

  const std::vector<Point3>& vertices() const { return vertices_; }
  const std::vector<std::array<std::uint32_t, 3>>& triangles() const { return triangles_; }

 private:
  using Key = std::tuple<long long, long long, long long>;
  Key key_of(Point3 p) const;

  double tolerance_;
  std::vector<Point3> vertices_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  std::map<Key, std::uint32_t> index_;
};

/// A straight prism around the z axis (outer radius, optional bore) between a bottom
/// surface z = bottom(x) and the plane z = top_z. bottom must be linear in x between the
/// sorted crease positions, so every generated bottom triangle lies in one plane.
struct CutPrism {
  double outer_radius_m = 0;
  double bore_radius_m = 0;  // 0: solid
  int segments = 64;         // polygon sides around the circumference
  double top_z_m = 0;
  std::vector<double> creases_x_m;
  std::function<double(double)> bottom_z_m;
};

MeshBuilder build_cut_prism(const CutPrism& prism);

struct ProfilePoint {
  double r, z;
};

/// Revolves a closed profile loop in the (r >= 0, z) half-plane around the z axis. Points
/// with r = 0 become single axis vertices. The result is oriented outward.
MeshBuilder build_revolved(const std::vector<ProfilePoint>& loop, int segments);

/// Integrals over the part x >= b of a disc of radius r centred on the axis.
struct SegmentMoments {
  double area;  // ∫ dA
  double sx;    // ∫ x dA
  double ixx;   // ∫ x² dA
  double iyy;   // ∫ y² dA
};
SegmentMoments disc_segment(double radius, double b);

struct SectionProperties {
  double area_m2;
  double i_min_m4;
};

/// Area and smaller principal centroidal second moment of the region x >= b of an annulus
/// (outer radius, bore radius; bore 0 = solid). The region is symmetric about the x axis,
/// so x and y are principal directions.
SectionProperties annulus_segment_properties(double outer_radius, double bore_radius, double b);

/// Full annulus (or disc when bore_radius = 0).
SectionProperties annulus_properties(double outer_radius, double bore_radius);

/// A tube cut by one plane at an angle to the axis (the sharp bevel), every edge of the cut
/// rounded to `edge_radius_m`: the union of every ball of that radius inside the sharp shape.
/// Tip (the lowest point) at z = 0 on the +x side, body along +z up to `length_m`.
/// With `flat_width_m` > 0 the shape is the blunt bevel: the sharp bevel cut flat,
/// perpendicular to the axis, where the flat is that wide from the rim; the flat lies at z = 0
/// and its rim, the crease and the corners where they meet the walls are rounded too.
struct RoundedBevel {
  double outer_radius_m = 0;
  double bore_radius_m = 0;  // 0: solid
  double tan_angle = 0;      // tan of the angle between the cut and the axis
  double edge_radius_m = 0;  // > 0
  double length_m = 0;
  int segments = 64;        // polygon sides around the circumference (more near the tip)
  double flat_width_m = 0;  // 0: the sharp bevel; > 0: the blunt bevel's flat
};

/// Throws ParameterError unless the rounding fits: edge radius at least 1e-6 R and below a
/// quarter of the wall (half the radius for a solid tube) and, with a bore, below
/// r_b sin t / (1 - sin t) (the bore rim would fold); positive tan, a bore narrower than the
/// tube, a cut shorter than the needle. A flat must stay wider than
/// rho (1 + (1 - sin t) / cos t) (the rounding would take all of it) and leave some bevel.
void check_rounded_bevel(const RoundedBevel& bevel);
MeshBuilder build_rounded_bevel(const RoundedBevel& bevel);
/// How far the rounded tip lies above the sharp bevel's tip (m): rho (1 + cos t - sin t) / sin t;
/// 0 with a flat, which stays at z = 0.
double rounded_bevel_tip_height(const RoundedBevel& bevel);
/// The section at height h above the rounded tip, by polar integration of the opening's
/// membership (2048 rays, each interval's ends bisected to round-off).
SectionProperties rounded_bevel_section(const RoundedBevel& bevel, double h_m);
/// Whether p (m, the mesh's frame: tip or flat at z = 0) lies in the opening: the membership
/// the section integrates.
bool rounded_bevel_contains(const RoundedBevel& bevel, Point3 p);

/// Reads an integral polygon side count from a parameter value.
int segment_count(double value);

}  // namespace mneedle::shape_kit
