#include "mneedle/strength/section_table.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "mneedle/base/error.h"
#include "mneedle/geometry/cross_section.h"

namespace mneedle {
namespace {

using Loop = std::vector<std::array<double, 2>>;

// Area moments of one loop about the origin, oriented counter-clockwise.
struct Moments {
  double a = 0, sx = 0, sy = 0, ixx = 0, iyy = 0, ixy = 0;
};

Moments loop_moments(const Loop& loop) {
  Moments m;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const auto& p = loop[i];
    const auto& q = loop[(i + 1) % loop.size()];
    const double c = p[0] * q[1] - q[0] * p[1];
    m.a += c / 2.0;
    m.sx += (p[0] + q[0]) * c / 6.0;
    m.sy += (p[1] + q[1]) * c / 6.0;
    m.ixx += (p[1] * p[1] + p[1] * q[1] + q[1] * q[1]) * c / 12.0;
    m.iyy += (p[0] * p[0] + p[0] * q[0] + q[0] * q[0]) * c / 12.0;
    m.ixy += (p[0] * q[1] + 2 * p[0] * p[1] + 2 * q[0] * q[1] + q[0] * p[1]) * c / 24.0;
  }
  if (m.a < 0) {  // clockwise loop: flip every moment
    m.a = -m.a, m.sx = -m.sx, m.sy = -m.sy, m.ixx = -m.ixx, m.iyy = -m.iyy, m.ixy = -m.ixy;
  }
  return m;
}

SectionProperties lerp(const SectionProperties& a, const SectionProperties& b, double t) {
  return {a.area_m2 + t * (b.area_m2 - a.area_m2), a.i_min_m4 + t * (b.i_min_m4 - a.i_min_m4),
          a.extreme_fibre_m + t * (b.extreme_fibre_m - a.extreme_fibre_m)};
}

}  // namespace

SectionProperties polygon_section_properties(const std::vector<Loop>& loops) {
  Moments total;
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const double s = nested_loop_sign(loops, i);
    if (s == 0.0) continue;
    const Moments m = loop_moments(loops[i]);
    total.a += s * m.a, total.sx += s * m.sx, total.sy += s * m.sy;
    total.ixx += s * m.ixx, total.iyy += s * m.iyy, total.ixy += s * m.ixy;
  }
  SectionProperties out;
  if (!(total.a > 0.0)) return out;
  const double cx = total.sx / total.a, cy = total.sy / total.a;
  // Parallel-axis shift to the centroid; x-moments are about the y axis and vice versa.
  const double ixx = total.ixx - total.a * cy * cy;
  const double iyy = total.iyy - total.a * cx * cx;
  const double ixy = total.ixy - total.a * cx * cy;
  const double mean = (ixx + iyy) / 2.0;
  const double radius = std::hypot((ixx - iyy) / 2.0, ixy);
  out.area_m2 = total.a;
  out.i_min_m4 = std::max(0.0, mean - radius);
  for (const auto& loop : loops)
    for (const auto& p : loop)
      out.extreme_fibre_m = std::max(out.extreme_fibre_m, std::hypot(p[0] - cx, p[1] - cy));
  return out;
}

SectionTable::SectionTable(std::vector<double> heights_m, std::vector<SectionProperties> sections,
                           SectionProfile exact)
    : heights_(std::move(heights_m)), sections_(std::move(sections)), exact_(std::move(exact)) {
  if (heights_.size() < 2 || heights_.size() != sections_.size())
    throw InputError("section table: needs at least two heights, one section each");
  if (!std::is_sorted(heights_.begin(), heights_.end()))
    throw InputError("section table: heights must increase");
}

SectionTable SectionTable::from_profile(SectionProfile exact, double length_m, int samples) {
  std::vector<double> heights;
  std::vector<SectionProperties> sections;
  for (int i = 0; i <= samples; ++i) {
    heights.push_back(length_m * i / samples);
    sections.push_back(exact(heights.back()));
  }
  return SectionTable(std::move(heights), std::move(sections), std::move(exact));
}

SectionTable SectionTable::from_mesh(const TriangleMesh& mesh, int samples) {
  const BoundingBox box = bounding_box(mesh);
  const double length = box.max[2] - box.min[2];
  if (!(length > 0.0)) throw InputError("section table: the needle has no length along its axis");
  const auto slicer = std::make_shared<const CrossSectionSlicer>(mesh);
  // Planes exactly through the tip or base vertices give degenerate loops: stay just inside.
  const double inset = 1e-7 * length;
  SectionProfile exact = [slicer, inset, length](double height_m) {
    const double h = std::clamp(height_m, inset, length - inset);
    return polygon_section_properties(slicer->slice(h).polygons);
  };
  return from_profile(std::move(exact), length, samples);
}

SectionProperties SectionTable::at(double height_m) const {
  if (height_m <= heights_.front()) return sections_.front();
  if (height_m >= heights_.back()) return sections_.back();
  const auto it = std::upper_bound(heights_.begin(), heights_.end(), height_m);
  const std::size_t i = static_cast<std::size_t>(it - heights_.begin());
  const double t = (height_m - heights_[i - 1]) / (heights_[i] - heights_[i - 1]);
  return lerp(sections_[i - 1], sections_[i], t);
}

SectionProfile SectionTable::profile() const {
  return [table = *this](double h) { return table.at(h); };
}

double SectionTable::tip_length_m(double fraction) const {
  double largest = 0.0;
  for (const auto& s : sections_) largest = std::max(largest, s.area_m2);
  // Between the samples that bracket the area sought, linearly: the height then moves
  // continuously with the needle, not in steps of the slicing grid (which scales with the
  // needle's length, so the same tip on a longer shaft would read another length).
  const double sought = fraction * largest;
  for (std::size_t i = 0; i < sections_.size(); ++i) {
    if (sections_[i].area_m2 < sought) continue;
    if (i == 0) return heights_[0];
    double lo = heights_[i - 1], hi = heights_[i];
    if (!exact_) {
      const double a0 = sections_[i - 1].area_m2, a1 = sections_[i].area_m2;
      return lo + (sought - a0) / (a1 - a0) * (hi - lo);
    }
    // Bisection: a tip's area is not linear in height (quadratic on a cone, with a kink where
    // the taper meets the shaft), so the chord would still follow the grid.
    const double resolution = 1e-9 * (hi - lo);
    while (hi - lo > resolution) {
      const double mid = 0.5 * (lo + hi);
      (exact_(mid).area_m2 >= sought ? hi : lo) = mid;
    }
    return hi;
  }
  return heights_.back();
}

}  // namespace mneedle
