#include "mneedle/needle/needle_frame.h"

#include <Eigen/Dense>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

Vector3d to_eigen(const Vec3& p) {
  return {p[0], p[1], p[2]};
}
Vec3 to_vec3(const Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

// Relative tolerance on lengths: far below any feature a needle mesh resolves, far above
// the rounding of coordinates read as floats.
constexpr double kRelativeTolerance = 1e-6;
// Where `auto` probes each end's cross-section, as a fraction of the length from the end.
constexpr double kProbeFraction = 0.05;
// Ends whose probed widths differ by less than this fraction count as alike.
constexpr double kAlikeFraction = 0.02;
// A principal axis is trusted when its moment is this many times the next one (a needle is
// several times longer than wide; a short, wide body or a needle on a wide plate is not).
constexpr double kElongation = 1.5;
// ... and then a needle's end is found when its section is this narrow against the other end's.
constexpr double kHolderNarrowing = 0.25;
// Faces whose normal is within asin(0.2) = 11.5 deg of perpendicular to a trial axis count as
// the shaft's sides when the axis is refined (a bevel tilts the principal axis by a few deg).
constexpr double kSideFaceSlope = 0.2;
// The second pass's: within asin(0.01) = 0.57 deg of parallel (refined_by_side_faces).
constexpr double kShaftFaceSlope = 0.01;
// ... and the share of the first pass's face area those must carry to be the shaft.
constexpr double kShaftFaceShare = 0.5;
// The trimmed pass's (trimmed_side_face_axis): its shaft's share of the first set, and how evenly
// its normals must spread round the axis (smaller over larger moment).
constexpr double kTrimmedShaftShare = 0.25;
constexpr double kTrimmedSpread = 0.1;

double size_of(const TriangleMesh& mesh) {
  const BoundingBox box = bounding_box(mesh);
  return (to_eigen(box.max) - to_eigen(box.min)).norm();
}

// Area centroid of the faces `keep` accepts (corners a, b, c); nullopt when they have no area.
std::optional<Vector3d> area_centroid_of(
    const TriangleMesh& mesh,
    const std::function<bool(const Vector3d&, const Vector3d&, const Vector3d&)>& keep) {
  Vector3d weighted = Vector3d::Zero();
  double area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vector3d a = to_eigen(mesh.vertices[t[0]]);
    const Vector3d b = to_eigen(mesh.vertices[t[1]]);
    const Vector3d c = to_eigen(mesh.vertices[t[2]]);
    if (!keep(a, b, c)) continue;
    const double dA = 0.5 * (b - a).cross(c - a).norm();
    weighted += dA * (a + b + c) / 3.0;
    area += dA;
  }
  if (!(area > 0.0)) return std::nullopt;
  return Vector3d(weighted / area);
}

// Area centroid of the surface; the fallback for meshes that enclose no volume.
Vector3d area_centroid(const TriangleMesh& mesh) {
  return area_centroid_of(mesh,
                          [](const Vector3d&, const Vector3d&, const Vector3d&) { return true; })
      .value_or(to_eigen(mesh.vertices.front()));
}

Vector3d centroid(const TriangleMesh& mesh) {
  // Tetrahedra from a point near the mesh keep the sums well conditioned far from the origin.
  const Vector3d origin = area_centroid(mesh);
  Vector3d weighted = Vector3d::Zero();
  double six_volume = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vector3d a = to_eigen(mesh.vertices[t[0]]) - origin;
    const Vector3d b = to_eigen(mesh.vertices[t[1]]) - origin;
    const Vector3d c = to_eigen(mesh.vertices[t[2]]) - origin;
    const double dv = a.dot(b.cross(c));
    weighted += dv * (a + b + c) / 4.0;
    six_volume += dv;
  }
  const double scale = size_of(mesh);
  if (std::abs(six_volume) <= kRelativeTolerance * scale * scale * scale) return origin;
  return origin + weighted / six_volume;
}

// Second moment of the surface about `center`: the integral of (x-c)(x-c)^T over each
// triangle is A/12 (sum of v v^T over the corners + 9 m m^T), m the triangle's centroid.
Matrix3d surface_second_moment(const TriangleMesh& mesh, const Vector3d& center) {
  Matrix3d moment = Matrix3d::Zero();
  for (const Triangle& t : mesh.triangles) {
    const Vector3d a = to_eigen(mesh.vertices[t[0]]) - center;
    const Vector3d b = to_eigen(mesh.vertices[t[1]]) - center;
    const Vector3d c = to_eigen(mesh.vertices[t[2]]) - center;
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const Vector3d m = (a + b + c) / 3.0;
    moment += area / 12.0 *
              (a * a.transpose() + b * b.transpose() + c * c.transpose() + 9.0 * m * m.transpose());
  }
  return moment;
}

