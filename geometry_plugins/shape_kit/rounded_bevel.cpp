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
  // The unrounded cut meets z = 0 at x = X: R for the sharp bevel, R - flat_width for the
  // blunt one, whose flat is the plane z = 0 (K''s flat is z = rho).
  double X;
  bool flat;
  double outer() const { return R - rho; }
  double inner() const { return bore > 0 ? bore + rho : 0.0; }
  // Height of K''s plane over x.
  double plane_z(double x) const { return (X * c + rho - x * c) / s; }
  // Where K''s plane meets its flat z = rho: the crease line x = X' (blunt bevel only).
  double crease() const { return X + rho * (1 - s) / c; }
};

Frame frame_of(const RoundedBevel& b) {
  const double t = std::atan(b.tan_angle);
  Frame f{b.outer_radius_m,
          b.bore_radius_m,
          b.edge_radius_m,
          std::cos(t),
          std::sin(t),
          0.0,
          b.outer_radius_m - b.flat_width_m,
          b.flat_width_m > 0};
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

// Whether the ellipse where K''s plane meets the wall of `radius` comes within rho of q = (x, y,
// z), on its part |angle| >= end (0: all of it; the rest is a blunt bevel's flat's, whose end is
// a corner checked on its own). The nearest edge point lies within asin(rho / radius) of q's own
// angle (q is within rho of it in plan); the arc searched is 4 rho / radius wide on each side,
// less any of it outside the part, sampled at 32 points (the distance may have two minima there
// near the ellipse's ends), then the best sample's bracket refined by ternary search.
bool near_ellipse(const Frame& f, double radius, double end, double x, double y, double z) {
  auto distance2 = [&](double a) {
    const double ex = radius * std::cos(a), ey = radius * std::sin(a);
    const double ez = f.plane_z(ex);
    return (x - ex) * (x - ex) + (y - ey) * (y - ey) + (z - ez) * (z - ez);
  };
  const double rho2 = f.rho * f.rho;
  constexpr int kScan = 32;
  // Sampled on [lo, lo + width], then refined.
  auto within = [&](double lo, double width) {
    int best = 0;
    double best_d2 = std::numeric_limits<double>::max();
    for (int i = 0; i <= kScan; ++i) {
      const double d2 = distance2(lo + width * i / kScan);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    if (best_d2 <= rho2) return true;
    double a = lo + width * std::max(best - 1, 0) / kScan;
    double b = lo + width * std::min(best + 1, kScan) / kScan;
    for (int k = 0; k < 40; ++k) {
      const double m1 = a + (b - a) / 3, m2 = b - (b - a) / 3;
      if (distance2(m1) < distance2(m2))
        b = m2;
      else
        a = m1;
    }
    return distance2(0.5 * (a + b)) <= rho2;
  };
  const double centre = std::atan2(y, x);
  const double half = std::min(kPi, 4.0 * f.rho / radius + 1e-3);
  if (end <= 0) return within(centre - half, 2 * half);
  // The part is [end, 2 pi - end] around the circle; the window lies within (-2 pi, 2 pi].
  for (const double shift : {-2 * kPi, 0.0}) {
    const double lo = std::max(centre - half, end + shift);
    const double hi = std::min(centre + half, 2 * kPi - end + shift);
    if (hi > lo && within(lo, hi - lo)) return true;
  }
  return false;
}

// Points of the shell K' that lie within rho of q (x, y, z in the internal frame): q lies in
// the opening. The nearest point of K' is q itself, its projection onto the plane face or onto
// a wall (where that lands on K'), or a point of an edge; an edge is only searched where q is
// within rho of both surfaces that meet there.
bool in_opening(const Frame& f, double x, double y, double z) {
  const double r = std::hypot(x, y);
  const double w = x * f.c + z * f.s - (f.R * f.c + f.rho);  // > 0: above K''s plane
  const double ro = f.outer(), ri = f.inner();
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
    if (near_ellipse(f, radius, 0.0, x, y, z)) return true;
  }
  return false;
}

// The blunt bevel's membership: K' is the shell above its plane and above its flat z = rho.
// The nearest point of K' to q is q itself, q's projection onto one of K''s four faces (the
// plane, the flat, the walls), the nearest point of one of its five edges (the plane's ellipses
// on the walls, the flat's circles on the walls, the crease) or one of its corners (where the
// crease meets a wall); every candidate is kept only if it lies on K', so the least distance
// among them is the distance to K'.
bool in_blunt_opening(const Frame& f, double x, double y, double z) {
  const double r = std::hypot(x, y);
  const double ro = f.outer(), ri = f.inner(), xc = f.crease();
  const double rho2 = f.rho * f.rho;
  const double slack = 1e-12 * f.R;  // round-off of a point computed on one of K''s surfaces
  const double plane_level = f.X * f.c + f.rho;
  auto on_k = [&](double px, double py, double pz) {
    const double pr = std::hypot(px, py);
    return pr <= ro + slack && pr >= ri - slack && px * f.c + pz * f.s >= plane_level - slack &&
           pz >= f.rho - slack;
  };
  auto near = [&](double px, double py, double pz) {
    return (x - px) * (x - px) + (y - py) * (y - py) + (z - pz) * (z - pz) <= rho2;
  };
  if (on_k(x, y, z)) return true;
  // The faces.
  const double w = x * f.c + z * f.s - plane_level;
  if (w < 0 && -w <= f.rho && on_k(x - w * f.c, y, z - w * f.s)) return true;
  if (z < f.rho && z >= 0 && on_k(x, y, f.rho)) return true;
  if (r > ro && r - ro <= f.rho && on_k(x * ro / r, y * ro / r, z)) return true;
  if (ri > 0 && r < ri && ri - r <= f.rho) {
    // On the axis every direction is as near; the one toward the flat's side lies on K' if any.
    const double ux = r > 0 ? x / r : 1.0, uy = r > 0 ? y / r : 0.0;
    if (on_k(ri * ux, ri * uy, z)) return true;
  }
  // The flat's circles: the nearest point lies at q's own angle.
  for (const double radius : {ro, ri}) {
    if (radius <= 0 || r <= 0) continue;
    const double px = radius * x / r, py = radius * y / r;
    if (px >= xc - slack && near(px, py, f.rho)) return true;
  }
  // The crease.
  const double crease_r2 = xc * xc + y * y;
  if (crease_r2 <= (ro + slack) * (ro + slack) && crease_r2 >= (ri - slack) * (ri - slack) &&
      near(xc, y, f.rho))
    return true;
  // The corners.
  for (const double radius : {ro, ri}) {
    if (radius <= 0 || std::abs(xc) >= radius) continue;
    const double corner_y = std::sqrt(radius * radius - xc * xc);
    if (near(xc, corner_y, f.rho) || near(xc, -corner_y, f.rho)) return true;
  }
  // The plane's ellipses, on their part x <= X' (the rest is the flat's).
  for (const double radius : {ro, ri}) {
    if (radius <= 0 || std::abs(r - radius) > f.rho || w > f.rho || -w > f.rho) continue;
    if (xc <= -radius) continue;  // the flat takes the whole wall
    const double end = xc >= radius ? 0.0 : std::acos(xc / radius);  // |angle| >= end
    if (near_ellipse(f, radius, end, x, y, z)) return true;
  }
  return false;
}

// A point of the opening's surface with the outward normal there.
struct Surfel {
  Point3 p, n;
};

Point3 minus(Point3 a, Point3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}

double dot(Point3 a, Point3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

Point3 cross(Point3 a, Point3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// The points e + rho n for n on the great-circle arc from `from` to `to`, kPipeSteps equal
// steps: a pipe's ring around the edge point e, or a row of a corner's sphere.
std::vector<Surfel> sweep(Point3 e, Point3 from, Point3 to, double rho) {
  std::vector<Surfel> ring;
  for (int j = 0; j <= kPipeSteps; ++j) {
    const Point3 n = slerp(from, to, static_cast<double>(j) / kPipeSteps);
    ring.push_back({add(e, n, rho), n});
  }
  return ring;
}

// A quad (a, b, c, d in cyclic order) or triangle (d = a) turned so that its normal agrees with
// the surface normals at its corners: every patch is built in whichever order is simplest.
void add_facing(MeshBuilder& mesh, const Surfel& a, const Surfel& b, const Surfel& c,
                const Surfel& d) {
  const Point3 normal = cross(minus(c.p, a.p), minus(d.p, b.p));
  const Point3 outward = add(add(a.n, b.n, 1.0), add(c.n, d.n, 1.0), 1.0);
  const bool ccw = dot(normal, outward) >= 0;
  if (ccw) {
    mesh.add_triangle(a.p, b.p, c.p);
    mesh.add_triangle(a.p, c.p, d.p);
  } else {
    mesh.add_triangle(a.p, c.p, b.p);
    mesh.add_triangle(a.p, d.p, c.p);
  }
}

void add_facing(MeshBuilder& mesh, const Surfel& a, const Surfel& b, const Surfel& c) {
  const Point3 normal = cross(minus(b.p, a.p), minus(c.p, a.p));
  const Point3 outward = add(add(a.n, b.n, 1.0), c.n, 1.0);
  if (dot(normal, outward) >= 0)
    mesh.add_triangle(a.p, b.p, c.p);
  else
    mesh.add_triangle(a.p, c.p, b.p);
}

void add_strip(MeshBuilder& mesh, const std::vector<Surfel>& r0, const std::vector<Surfel>& r1) {
  for (std::size_t j = 0; j + 1 < r0.size(); ++j)
    add_facing(mesh, r0[j], r1[j], r1[j + 1], r0[j + 1]);
}

// The blunt bevel's opening (docs/model.md, "Blunt bevel with rounded edges"). Around the axis
// every angle's ray through K''s section at the walls meets the flat, the plane or both (then
// the crease between them); the angles are the polygon's plus the corners', so that between two
// neighbours each ray is of one kind. Each angle carries the pipes' rings (normals swept from
// the face's to the wall's), each corner a sphere patch (normals in the triangle of the flat's,
// the plane's and the wall's) whose rows end on the rings and on the crease's pipe.
MeshBuilder build_blunt(const RoundedBevel& b, const Frame& exact) {
  // A crease within 10^-6 R of touching the bore is moved onto the bore's edge, and one within
  // 10^-6 R of the axis 10^-6 R off it (with a bore): the corners' spheres would be slivers
  // whose points weld, a crease just inside the bore would fold the face between them, and one
  // through the axis would put the bore's corners at the outer ones' angles. The cut then moves
  // by at most 10^-6 R (0.1 nm for paper A's needle).
  Frame f = exact;
  {
    const double tiny = 1e-6 * f.R, ri = f.inner(), xc = f.crease();
    double moved = xc;
    if (ri > 0 && std::abs(std::abs(xc) - ri) < tiny)
      moved = std::copysign(ri, xc);
    else if (ri > 0 && std::abs(xc) < tiny)
      moved = tiny;
    f.X += moved - xc;
  }
  const double ro = f.outer(), ri = f.inner(), xc = f.crease(), rho = f.rho;
  const Point3 n_flat{0.0, 0.0, -1.0}, n_plane{-f.c, 0.0, -f.s};
  auto radial = [](double a, double sign) {
    return Point3{sign * std::cos(a), sign * std::sin(a), 0.0};
  };
  // Corner angles: the crease meets the outer wall at +-acos(X'/R') and the bore at
  // +-acos(X'/r_i) when it crosses it.
  struct Corner {
    double angle, radius, sign;
  };
  std::vector<Corner> corners;
  const double outer_corner = std::acos(xc / ro);
  corners.push_back({outer_corner, ro, 1.0});
  corners.push_back({2 * kPi - outer_corner, ro, 1.0});
  // (A crease moved onto the bore's edge, above, touches it at one point: no corners there.)
  const bool crosses_bore = ri > 0 && std::abs(xc) < ri - 0.5e-6 * f.R;
  if (crosses_bore) {
    const double inner_corner = std::acos(xc / ri);
    corners.push_back({inner_corner, ri, -1.0});
    corners.push_back({2 * kPi - inner_corner, ri, -1.0});
  }
  const double step = 2 * kPi / b.segments;
  std::vector<double> angles;
  for (int i = 0; i < b.segments; ++i) {
    const double a = i * step;
    bool clear = true;  // no sliver between a polygon angle and a corner
    for (const Corner& k : corners) {
      const double gap = std::abs(std::remainder(a - k.angle, 2 * kPi));
      if (gap < 0.25 * step) clear = false;
    }
    if (clear) angles.push_back(a);
  }
  for (const Corner& k : corners) angles.push_back(k.angle);
  std::sort(angles.begin(), angles.end());
  auto find_corner = [&](double a, double radius) -> const Corner* {
    for (const Corner& k : corners)
      if (k.angle == a && k.radius == radius) return &k;
    return nullptr;
  };

  auto edge = [&](double radius, double a, bool on_flat) {
    const double x = radius * std::cos(a);
    return Point3{x, radius * std::sin(a), on_flat ? rho : f.plane_z(x)};
  };
  auto wall_ring = [&](double radius, double sign, double a, bool on_flat) {
    return sweep(edge(radius, a, on_flat), on_flat ? n_flat : n_plane, radial(a, sign), rho);
  };
  // The crease's ring at the ray of angle a (x = X'); at a corner the corner itself, computed
  // as the walls' edge points are, so that the patches share it.
  auto crease_ring = [&](double a) {
    Point3 e{xc, xc * std::tan(a), rho};
    for (const double radius : {ro, ri})
      if (radius > 0 && find_corner(a, radius)) e = edge(radius, a, true);
    return sweep(e, n_flat, n_plane, rho);
  };
  const double top = f.top;
  const Point3 up{0.0, 0.0, 1.0};
  auto lifted = [&](const Surfel& s) { return Surfel{{s.p.x, s.p.y, top}, s.n}; };
  auto top_of = [&](const Surfel& s) { return Surfel{{s.p.x, s.p.y, top}, up}; };
  // A solid needle's crease ring through its midpoint, the hub of its faces' fans.
  const std::vector<Surfel> middle = ri > 0 ? std::vector<Surfel>{} : crease_ring(0.0);

  MeshBuilder mesh(1e-9 * b.outer_radius_m);
  const std::size_t n = angles.size();
  for (std::size_t k = 0; k < n; ++k) {
    const double a0 = angles[k], a1 = angles[(k + 1) % n];
    const double mid = k + 1 < n ? 0.5 * (a0 + a1) : 0.5 * (a0 + a1 + 2 * kPi);
    const bool outer_flat = ro * std::cos(mid) > xc;
    const auto o0 = wall_ring(ro, 1.0, a0, outer_flat);
    const auto o1 = wall_ring(ro, 1.0, a1, outer_flat);
    add_strip(mesh, o0, o1);
    add_facing(mesh, o0.back(), o1.back(), lifted(o1.back()), lifted(o0.back()));
    if (ri > 0) {
      const bool inner_flat = crosses_bore ? ri * std::cos(mid) > xc : xc < 0;
      const auto i0 = wall_ring(ri, -1.0, a0, inner_flat);
      const auto i1 = wall_ring(ri, -1.0, a1, inner_flat);
      add_strip(mesh, i0, i1);
      add_facing(mesh, i0.back(), i1.back(), lifted(i1.back()), lifted(i0.back()));
      add_facing(mesh, top_of(o0.back()), top_of(o1.back()), top_of(i1.back()), top_of(i0.back()));
      // The face between the walls: one kind, or the inner kind up to the crease and the
      // outer kind beyond it (ring index 0 the flat's side, kPipeSteps the plane's).
      if (inner_flat == outer_flat) {
        add_facing(mesh, i0.front(), i1.front(), o1.front(), o0.front());
      } else {
        const auto c0 = crease_ring(a0), c1 = crease_ring(a1);
        add_strip(mesh, c0, c1);
        const std::size_t in_side = inner_flat ? 0 : c0.size() - 1;
        const std::size_t out_side = outer_flat ? 0 : c0.size() - 1;
        add_facing(mesh, i0.front(), i1.front(), c1[in_side], c0[in_side]);
        add_facing(mesh, c0[out_side], c1[out_side], o1.front(), o0.front());
      }
    } else {
      add_facing(mesh, {{0.0, 0.0, top}, up}, top_of(o0.back()), top_of(o1.back()));
      // The solid's faces are fans from the crease's midpoint (both faces are convex and it
      // lies on the edge of each).
      const Surfel& hub = outer_flat ? middle.front() : middle.back();
      add_facing(mesh, hub, o0.front(), o1.front());
    }
  }
  if (ri <= 0) {
    // The crease's pipe of a solid needle: from one outer corner through the midpoint to the
    // other, matching the fans' edges.
    const auto low = crease_ring(corners[1].angle), high = crease_ring(corners[0].angle);
    add_strip(mesh, low, middle);
    add_strip(mesh, middle, high);
  }
  // The corners' spheres: row i runs from the flat's ring (normal toward the wall by i steps)
  // to the plane's; row 0 is the crease's ring, the last row the wall's normal alone.
  for (const Corner& k : corners) {
    const Point3 q = edge(k.radius, k.angle, true);
    const Point3 wall = radial(k.angle, k.sign);
    std::vector<std::vector<Surfel>> rows;
    for (int i = 0; i <= kPipeSteps; ++i) {
      const double t = static_cast<double>(i) / kPipeSteps;
      const Point3 from = slerp(n_flat, wall, t), to = slerp(n_plane, wall, t);
      std::vector<Surfel> row;
      const int count = kPipeSteps - i;
      for (int m = 0; m <= count; ++m) {
        const Point3 nn = count > 0 ? slerp(from, to, static_cast<double>(m) / count) : from;
        row.push_back({add(q, nn, rho), nn});
      }
      rows.push_back(row);
    }
    for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
      const auto &lower = rows[i], &upper = rows[i + 1];
      for (std::size_t m = 0; m + 1 < lower.size(); ++m) {
        add_facing(mesh, lower[m], lower[m + 1], upper[m]);
        if (m + 1 < upper.size()) add_facing(mesh, lower[m + 1], upper[m + 1], upper[m]);
      }
    }
  }
  return mesh;
}

}  // namespace

double rounded_bevel_tip_height(const RoundedBevel& b) {
  if (b.flat_width_m > 0) return 0.0;  // the flat stays at z = 0
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
  if (!(b.flat_width_m >= 0) || !(b.flat_width_m < 2 * b.outer_radius_m))
    throw ParameterError("flat_width must lie in [0, diameter)");
  // The bore's pipe sweeps toward the bore's axis at the ends of its ellipse, whose in-plane
  // radius of curvature there is r_i sin(t): a larger rho would fold the pipe onto itself. A flat
  // that takes the whole bore rim (a crease at x <= -r_i) leaves no ellipse.
  const double sine = b.tan_angle / std::sqrt(1 + b.tan_angle * b.tan_angle);
  const Frame f = frame_of(b);
  const bool bore_ellipse = !f.flat || f.crease() > -f.inner();
  if (b.bore_radius_m > 0 && bore_ellipse &&
      !(b.edge_radius_m < (b.bore_radius_m + b.edge_radius_m) * sine))
    throw ParameterError(
        "tip_radius is too large for this bore and bevel_angle: it must stay below "
        "bore / 2 * sin(bevel_angle) / (1 - sin(bevel_angle)), or the rounded bore rim folds");
  if (b.segments < 8) throw ParameterError("resolution must be at least 8 segments");
  if (f.flat) {
    // K''s flat runs from the crease X' to R - rho; a millionth of the radius at least on
    // either side keeps the two corners apart and some of the plane.
    const double margin = 1e-6 * b.outer_radius_m;
    if (!(f.crease() < f.outer() - margin))
      throw ParameterError(
          "tip_radius is too large for flat_width: the flat must be wider than "
          "tip_radius (1 + (1 - sin(bevel_angle)) / cos(bevel_angle)), or rounding takes all of "
          "it");
    if (!(f.crease() > -f.outer() + margin))
      throw ParameterError(
          "flat_width is too large for tip_radius: the rounded flat would leave no bevel");
  }
  if (!(f.plane_z(-f.R) + f.rho < f.top))
    throw ParameterError("the bevel (diameter / tan(bevel_angle)) is longer than length");
}

MeshBuilder build_rounded_bevel(const RoundedBevel& b) {
  check_rounded_bevel(b);
  const Frame f = frame_of(b);
  if (f.flat) return build_blunt(b, f);
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

bool rounded_bevel_contains(const RoundedBevel& b, Point3 p) {
  check_rounded_bevel(b);
  const Frame f = frame_of(b);
  const double z = p.z + rounded_bevel_tip_height(b);
  return f.flat ? in_blunt_opening(f, p.x, p.y, z) : in_opening(f, p.x, p.y, z);
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
  const double sharp_b = f.X - z * b.tan_angle;
  for (int k = 0; k < kRays; ++k) {
    const double a = (k + 0.5) * d_angle;
    const double ca = std::cos(a), sa = std::sin(a);
    auto member = [&](double r) {
      return f.flat ? in_blunt_opening(f, r * ca, r * sa, z) : in_opening(f, r * ca, r * sa, z);
    };
    // The opening lies inside the unrounded bevel, whose slice on this ray is r cos(a) >=
    // sharp_b within the annulus: the samples span that interval, however short it is.
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
