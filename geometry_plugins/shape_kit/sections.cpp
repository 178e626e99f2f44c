#include <algorithm>
#include <cmath>
#include <numbers>

#include "shape_kit.h"

namespace mneedle::shape_kit {

// The segment is the sector of half-angle a = acos(b/r) minus the triangle spanned by the
// centre and the chord; the signed triangle terms also hold for b < 0, where it is added.
SegmentMoments disc_segment(double radius, double b) {
  if (radius <= 0) return {0, 0, 0, 0};
  const double a = std::acos(std::clamp(b / radius, -1.0, 1.0));
  const double chord_half = radius * std::sin(a);
  const double cb = radius * std::cos(a);
  const double r4 = std::pow(radius, 4);
  return {
      radius * radius * a - cb * chord_half,
      2.0 / 3.0 * std::pow(chord_half, 3),
      r4 / 8 * (2 * a + std::sin(2 * a)) - chord_half * std::pow(cb, 3) / 2,
      r4 / 8 * (2 * a - std::sin(2 * a)) - std::pow(chord_half, 3) * cb / 6,
  };
}

SectionProperties annulus_segment_properties(double outer_radius, double bore_radius, double b) {
  const SegmentMoments outer = disc_segment(outer_radius, b);
  const SegmentMoments bore = disc_segment(bore_radius, b);
  const double area = outer.area - bore.area;
  if (area <= 0) return {0, 0};
  const double sx = outer.sx - bore.sx;
  const double centroid_x = sx / area;
  // Bending about the y axis uses ∫(x - x̄)², about the x axis ∫y²; symmetry about the
  // x axis makes these the principal values.
  const double i_about_y = (outer.ixx - bore.ixx) - area * centroid_x * centroid_x;
  const double i_about_x = outer.iyy - bore.iyy;
  return {area, std::max(0.0, std::min(i_about_y, i_about_x))};
}

SectionProperties annulus_properties(double outer_radius, double bore_radius) {
  const double area = std::numbers::pi * (outer_radius * outer_radius - bore_radius * bore_radius);
  const double i = std::numbers::pi / 4 * (std::pow(outer_radius, 4) - std::pow(bore_radius, 4));
  return {area, i};
}

}  // namespace mneedle::shape_kit