// Points where the plane (x - center).axis = level cuts the surface.
std::vector<Vector3d> cross_section_points(const TriangleMesh& mesh, const Vector3d& center,
                                           const Vector3d& axis, double level) {
  std::vector<Vector3d> points;
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const Vector3d p = to_eigen(mesh.vertices[t[k]]);
      const Vector3d q = to_eigen(mesh.vertices[t[(k + 1) % 3]]);
      const double hp = (p - center).dot(axis) - level;
      const double hq = (q - center).dot(axis) - level;
      if (hp == 0.0) points.push_back(p);
      if ((hp < 0.0 && hq > 0.0) || (hp > 0.0 && hq < 0.0)) {
        points.push_back(p + (q - p) * (hp / (hp - hq)));
      }
    }
  }
  return points;
}

// Width of a cross-section: the diagonal of its bounding rectangle in the section plane.
double section_width(const std::vector<Vector3d>& points, const Vector3d& u, const Vector3d& w) {
  if (points.empty()) return 0.0;
  double u_min = std::numeric_limits<double>::infinity(), u_max = -u_min;
  double w_min = u_min, w_max = -u_min;
  for (const Vector3d& p : points) {
    u_min = std::min(u_min, p.dot(u));
    u_max = std::max(u_max, p.dot(u));
    w_min = std::min(w_min, p.dot(w));
    w_max = std::max(w_max, p.dot(w));
  }
  return std::hypot(u_max - u_min, w_max - w_min);
}

std::pair<double, double> extent_along(const TriangleMesh& mesh, const Vector3d& center,
                                       const Vector3d& axis) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const Vec3& p : mesh.vertices) {
    const double h = (to_eigen(p) - center).dot(axis);
    low = std::min(low, h);
    high = std::max(high, h);
  }
  return {low, high};
}

// A point of the shaft's axis: the area centroid of the base, the faces at the end farthest
// from the tip that face away from it (the section of the shaft there, bore excluded, whose
// centroid is on the axis of a tube however its wall is triangulated). The volume centroid is
// not on it: a bevel's cut moves it toward the heel. Falls back to `center` without a flat base.
Vector3d shaft_axis_point(const TriangleMesh& mesh, const Vector3d& center,
                          const Vector3d& direction) {
  const auto [low, high] = extent_along(mesh, center, direction);
  const double level = low + kRelativeTolerance * std::max(high - low, size_of(mesh));
  auto at_base = [&](const Vector3d& p) { return (p - center).dot(direction) <= level; };
  return area_centroid_of(mesh,
                          [&](const Vector3d& a, const Vector3d& b, const Vector3d& c) {
                            const Vector3d n = (b - a).cross(c - a);
                            return at_base(a) && at_base(b) && at_base(c) &&
                                   n.dot(direction) <= -0.999 * n.norm();
                          })
      .value_or(center);
}

std::string format_vector(const Vector3d& v) {
  std::ostringstream out;
  out.precision(4);
  out << "(" << v.x() + 0.0 << ", " << v.y() + 0.0 << ", " << v.z() + 0.0 << ")";  // no "-0"
  return out.str();
}

// A principal axis is tilted by whatever breaks the body's symmetry (a bevel's cut tilts it by
// degrees). The shaft's side faces are exactly parallel to the true axis: among the faces
// within `slope` of parallel to `axis`, the direction their normals avoid (the smallest
// eigenvector of sum A n n^T) is the shaft's axis. Empty without a clear shaft; `area` (m^2)
// is what the faces taken in add up to.
std::optional<Vector3d> side_face_axis(const TriangleMesh& mesh, const Vector3d& axis, double slope,
                                       double* area) {
  Matrix3d tensor = Matrix3d::Zero();
  *area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vector3d a = to_eigen(mesh.vertices[t[0]]);
    const Vector3d n2 =
        (to_eigen(mesh.vertices[t[1]]) - a).cross(to_eigen(mesh.vertices[t[2]]) - a);
    const double twice_area = n2.norm();
    if (!(twice_area > 0.0)) continue;
    const Vector3d n = n2 / twice_area;
    if (std::abs(n.dot(axis)) < slope) {
      tensor += 0.5 * twice_area * n * n.transpose();
      *area += 0.5 * twice_area;
    }
  }
  const Eigen::SelfAdjointEigenSolver<Matrix3d> solver(tensor);
  const auto& lambda = solver.eigenvalues();
  if (!(lambda[1] > 0.0) || !(lambda[0] < 1e-3 * lambda[1])) return std::nullopt;
  const Vector3d refined = solver.eigenvectors().col(0);
  return refined.dot(axis) < 0.0 ? Vector3d(-refined) : refined;
}

