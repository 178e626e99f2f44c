// Closed-form indentation of a layered block by a rigid punch of revolution.
// Equations, units and sources: docs/model.md, "The fast analytic path".
//  - Sneddon (1965) general solution for a frictionless punch of profile h(r) on a half-space;
//    for a piecewise-linear profile both of its integrals are closed-form (asin and sqrt terms).
//  - Gao, Chiu & Lee (1992) two-layer weight function I0, applied layer by layer from the bottom
//    (our reconstruction for more than two layers).
//  - Hayes et al. (1972) finite-layer factor kappa(a/H, nu) for the stack bonded to a rigid base.
#include "mneedle/insertion/analytic_indentation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/geometry/cross_section.h"

namespace mneedle {
namespace {

// Relative change of a sliced radius below which it is round-off (equivalent needle).
constexpr double kRadiusNoise = 1e-6;

constexpr double kPi = 3.14159265358979323846;

std::string um(double metres) {
  std::ostringstream out;
  out.precision(6);
  out << metres * 1e6 << " um";
  return out.str();
}

// A sloped piece of the profile h(r): height above the tip rises by `slope` per metre of radius
// on r0 <= r <= r1. Flat pieces (slope 0) contribute nothing to Sneddon's integrals.
struct Segment {
  double r0 = 0.0;
  double r1 = 0.0;
  double slope = 0.0;
};

struct Profile {
  std::vector<Segment> segments;
  double max_radius = 0.0;   // vertical wall beyond: the contact radius cannot grow further
  double bore_radius = 0.0;  // the bore is treated as filled flat at the tip's height
};

void check_needle(const fe::AxisymmetricNeedle& n) {
  const auto& h = n.heights_m;
  const auto& r = n.radii_m;
  if (h.empty() || h.size() != r.size())
    throw InputError(
        "analytic indentation: needle profile needs equal, non-empty height and radius lists");
  if (h.front() != 0.0)
    throw InputError("analytic indentation: needle profile must start at height 0");
  for (std::size_t i = 0; i < h.size(); ++i) {
    if (!std::isfinite(h[i]) || !std::isfinite(r[i]) || r[i] < 0.0)
      throw InputError("analytic indentation: needle profile point " + std::to_string(i) +
                       " is not finite or has a negative radius");
    if (i > 0 && (h[i] <= h[i - 1] || r[i] < r[i - 1]))
      throw InputError("analytic indentation: needle profile point " + std::to_string(i) +
                       ": heights must increase and radii must not decrease");
  }
  if (!(n.max_radius() > 0.0)) throw InputError("analytic indentation: needle has zero radius");
  if (!std::isfinite(n.bore_radius_m) || n.bore_radius_m < 0.0 || n.bore_radius_m >= n.max_radius())
    throw InputError("analytic indentation: bore radius " + um(n.bore_radius_m) +
                     " must be in [0, outer radius " + um(n.max_radius()) + ")");
  if (r.front() < n.bore_radius_m)
    throw InputError("analytic indentation: the tip radius " + um(r.front()) +
                     " lies inside the bore " + um(n.bore_radius_m));
}

Profile make_profile(const fe::AxisymmetricNeedle& n) {
  Profile p;
  p.max_radius = n.max_radius();
  p.bore_radius = n.bore_radius_m;
  for (std::size_t i = 1; i < n.heights_m.size(); ++i) {
    const double r0 = std::max(n.radii_m[i - 1], p.bore_radius);
    const double r1 = n.radii_m[i];
    if (r1 <= r0) continue;  // a vertical wall (or inside the bore): no sloped piece
    // Clipping at the bore keeps the true height at r0 because the profile is linear there.
    const double slope = (n.heights_m[i] - n.heights_m[i - 1]) / (n.radii_m[i] - n.radii_m[i - 1]);
    p.segments.push_back({r0, r1, slope});
  }
  return p;
}

// Phi(t) = t * integral_0^t h'(r) / sqrt(t^2 - r^2) dr: the depth at which the contact radius is
// t (Sneddon's edge condition), metres.
double depth_at_contact_radius(const Profile& p, double t) {
  if (!(t > 0.0)) return 0.0;
  double sum = 0.0;
  for (const Segment& s : p.segments) {
    if (s.r0 >= t) break;
    sum += s.slope * (std::asin(std::min(s.r1 / t, 1.0)) - std::asin(s.r0 / t));
  }
  return t * sum;
}

// J(c, t) = integral_0^t tau * asin(min(c, tau) / tau) d tau, m^2.
double asin_moment(double c, double t) {
  if (t <= c) return 0.25 * kPi * t * t;
  return 0.5 * t * t * std::asin(c / t) + 0.5 * c * std::sqrt(t * t - c * c);
}

// integral_0^a Phi(t) dt, m^2.
double integrated_depth(const Profile& p, double a) {
  double sum = 0.0;
  for (const Segment& s : p.segments) {
    if (s.r0 >= a) break;
    sum += s.slope * (asin_moment(s.r1, a) - asin_moment(s.r0, a));
  }
  return sum;
}

// Contact radius at depth d: Phi(a) = d on (0, max_radius], else max_radius (the punch's edge).
double contact_radius(const Profile& p, double d) {
  if (!(d > 0.0)) return 0.0;
  if (depth_at_contact_radius(p, p.max_radius) <= d) return p.max_radius;
  double lo = 0.0;
  double hi = p.max_radius;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * p.max_radius; ++i) {
    const double mid = 0.5 * (lo + hi);
    (depth_at_contact_radius(p, mid) < d ? lo : hi) = mid;
  }
  return hi;
}

// Gao, Chiu & Lee (1992) weight functions of xi = film thickness / contact radius.
double gao_i0(double xi, double nu) {
  if (!std::isfinite(xi)) return 1.0;
  if (xi <= 0.0) return 0.0;
  const double log_term = xi * std::log1p(1.0 / (xi * xi));
  return 2.0 / kPi * std::atan(xi) +
         ((1.0 - 2.0 * nu) * log_term - xi / (1.0 + xi * xi)) / (2.0 * kPi * (1.0 - nu));
}

double gao_i1(double xi) {
  if (!std::isfinite(xi)) return 1.0;
  if (xi <= 0.0) return 0.0;
  return 2.0 / kPi * std::atan(xi) + xi / kPi * std::log1p(1.0 / (xi * xi));
}

// Hayes et al. (1972) kappa(a/h, nu) for a layer bonded to a rigid base (reference-data.md).
constexpr std::array<double, 7> kHayesX{0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 2.0};
constexpr std::array<double, 3> kHayesNu{0.3, 0.45, 0.5};
constexpr std::array<std::array<double, 7>, 3> kHayesKappa{{
    {1.0, 1.207, 1.472, 1.784, 2.124, 2.480, 4.336},
    {1.0, 1.252, 1.599, 2.031, 2.532, 3.085, 6.380},
    {1.0, 1.281, 1.683, 2.211, 2.855, 3.609, 9.069},
}};

double hayes_row(std::size_t row, double x) {
  const auto& k = kHayesKappa[row];
  for (std::size_t i = 1; i < kHayesX.size(); ++i)
    if (x <= kHayesX[i]) {
      const double t = (x - kHayesX[i - 1]) / (kHayesX[i] - kHayesX[i - 1]);
      return k[i - 1] + t * (k[i] - k[i - 1]);
    }
  return k.back();
}

double hayes_kappa(double a_over_h, double nu) {
  if (!(a_over_h >= 0.0) || a_over_h > kHayesX.back())
    throw InputError(
        "analytic indentation: contact radius / block depth = " + std::to_string(a_over_h) +
        " is outside the finite-layer table (0 to 2, Hayes et al. 1972)");
  if (nu <= kHayesNu.front()) return hayes_row(0, a_over_h);  // the factor falls with nu
  for (std::size_t j = 1; j < kHayesNu.size(); ++j)
    if (nu <= kHayesNu[j]) {
      const double t = (nu - kHayesNu[j - 1]) / (kHayesNu[j] - kHayesNu[j - 1]);
      return (1.0 - t) * hayes_row(j - 1, a_over_h) + t * hayes_row(j, a_over_h);
    }
  return hayes_row(kHayesNu.size() - 1, a_over_h);
}

struct EffectiveModulus {
  double reduced_modulus_Pa = 0.0;  // E* = 2 mu / (1 - nu)
  double shear_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
};

double plate_modulus(double D, double e_found, double a);

EffectiveModulus effective_modulus(const Tissue& tissue, double contact_radius_m) {
  const auto& layers = tissue.layers;
  double mu = layers.back().material.shear_modulus();
  double nu = layers.back().material.poisson_ratio;
  for (std::size_t k = layers.size() - 1; k-- > 0;) {
    const TissueMaterial& film = layers[k].material;
    const double xi = contact_radius_m > 0.0 ? layers[k].thickness / contact_radius_m
                                             : std::numeric_limits<double>::infinity();
    const double mu_f = film.shear_modulus();
    const double nu_f = film.poisson_ratio;
    mu = mu + (mu_f - mu) * gao_i0(xi, nu_f);
    nu = 1.0 - (1.0 - nu) * (1.0 - nu_f) / (1.0 - nu_f + (nu_f - nu) * gao_i1(xi));
  }
  EffectiveModulus gao{2.0 * mu / (1.0 - nu), mu, nu};
  if (layers.size() < 2 || !(contact_radius_m > 0.0)) return gao;
  // A top layer stiffer than what is beneath bends as a plate and spreads the load: Gao's
  // weight function, a first-order perturbation, misses that (100x too stiff for 1 GPa stratum
  // corneum on 0.1 MPa). The smaller of the two is taken (docs/model.md, "The fast analytic
  // path", 3).
  Tissue below = tissue;
  below.layers.erase(below.layers.begin());
  const EffectiveModulus foundation = effective_modulus(below, contact_radius_m);
  const TissueMaterial& top = layers.front().material;
  const double t = layers.front().thickness;
  const double D =
      top.youngs_modulus * t * t * t / (12.0 * (1.0 - top.poisson_ratio * top.poisson_ratio));
  const double plate = plate_modulus(D, foundation.reduced_modulus_Pa, contact_radius_m);
  if (plate < gao.reduced_modulus_Pa) gao.reduced_modulus_Pa = plate;
  return gao;
}

// Reduced modulus of the top layer acting as a Kirchhoff plate (bending stiffness D) on the
// layers below (reduced modulus e_found), pressed over a disc of radius a (Hankel transform of
// a plate on an elastic half-space, surface stiffness E* k / 2 per wavenumber k):
// w0 / P = (1 / 2 pi) int_0^inf [2 J1(k a) / (k a)] / (D k^3 + E*/2) dk, uniform pressure.
// The rigid punch is 4/pi stiffer than uniform pressure on a half-space (2 a E* vs pi a E* / 2);
// that factor makes the D -> 0 limit exactly the foundation. Returned as k / (2 a).
double plate_modulus(double D, double e_found, double a) {
  const double c = 0.5 * e_found;
  const double scale = D / (a * a * a);
  // Integrand in x = k a. A stiff plate concentrates it below x_c = (c / scale)^(1/3): [0, 1e-4
  // min(1, x_c)] is constant, (.., 1] Simpson in log x, [1, X] Simpson in x (step 0.05, through
  // the J1 oscillations); beyond X = min(2000, max(50, 40 x_c)) the remainder is < 1e-4.
  auto f = [&](double x) {
    const double shape = x < 1e-8 ? 1.0 : 2.0 * std::cyl_bessel_j(1.0, x) / x;
    return shape / (scale * x * x * x + c);
  };
  const double x_c = scale > 0.0 ? std::cbrt(c / scale) : 1e300;
  const double x_lo = 1e-4 * std::min(1.0, x_c);
  const double x_max = std::min(2000.0, std::max(50.0, 40.0 * x_c));
  auto simpson = [](auto&& g, double lo, double hi, int n) {
    const double h = (hi - lo) / n;
    double acc = g(lo) + g(hi);
    for (int i = 1; i < n; ++i) acc += (i % 2 ? 4.0 : 2.0) * g(lo + i * h);
    return acc * h / 3.0;
  };
  double sum = x_lo * f(0.0);
  sum += simpson([&](double u) { return f(std::exp(u)) * std::exp(u); }, std::log(x_lo), 0.0, 400);
  sum += simpson(f, 1.0, x_max, 2 * static_cast<int>(std::ceil((x_max - 1.0) / 0.1)));
  const double compliance = sum / (2.0 * kPi * a);  // w0 / P, m/N
  return 4.0 / kPi / compliance / (2.0 * a);
}

void check_tissue(const Tissue& tissue) {
  if (tissue.layers.empty()) throw InputError("analytic indentation: tissue has no layers");
  for (const TissueLayer& l : tissue.layers) {
    const TissueMaterial& m = l.material;
    if (!(l.thickness > 0.0) || !std::isfinite(l.thickness))
      throw InputError("analytic indentation: layer '" + l.name + "': thickness must be > 0");
    if (!(m.youngs_modulus > 0.0) || !std::isfinite(m.youngs_modulus))
      throw InputError("analytic indentation: layer '" + l.name + "': Young's modulus must be > 0");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
      throw InputError("analytic indentation: layer '" + l.name +
                       "': Poisson's ratio must be in (-1, 0.5)");
  }
  if (!(tissue.size[0] > 0.0) || !(tissue.size[1] > 0.0))
    throw InputError("analytic indentation: tissue block needs a positive lateral size");
}

double total_depth(const Tissue& tissue) {
  double h = 0.0;
  for (const TissueLayer& l : tissue.layers) h += l.thickness;
  return h;
}

}  // namespace

