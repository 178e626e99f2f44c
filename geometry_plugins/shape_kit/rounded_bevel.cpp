// A bevelled tube whose edges are rounded: the union of every ball of radius rho inside the
// sharp bevel (its morphological opening; docs/model.md, "Sharp bevel with a rounded edge"). In the
// frame used here the sharp bevel's tip is the rim point (R, 0, 0), the cut is the plane x cos(t) +
// z sin(t) = R cos(t) (t the bevel angle to the axis) and the material lies above it. Shrinking the
// shape by rho gives K': the shell r_i <= r <= R' (r_i = bore + rho, R' = R - rho; a solid tube has
// no inner bound) above the plane moved rho into the material. The opening is K' grown by rho, so
// its surface is made of
//   the face: K''s plane face moved back by rho along the plane's outward normal n_p,
//   two pipes of radius rho around K''s two edges (the ellipses where that plane meets r = R'
//   and r = r_i), their normals swept from n_p to the cylinder's outward normal,
//   the walls r = R and r = bore above the pipes, and the flat top.
// The patches are built from the same edge points, so MeshBuilder's weld joins them exactly.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "shape_kit.h"

namespace mneedle::shape_kit {

namespace {

constexpr double kPi = std::numbers::pi;
// Steps across a pipe: the normal turns by less than pi - t (t the bevel angle, at least 5 deg
// in the plugin), so each step is under 11 deg and the chord stays within 0.5 % of rho of the
// circle.
constexpr int kPipeSteps = 16;

struct Frame {
  double R, bore, rho, c, s, top;  // top: the base plane, in the internal frame
  double outer() const { return R - rho; }
  double inner() const { return bore > 0 ? bore + rho : 0.0; }
  // Height of K''s plane over x.
  double plane_z(double x) const { return (R * c + rho - x * c) / s; }
};

Frame frame_of(const RoundedBevel& b) {
  const double t = std::atan(b.tan_angle);
  Frame f{b.outer_radius_m, b.bore_radius_m, b.edge_radius_m, std::cos(t), std::sin(t), 0.0};
  f.top = b.length_m + rounded_bevel_tip_height(b);
  return f;
}

Point3 add(Point3 a, Point3 b, double scale) {
  return {a.x + scale * b.x, a.y + scale * b.y, a.z + scale * b.z};
}

// Unit vector at fraction t of the great-circle arc from a to b (|a| = |b| = 1, not opposite).
Point3 slerp(Point3 a, Point3 b, double t) {
  const double cosine = std::clamp(a.x * b.x + a.y * b.y + a.z * b.z, -1.0, 1.0);
  const double angle = std::acos(cosine);
  if (angle < 1e-12) return a;
  const double wa = std::sin((1 - t) * angle) / std::sin(angle);
  const double wb = std::sin(t * angle) / std::sin(angle);
  return {wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z};
}

// Angles around the axis: the uniform ones plus a geometric refinement toward the tip (angle
// 0), where the edge turns fastest, down to a quarter of rho along the rim; symmetric about 0
// so that the mesh keeps its mirror plane y = 0.
std::vector<double> angles_of(const RoundedBevel& b) {
  const double step = 2 * kPi / b.segments;
  std::vector<double> angles;
  for (int i = 0; i < b.segments; ++i) angles.push_back(i * step);
  const double finest = 0.25 * b.edge_radius_m / b.outer_radius_m;
  for (double a = 0.5 * step; a > finest; a *= 0.5) {
    angles.push_back(a);
    angles.push_back(2 * kPi - a);
  }
  std::sort(angles.begin(), angles.end());
  return angles;
}

// Fractions of the sweep across a pipe: kPipeSteps equal ones, plus the one at which the outer
// pipe's normal at angle 0 points straight down, so that the tip, its lowest point, is a
// vertex (at z = 0 exactly once shifted).
std::vector<double> sweep_fractions(const Frame& f) {
  std::vector<double> fractions;
  for (int j = 0; j <= kPipeSteps; ++j) fractions.push_back(static_cast<double>(j) / kPipeSteps);
  // From n_p = (-c, 0, -s) to (1, 0, 0) the normal turns by pi - t; down is pi/2 - t of it.
  const double t = std::atan2(f.s, f.c);
  const double down = (0.5 * kPi - t) / (kPi - t);
  // A uniform fraction within a thousandth of a step of it is moved onto it.
  auto nearest = std::min_element(fractions.begin(), fractions.end(), [&](double x, double y) {
    return std::abs(x - down) < std::abs(y - down);
  });
  if (std::abs(*nearest - down) < 1e-3 / kPipeSteps)
    *nearest = down;
  else
    fractions.push_back(down);
  std::sort(fractions.begin(), fractions.end());
  return fractions;
}

// One ring of a pipe: the edge point at angle a and its normals swept from n_p (first) to the
// cylinder's outward normal (last); `sign` -1 for the bore, whose outward normal points at the
// axis.
std::vector<Point3> pipe_ring(const Frame& f, double radius, double sign, double a,
                              const std::vector<double>& fractions) {
  const Point3 edge{radius * std::cos(a), radius * std::sin(a), f.plane_z(radius * std::cos(a))};
  const Point3 face_normal{-f.c, 0.0, -f.s};
  const Point3 wall_normal{sign * std::cos(a), sign * std::sin(a), 0.0};
  std::vector<Point3> ring;
  for (const double t : fractions)
    ring.push_back(add(edge, slerp(face_normal, wall_normal, t), f.rho));
  return ring;
}

void add_quad(MeshBuilder& mesh, Point3 a, Point3 b, Point3 c, Point3 d) {
  mesh.add_triangle(a, b, c);
  mesh.add_triangle(a, c, d);
}

Point3 shifted(Point3 p, double dz) {
  return {p.x, p.y, p.z - dz};
}

// Points of the shell K' that lie within rho of q (x, y, z in the internal frame): q lies in
// the opening. The nearest point of K' is q itself, its projection onto the plane face or onto
// a wall (where that lands on K'), or a point of an edge; an edge is only searched where q is
// within rho of both surfaces that meet there.
bool in_opening(const Frame& f, double x, double y, double z) {
  const double r = std::hypot(x, y);
  const double w = x * f.c + z * f.s - (f.R * f.c + f.rho);  // > 0: above K''s plane
  const double ro = f.outer(), ri = f.inner();
  const double rho2 = f.rho * f.rho;
  if (w >= 0 && r <= ro && r >= ri) return true;
  if (w < 0 && -w <= f.rho) {
    const double px = x - w * f.c, py = y;
    const double pr = std::hypot(px, py);
    if (pr <= ro && pr >= ri) return true;
  }
  if (r > ro && r - ro <= f.rho && x * ro / r * f.c + z * f.s >= f.R * f.c + f.rho) return true;
  if (ri > 0 && r < ri && ri - r <= f.rho) {
    const double px = r > 0 ? x * ri / r : ri;
    if (px * f.c + z * f.s >= f.R * f.c + f.rho) return true;
  }
  // Edges: the ellipse of K''s plane on a wall, searched on a coarse ring then refined.
  for (const double radius : {ro, ri}) {
    if (radius <= 0 || std::abs(r - radius) > f.rho || w > f.rho || -w > f.rho) continue;
    auto distance2 = [&](double a) {
      const double ex = radius * std::cos(a), ey = radius * std::sin(a);
      const double ez = f.plane_z(ex);
      return (x - ex) * (x - ex) + (y - ey) * (y - ey) + (z - ez) * (z - ez);
    };
    // The nearest edge point lies within asin(rho / radius) of q's own angle (q is within rho
    // of it in plan); the arc searched is 4 rho / radius wide on each side, sampled at 32 points
    // (the distance may have two minima there near the ellipse's ends), then the best sample's
    // bracket refined by ternary search.
    const double centre = std::atan2(y, x);
    const double half = std::min(kPi, 4.0 * f.rho / radius + 1e-3);
    constexpr int kScan = 32;
    int best = 0;
    double best_d2 = std::numeric_limits<double>::max();
    for (int i = 0; i <= kScan; ++i) {
      const double d2 = distance2(centre - half + 2 * half * i / kScan);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    if (best_d2 <= rho2) return true;
    double lo = centre - half + 2 * half * std::max(best - 1, 0) / kScan;
    double hi = centre - half + 2 * half * std::min(best + 1, kScan) / kScan;
    for (int k = 0; k < 40; ++k) {
      const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      if (distance2(m1) < distance2(m2))
        hi = m2;
      else
        lo = m1;
    }
    if (distance2(0.5 * (lo + hi)) <= rho2) return true;
  }
  return false;
}

}  // namespace

double rounded_bevel_tip_height(const RoundedBevel& b) {
  // The pipe's lowest point lies under the edge's lowest point (angle 0), rho below it.
  const double t = std::atan(b.tan_angle);
  const double c = std::cos(t), s = std::sin(t);
  return b.edge_radius_m * (1 + c - s) / s;
}

void check_rounded_bevel(const RoundedBevel& b) {
  if (!(b.outer_radius_m > 0)) throw ParameterError("outer radius must be positive");
  if (b.bore_radius_m < 0 || b.bore_radius_m >= b.outer_radius_m)
    throw ParameterError("bore must be smaller than the diameter");
  if (!(b.tan_angle > 0) || !std::isfinite(b.tan_angle))
    throw ParameterError("bevel_angle must lie in (0, 90) degrees");
  if (!(b.edge_radius_m > 0) || !std::isfinite(b.edge_radius_m))
    throw ParameterError("tip_radius must be positive for a rounded bevel");
  // Below a millionth of the radius the pipes' vertices would weld into each other.
  if (b.edge_radius_m < 1e-6 * b.outer_radius_m)
    throw ParameterError("tip_radius must be 0 (sharp) or at least 1e-6 of the radius");
  // Both pipes must fit in the wall with some shell left between them: a quarter of the wall,
  // half the radius for a solid tube.
  const double wall = b.outer_radius_m - b.bore_radius_m;
  const double most = b.bore_radius_m > 0 ? 0.25 * wall : 0.5 * b.outer_radius_m;
  if (!(b.edge_radius_m < most))
    throw ParameterError(
        std::string("tip_radius is too large: it must stay below ") +
        (b.bore_radius_m > 0 ? "(diameter - bore) / 8, a quarter of the wall" : "diameter / 4"));
  // The bore's pipe sweeps toward the bore's axis at the ends of its ellipse, whose in-plane
  // radius of curvature there is r_i sin(t): a larger rho would fold the pipe onto itself.
  const double sine = b.tan_angle / std::sqrt(1 + b.tan_angle * b.tan_angle);
  if (b.bore_radius_m > 0 && !(b.edge_radius_m < (b.bore_radius_m + b.edge_radius_m) * sine))
    throw ParameterError(
        "tip_radius is too large for this bore and bevel_angle: it must stay below "
        "bore / 2 * sin(bevel_angle) / (1 - sin(bevel_angle)), or the rounded bore rim folds");
  if (b.segments < 8) throw ParameterError("resolution must be at least 8 segments");
  const Frame f = frame_of(b);
  if (!(f.plane_z(-f.R) + f.rho < f.top))
    throw ParameterError("the bevel (diameter / tan(bevel_angle)) is longer than length");
}

MeshBuilder build_rounded_bevel(const RoundedBevel& b) {
  check_rounded_bevel(b);
  const Frame f = frame_of(b);
  const double dz = rounded_bevel_tip_height(b);
  MeshBuilder mesh(1e-9 * b.outer_radius_m);
  const std::vector<double> angles = angles_of(b);
  const std::size_t n = angles.size();
  const std::vector<double> fractions = sweep_fractions(f);
  std::vector<std::vector<Point3>> outer(n), inner(n);
  for (std::size_t k = 0; k < n; ++k) {
    outer[k] = pipe_ring(f, f.outer(), 1.0, angles[k], fractions);
    for (Point3& p : outer[k]) p = shifted(p, dz);
    if (f.bore > 0) {
      inner[k] = pipe_ring(f, f.inner(), -1.0, angles[k], fractions);
      for (Point3& p : inner[k]) p = shifted(p, dz);
    }
  }
  const double top = f.top - dz;
  // The face's centre for a solid needle: the plane point over the axis, moved back by rho.
  const Point3 centre = shifted({-f.rho * f.c, 0.0, f.plane_z(0.0) - f.rho * f.s}, dz);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t m = (k + 1) % n;
    const auto& o0 = outer[k];
    const auto& o1 = outer[m];
    // Outer pipe, face side (j = 0) to wall side: outward seen with angles counter-clockwise.
    for (std::size_t j = 0; j + 1 < fractions.size(); ++j)
      add_quad(mesh, o0[j], o1[j], o1[j + 1], o0[j + 1]);
    const Point3 w0 = o0.back(), w1 = o1.back();
    add_quad(mesh, w0, w1, {w1.x, w1.y, top}, {w0.x, w0.y, top});
    if (f.bore > 0) {
      const auto& i0 = inner[k];
      const auto& i1 = inner[m];
      add_quad(mesh, i0.front(), i1.front(), o1.front(), o0.front());  // the face, facing down
      for (std::size_t j = 0; j + 1 < fractions.size(); ++j)
        add_quad(mesh, i1[j], i0[j], i0[j + 1], i1[j + 1]);
      const Point3 v0 = i0.back(), v1 = i1.back();
      add_quad(mesh, v1, v0, {v0.x, v0.y, top}, {v1.x, v1.y, top});
      add_quad(mesh, {w0.x, w0.y, top}, {w1.x, w1.y, top}, {v1.x, v1.y, top}, {v0.x, v0.y, top});
    } else {
      mesh.add_triangle(centre, o1.front(), o0.front());
      mesh.add_triangle({0.0, 0.0, top}, {w0.x, w0.y, top}, {w1.x, w1.y, top});
    }
  }
  return mesh;
}

SectionProperties rounded_bevel_section(const RoundedBevel& b, double h) {
  check_rounded_bevel(b);
  const Frame f = frame_of(b);
  const double z = h + rounded_bevel_tip_height(b);
  if (h < 0 || z > f.top) return {0, 0};
  // Polar integration over the annulus bore <= r <= R: on each ray the opening is one interval
  // of r (a slice of the shell above a plane, less its rounded corners), found from samples and
  // bisection; its moments are integrated exactly in r.
  constexpr int kRays = 2048;
  constexpr int kSamples = 48;
  constexpr int kBisections = 40;
  double area = 0, sx = 0, ixx = 0, iyy = 0;
  const double d_angle = 2 * kPi / kRays;
  const double sharp_b = b.outer_radius_m - z * b.tan_angle;
  for (int k = 0; k < kRays; ++k) {
    const double a = (k + 0.5) * d_angle;
    const double ca = std::cos(a), sa = std::sin(a);
    auto member = [&](double r) { return in_opening(f, r * ca, r * sa, z); };
    // The opening lies inside the sharp bevel, whose slice on this ray is r cos(a) >= sharp_b
    // within the annulus: the samples span that interval, however short it is.
    double r0 = b.bore_radius_m, r1 = b.outer_radius_m;
    if (ca > 1e-15)
      r0 = std::max(r0, sharp_b / ca);
    else if (ca < -1e-15)
      r1 = std::min(r1, sharp_b / ca);
    else if (sharp_b > 0)
      continue;
    if (!(r1 > r0)) continue;
    int first = -1, last = -1;
    for (int i = 0; i <= kSamples; ++i) {
      if (member(r0 + (r1 - r0) * i / kSamples)) {
        if (first < 0) first = i;
        last = i;
      }
    }
    if (first < 0) continue;
    auto boundary = [&](double out, double in) {
      for (int i = 0; i < kBisections; ++i) {
        const double mid = 0.5 * (out + in);
        (member(mid) ? in : out) = mid;
      }
      return 0.5 * (out + in);
    };
    auto radius_at = [&](int i) { return r0 + (r1 - r0) * i / kSamples; };
    const double lo = first == 0 ? r0 : boundary(radius_at(first - 1), radius_at(first));
    const double hi = last == kSamples ? r1 : boundary(radius_at(last + 1), radius_at(last));
    // Moments of the ray's interval: dA = r dr da.
    const double p2 = (hi * hi - lo * lo) / 2, p3 = (std::pow(hi, 3) - std::pow(lo, 3)) / 3,
                 p4 = (std::pow(hi, 4) - std::pow(lo, 4)) / 4;
    area += p2 * d_angle;
    sx += p3 * ca * d_angle;
    ixx += p4 * ca * ca * d_angle;
    iyy += p4 * sa * sa * d_angle;
  }
  if (area <= 0) return {0, 0};
  const double centroid_x = sx / area;
  const double i_about_y = ixx - area * centroid_x * centroid_x;
  return {area, std::max(0.0, std::min(i_about_y, iyy))};
}

}  // namespace mneedle::shape_kit