// When the faces within kSideFaceSlope of parallel to the principal axis hold more than the
// shaft, their normals span no plane and side_face_axis finds none: a long bevel (17 deg and
// less) tilts the principal axis by 6.5 deg, within which its face then counts as a side. The
// shaft's faces lie on one plane of normals, the bevel's off it: drop the faces furthest off the
// current estimate's plane (beyond half the furthest) and estimate again, while the faces kept
// are still kTrimmedShaftShare of the first set's area (a 15 deg bevel's shaft holds 32 % of it,
// the face the rest). The plane found must be spread round the axis (its two moments within
// kTrimmedSpread), as a shaft's walls are and a flat's two sides are not. Empty otherwise.
std::optional<Vector3d> trimmed_side_face_axis(const TriangleMesh& mesh, const Vector3d& axis) {
  struct Face {
    Vector3d normal;
    double area;
  };
  std::vector<Face> faces;
  double total = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vector3d a = to_eigen(mesh.vertices[t[0]]);
    const Vector3d n2 =
        (to_eigen(mesh.vertices[t[1]]) - a).cross(to_eigen(mesh.vertices[t[2]]) - a);
    const double twice_area = n2.norm();
    if (!(twice_area > 0.0) || !(std::abs(n2.dot(axis)) < kSideFaceSlope * twice_area)) continue;
    faces.push_back({n2 / twice_area, 0.5 * twice_area});
    total += 0.5 * twice_area;
  }
  Vector3d estimate = axis;
  for (int round = 0; round < 64; ++round) {
    Matrix3d tensor = Matrix3d::Zero();
    double kept = 0.0;
    for (const Face& f : faces) tensor += f.area * f.normal * f.normal.transpose(), kept += f.area;
    const Eigen::SelfAdjointEigenSolver<Matrix3d> solver(tensor);
    const auto& lambda = solver.eigenvalues();
    if (!(kept >= kTrimmedShaftShare * total)) return std::nullopt;
    if (!(lambda[1] > 0.0)) return std::nullopt;
    estimate = solver.eigenvectors().col(0);
    if (estimate.dot(axis) < 0.0) estimate = -estimate;
    if (lambda[0] < 1e-3 * lambda[1])
      return lambda[1] >= kTrimmedSpread * lambda[2] ? std::optional<Vector3d>(estimate)
                                                     : std::nullopt;
    double furthest = 0.0;
    for (const Face& f : faces) furthest = std::max(furthest, std::abs(f.normal.dot(estimate)));
    std::erase_if(faces,
                  [&](const Face& f) { return std::abs(f.normal.dot(estimate)) > 0.5 * furthest; });
  }
  return std::nullopt;
}

// Faces within kSideFaceSlope of parallel take in more than the shaft: a rounded edge's last
// steps before the wall (within 6 deg of it for 16 steps a quarter turn) tilt the axis where they
// are not spread evenly around it (4.6e-5 rad for a rounded blunt bevel, which lifted part of its
// flat 2 nm and its base out of the base's level). A second pass keeps only the faces within
// kShaftFaceSlope of the first pass's axis, the shaft's own walls. It stands only if they are
// most of the first pass's faces (kShaftFaceShare of their area): a tapered shaft has none, and
// a few exactly parallel faces elsewhere (a hub, a holder's side) must not decide the axis.
// Returns `axis` unchanged without a clear shaft.
Vector3d refined_by_side_faces(const TriangleMesh& mesh, const Vector3d& axis) {
  double first_area = 0.0, shaft_area = 0.0;
  std::optional<Vector3d> first = side_face_axis(mesh, axis, kSideFaceSlope, &first_area);
  if (!first) first = trimmed_side_face_axis(mesh, axis);
  if (!first) return axis;
  const std::optional<Vector3d> shaft = side_face_axis(mesh, *first, kShaftFaceSlope, &shaft_area);
  return shaft && shaft_area >= kShaftFaceShare * first_area ? *shaft : *first;
}