fe::AxisymmetricNeedle equivalent_axisymmetric_needle(const TriangleMesh& mesh, double height_m,
                                                      int samples) {
  if (!(height_m > 0.0) || !std::isfinite(height_m))
    throw InputError("equivalent needle: height must be > 0 (got " + um(height_m) + ")");
  if (samples < 2) throw InputError("equivalent needle: samples must be at least 2");
  const BoundingBox box = bounding_box(mesh);
  const double length = box.max[2] - box.min[2];
  if (!(length > 0.0)) throw InputError("equivalent needle: the mesh has no length along z");
  const CrossSectionSlicer slicer(mesh);
  // Planes through the tip or base vertices give degenerate loops: stay just inside the mesh.
  const double inset = 1e-7 * length;
  const double top = std::min(height_m, length);
  fe::AxisymmetricNeedle needle;
  double radius = 0.0;
  for (int i = 0; i <= samples; ++i) {
    const double h = top * i / samples;
    const double area = slicer.slice(std::clamp(h, inset, length - inset)).area_m2;
    // Running maximum: a narrower section above a wider one never meets the tissue first. A
    // rise within 1e-6 of it is the slicer's round-off, not a taper: kept as the same radius
    // (a near-vertical piece of slope 1e5 would wreck Sneddon's integrals).
    const double r = std::sqrt(std::max(area, 0.0) / kPi);
    if (r > radius * (1.0 + kRadiusNoise)) radius = r;
    needle.heights_m.push_back(h);
    needle.radii_m.push_back(radius);
  }
  if (!(needle.max_radius() > 0.0))
    throw InputError("equivalent needle: no section of the mesh has a positive area");
  return needle;
}

