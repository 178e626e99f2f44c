#pragma once
// PRIVATE to mneedle::core: the few Vec3 operations the surface-load code needs, inline so the
// per-face loops stay cheap. Public headers keep Vec3 a plain std::array.

#include <cmath>

#include "mneedle/needle/mesh.h"

namespace mneedle::vec3 {

inline Vec3 add(const Vec3& a, const Vec3& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 scale(const Vec3& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
/// Linear interpolation a + t (b - a).
inline Vec3 lerp(const Vec3& a, const Vec3& b, double t) {
  return add(a, scale(sub(b, a), t));
}

/// Unit vector of `a`; {0,0,0} for a zero vector so degenerate faces stay harmless.
inline Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return n > 0.0 ? scale(a, 1.0 / n) : Vec3{0.0, 0.0, 0.0};
}

}  // namespace mneedle::vec3