// `axis` (either sign; the principal axis when empty), signed so that it points toward the
// narrower end. Empty when no axis was given and the body has no clear principal axis.
std::optional<Vector3d> narrower_end_direction(const TriangleMesh& mesh, const Vector3d& center,
                                               std::optional<Vector3d> given, std::string& note) {
  const Eigen::SelfAdjointEigenSolver<Matrix3d> solver(surface_second_moment(mesh, center));
  const auto& moments = solver.eigenvalues();  // ascending
  if (!given && !(moments[2] >= kElongation * moments[1])) {
    // Not longer than wide: a needle on a wide holder or plate, or a short, wide body. The tip is
    // the narrowest end of any principal axis; a holder's rim is never that narrow.
    double best_width = std::numeric_limits<double>::infinity(), other_end = 0.0;
    Vector3d best;
    for (int k = 0; k < 3; ++k) {
      const Vector3d a = refined_by_side_faces(mesh, solver.eigenvectors().col(k));
      const Vector3d u = a.unitOrthogonal();
      const Vector3d w = a.cross(u);
      const auto [low, high] = extent_along(mesh, center, a);
      const double probe = kProbeFraction * (high - low);
      const double lw = section_width(cross_section_points(mesh, center, a, low + probe), u, w);
      const double hw = section_width(cross_section_points(mesh, center, a, high - probe), u, w);
      if (std::min(lw, hw) < best_width) {
        best_width = std::min(lw, hw);
        other_end = std::max(lw, hw);
        best = lw < hw ? Vector3d(-a) : a;
      }
    }
    std::ostringstream out;
    out.precision(4);
    out << "auto axis: the body is not clearly longer than it is wide (principal moments "
        << format_vector(moments) << "); ";
    if (best_width < kHolderNarrowing * other_end) {
      out << "the narrowest end of a principal axis, " << format_vector(best) << " (section "
          << best_width << " m wide against " << other_end << " m at the other end), is the tip";
      note = out.str();
      return best;
    }
    out << "no end is narrower than the other: used the input z, tip at the lowest z";
    note = out.str();
    return std::nullopt;
  }
  Vector3d axis =
      given ? given->normalized() : refined_by_side_faces(mesh, solver.eigenvectors().col(2));
  Eigen::Index largest = 0;
  axis.cwiseAbs().maxCoeff(&largest);
  if (axis[largest] < 0.0) axis = -axis;  // a reproducible sign for the tie-break below
  // Two directions across the axis for the section widths.
  const Vector3d u = axis.unitOrthogonal();
  const Vector3d w = axis.cross(u);
  const auto [low, high] = extent_along(mesh, center, axis);
  const double probe = kProbeFraction * (high - low);
  const double low_width =
      section_width(cross_section_points(mesh, center, axis, low + probe), u, w);
  const double high_width =
      section_width(cross_section_points(mesh, center, axis, high - probe), u, w);
  std::ostringstream out;
  out.precision(4);
  out << (given ? "axis: given line " : "auto axis: principal axis ") << format_vector(axis)
      << "; cross-section widths " << kProbeFraction * 100 << "% from each end: " << low_width
      << " m (low end) and " << high_width << " m (high end); ";
  if (std::abs(low_width - high_width) <= kAlikeFraction * std::max(low_width, high_width)) {
    out << "the ends look alike: chose the low end as the tip";
    note = out.str();
    return -axis;
  }
  const bool low_is_tip = low_width < high_width;
  out << "chose the " << (low_is_tip ? "low" : "high") << " end (narrower) as the tip";
  note = out.str();
  return low_is_tip ? Vector3d(-axis) : axis;
}

Vector3d normalized_direction(const Vec3& direction) {
  const Vector3d d = to_eigen(direction);
  const double length = d.norm();
  if (!std::isfinite(length) || length == 0.0) {
    throw InputError("axis: the tip direction must be a non-zero, finite vector (got " +
                     format_vector(d) + ")");
  }
  return d / length;
}

// The extreme vertex along the tip direction, or for a flat or hollow tip the point of the
// centroid's axis line at the level of the lowest cross-section.
Vector3d find_tip(const TriangleMesh& mesh, const Vector3d& center, const Vector3d& direction,
                  std::string& note) {
  const auto [low, high] = extent_along(mesh, center, direction);
  const double level_tolerance = kRelativeTolerance * std::max(high - low, size_of(mesh));
  std::vector<Vector3d> extreme;
  for (const Vec3& p : mesh.vertices) {
    if ((to_eigen(p) - center).dot(direction) >= high - level_tolerance) {
      extreme.push_back(to_eigen(p));
    }
  }
  Vector3d mean = Vector3d::Zero();
  for (const Vector3d& p : extreme) mean += p;
  mean /= static_cast<double>(extreme.size());
  double spread = 0.0;
  for (const Vector3d& p : extreme) spread = std::max(spread, (p - mean).norm());
  if (spread <= level_tolerance) {
    note += (note.empty() ? "" : "; ") + std::string("tip at the extreme vertex");
    return mean;
  }
  note += (note.empty() ? "" : "; ") +
          std::string("flat or hollow tip: tip on the centroid axis in the lowest cross-section");
  return center + high * direction;
}

}  // namespace