std::vector<AnalyticStep> analytic_indentation(const Tissue& tissue,
                                               const fe::AxisymmetricNeedle& needle,
                                               const std::vector<double>& depths_m) {
  check_tissue(tissue);
  check_needle(needle);
  const Profile profile = make_profile(needle);
  const double block_depth = total_depth(tissue);
  const double half_width = 0.5 * std::min(tissue.size[0], tissue.size[1]);
  const double nu_base = tissue.layers.back().material.poisson_ratio;
  std::vector<AnalyticStep> steps;
  double previous = 0.0;
  for (double d : depths_m) {
    if (!std::isfinite(d) || d < 0.0 || d < previous)
      throw InputError("analytic indentation: depths must be finite, >= 0 and ascending (got " +
                       um(d) + ")");
    previous = d;
    if (d >= block_depth)
      throw InputError("analytic indentation: depth " + um(d) + " reaches the block's depth " +
                       um(block_depth));
    const double a = contact_radius(profile, d);
    if (a > half_width)
      throw InputError("analytic indentation: contact radius " + um(a) + " at depth " + um(d) +
                       " exceeds the block's half-width " + um(half_width) +
                       " (the closed form assumes a laterally unbounded block)");
    AnalyticStep step;
    step.depth_m = d;
    if (a > 0.0) {
      const double kappa = hayes_kappa(a / block_depth, nu_base);
      const double e_star = effective_modulus(tissue, a).reduced_modulus_Pa;
      step.force_N = 2.0 * e_star * kappa * (d * a - integrated_depth(profile, a));
      const double inner = std::min(profile.bore_radius, a);
      step.contact_area_m2 = kPi * (a * a - inner * inner);
      step.contact_pressure_Pa =
          step.contact_area_m2 > 0.0 ? step.force_N / step.contact_area_m2 : 0.0;
    }
    if (!std::isfinite(step.force_N) || !std::isfinite(step.contact_pressure_Pa))
      throw SolverError("analytic indentation: non-finite force at depth " + um(d));
    steps.push_back(step);
  }
  return steps;
}

}  // namespace mneedle