FrameInfo find_needle_frame(const TriangleMesh& mesh, const AxisChoice& choice) {
  if (mesh.triangles.empty() || mesh.vertices.empty()) {
    throw InputError("needle frame: the mesh is empty");
  }
  FrameInfo info;
  const Vector3d center = centroid(mesh);
  Vector3d direction(0.0, 0.0, -1.0);
  switch (choice.kind) {
    case AxisChoice::Kind::input_z:
      info.note = "axis: input z, tip at the lowest z";
      break;
    case AxisChoice::Kind::given:
      direction = normalized_direction(choice.tip_direction);
      info.note = "axis: given tip direction " + format_vector(direction);
      break;
    case AxisChoice::Kind::line:
      if (const auto d = narrower_end_direction(
              mesh, center, normalized_direction(choice.tip_direction), info.note)) {
        direction = *d;
      } else {
        info.fell_back_to_input_z = true;
      }
      break;
    case AxisChoice::Kind::automatic:
      if (const auto d = narrower_end_direction(mesh, center, std::nullopt, info.note)) {
        direction = *d;
        info.auto_axis = true;
      } else {
        info.fell_back_to_input_z = true;
      }
      break;
  }
  info.axis = to_vec3(direction);
  info.tip = to_vec3(find_tip(mesh, center, direction, info.note));
  // The shaft axis where it crosses the tip's level: the frame's origin.
  const Vector3d shaft = shaft_axis_point(mesh, center, direction);
  const Vector3d tip = to_eigen(info.tip);
  info.origin = to_vec3(shaft + (tip - shaft).dot(direction) * direction);
  info.tip_offset_m = (tip - to_eigen(info.origin)).norm();
  return info;
}

FrameInfo place_in_needle_frame(TriangleMesh& mesh, const AxisChoice& choice) {
  const FrameInfo info = find_needle_frame(mesh, choice);
  // The smallest rotation taking the tip direction onto -z keeps the input's roll about
  // the axis (a bevel facing +x still faces +x).
  const Matrix3d rotation =
      Eigen::Quaterniond::FromTwoVectors(to_eigen(info.axis), Vector3d(0.0, 0.0, -1.0))
          .toRotationMatrix();
  const Vector3d origin = to_eigen(info.origin);
  for (Vec3& p : mesh.vertices) p = to_vec3(rotation * (to_eigen(p) - origin));
  return info;
}

AxisChoice parse_axis_choice(std::string_view text) {
  AxisChoice choice;
  const std::string t(text);
  if (t == "auto") {
    choice.kind = AxisChoice::Kind::automatic;
    return choice;
  }
  if (t == "x" || t == "y" || t == "z") {
    choice.kind = AxisChoice::Kind::line;
    choice.tip_direction = {t == "x" ? 1.0 : 0.0, t == "y" ? 1.0 : 0.0, t == "z" ? 1.0 : 0.0};
    return choice;
  }
  std::vector<double> parts;
  std::stringstream stream(t);
  for (std::string part; std::getline(stream, part, ',');) {
    double value = 0.0;
    const char* end = part.data() + part.size();
    const auto [rest, error] = std::from_chars(part.data(), end, value);
    if (error != std::errc() || rest != end || !std::isfinite(value)) {
      parts.clear();
      break;
    }
    parts.push_back(value);
  }
  if (parts.size() != 3) {
    throw InputError("axis '" + t +
                     "': expected auto, x, y, z (the tip at the narrower end) or a tip direction "
                     "a,b,c such as 0,-1,0");
  }
  choice.kind = AxisChoice::Kind::given;
  choice.tip_direction = {parts[0], parts[1], parts[2]};
  normalized_direction(choice.tip_direction);  // throws for a zero or non-finite vector
  return choice;
}

FrameInfo place_in_needle_frame(TriangleMesh& mesh, std::optional<Vec3> tip_direction) {
  AxisChoice choice;
  if (tip_direction) {
    choice.kind = AxisChoice::Kind::given;
    choice.tip_direction = *tip_direction;
  }
  return place_in_needle_frame(mesh, choice);
}

}  // namespace mneedle
