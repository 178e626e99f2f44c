// The top layer as a Kirchhoff plate on an elastic half-space, under a point load.
// Equations and their sources: docs/model.md, "The stress criterion on the analytic path".
// In units of the bending length l = (D / c)^(1/3), c = E*_f / 2 (a half-space's surface
// stiffness per wavenumber k is c k), the plate's response to a load of Hankel transform
// 1 / (2 pi) per newton (a point load), x = k l, is
//   w(r)   = 1 / (2 pi c l) int J0(y) / (x^3 + 1) dx,  y = x r / l
//   M_r(r) = 1 / (2 pi) int x^2 / (x^3 + 1) [J0(y) - (1 - nu) J1(y) / y] dx
//   M_t(r) = 1 / (2 pi) int x^2 / (x^3 + 1) [nu J0(y) + (1 - nu) J1(y) / y] dx
#include "mneedle/insertion/plate_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/insertion/analytic_indentation.h"

namespace mneedle {
namespace {

constexpr double kPi = std::numbers::pi;

// Gauss-Legendre, 8 points per panel, on [lo, hi] in panels no wider than `width`: the Bessel
// integrands oscillate with a fixed period in their argument, which the width resolves.
template <typename F>
double panels(F&& f, double lo, double hi, double width) {
  static constexpr double kX[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                   0.9602898564975363};
  static constexpr double kW[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                   0.1012285362903763};
  if (!(hi > lo)) return 0.0;
  const int n = std::max(1, static_cast<int>(std::ceil((hi - lo) / width)));
  const double h = (hi - lo) / n;
  double sum = 0.0;
  for (int p = 0; p < n; ++p) {
    const double mid = lo + (p + 0.5) * h, half = 0.5 * h;
    for (int i = 0; i < 4; ++i)
      sum += half * kW[i] * (f(mid - half * kX[i]) + f(mid + half * kX[i]));
  }
  return sum;
}

double j0(double x) {
  return std::cyl_bessel_j(0.0, x);
}
double j1(double x) {
  return std::cyl_bessel_j(1.0, x);
}

// Mean over a disc of radius rho (in units of l) of the hoop moment under a unit point load:
//   1/(2 pi) int x^2/(x^3+1) [nu A0(x rho) + (1 - nu) A1(x rho)] dx,
// A0(y) = 2 J1(y)/y and A1(y) = 2 (1 - J0(y))/y^2 being the disc means of J0 and J1(y)/y.
// Beyond x = 20 the kernel is 1/x (relative error 1.25e-4 at x = 20, 4e-5 of the integral
// past it) and the integral is taken in y = x rho, whose oscillation period 2 pi is fixed
// (panels of width 1); past y = 200 only A1's smooth part 2/y^2 counts (its tail is added; A0's
// oscillating remainder is below 1e-4 of the sum).
double disc_mean_hoop_moment(double rho, double nu) {
  auto shape = [nu](double y) {
    if (y < 1e-6) return 1.0 * nu + (1.0 - nu) * 0.5;
    return nu * 2.0 * j1(y) / y + (1.0 - nu) * 2.0 * (1.0 - j0(y)) / (y * y);
  };
  constexpr double kSplit = 20.0, kYMax = 200.0;
  double sum = panels([&](double x) { return x * x / (x * x * x + 1.0) * shape(x * rho); }, 0.0,
                      kSplit, 0.25);
  const double y_lo = kSplit * rho;
  sum += panels([&](double y) { return shape(y) / y; }, y_lo, std::max(y_lo, kYMax), 1.0);
  const double y_end = std::max(y_lo, kYMax);
  sum += (1.0 - nu) / (y_end * y_end);  // int_Y^inf 2 / y^3 dy of A1's smooth part
  return sum / (2.0 * kPi);
}

}  // namespace

PlateContact plate_contact(const Tissue& tissue, double contact_radius_m) {
  if (tissue.layers.size() < 2)
    throw InputError(
        "stress criterion on the analytic path: the tissue needs a top layer on others (it has " +
        std::to_string(tissue.layers.size()) + "); use --model axisymmetric or 3d");
  const TissueLayer& top = tissue.layers.front();
  if (!top.strength)
    throw InputError("stress criterion on the analytic path: layer '" + top.name +
                     "' has no strength and strength_length");
  const double E = top.material.youngs_modulus, nu = top.material.poisson_ratio;
  const double t = top.thickness, L = top.strength->length;
  const double D = E * t * t * t / (12.0 * (1.0 - nu * nu));
  // The foundation: the layer beneath as a half-space. Gao's weighting of all the layers beneath
  // at the plate's length l (the fixed point of l and E*_f) read 64 N/m on human skin where the
  // FE reads 84 N/m and this reads 89 N/m (docs/validation.md, "The stress criterion on the
  // analytic path"): a plate loads its foundation closer to the point than a punch of radius l.
  const TissueMaterial& beneath = tissue.layers[1].material;
  const double e_f = beneath.youngs_modulus / (1.0 - beneath.poisson_ratio * beneath.poisson_ratio);
  const double l = std::cbrt(2.0 * D / e_f);
  if (l < kPlateLengthPerThickness * t)
    throw InputError("stress criterion on the analytic path: layer '" + top.name + "' (" +
                     format_quantity(t, Dimension::Length) + ") bends over only " +
                     format_quantity(l, Dimension::Length) + ", less than " +
                     std::to_string(static_cast<int>(kPlateLengthPerThickness)) +
                     " times its thickness: it is no thin plate on the layers beneath; use "
                     "--model axisymmetric or 3d");
  const double c = 0.5 * e_f;
  PlateContact out;
  out.bending_length_m = l;
  out.foundation_modulus_Pa = e_f;

  if (contact_radius_m > L)
    throw InputError(
        "stress criterion on the analytic path: the needle meets layer '" + top.name +
        "' with a flat end (as wide as a circle of " +
        format_quantity(2.0 * contact_radius_m, Dimension::Length) +
        ", its area's); the plate model holds for a pointed tip only (a rigid edge concentrates "
        "stress in the layer beyond a plate's reach); use --model axisymmetric or 3d");
  // The ball of radius L centred on the underside below the point, cut at the layer's top:
  // slices at height z above the underside, each a disc of radius rho(z) weighted by the bending
  // profile max(0, 1 - 2 z / t) and by the disc's mean hoop moment (under a point the larger one).
  const double z_max = std::min(L, t);
  double weighted = 0.0, volume = 0.0;
  constexpr int kSlices = 24;
  for (int s = 0; s < kSlices; ++s) {
    const double z = (s + 0.5) * z_max / kSlices;
    const double rho = std::sqrt(L * L - z * z);
    const double area = kPi * rho * rho;
    // Above the mid-plane both in-plane stresses are compressive and the maximum principal
    // stress is the plate's out-of-plane one, zero.
    weighted += area * std::max(0.0, 1.0 - 2.0 * z / t) * disc_mean_hoop_moment(rho / l, nu);
    volume += area;
  }
  // w(0) = 1 / (2 pi c l) int dx / (x^3 + 1) = 1 / (3 sqrt(3) c l).
  out.stiffness_N_per_m = 3.0 * std::sqrt(3.0) * c * l;
  out.stress_per_force_Pa_per_N = 6.0 / (t * t) * weighted / volume;
  return out;
}

double plate_deflection_shape(const PlateContact& plate, double radius_m) {
  const double r = radius_m / plate.bending_length_m;
  // int_0^inf J0(x r) / (x^3 + 1) dx to x = X, then the tail int_X^inf J0(x r) / x^3 dx, taken
  // as J0(X r) / (2 X^2): exact where J0 varies slowly over the tail, within about 1e-5 of the
  // whole where it does not (measured at r = l/2).
  constexpr double kX = 60.0;
  const double integral = panels([&](double x) { return j0(x * r) / (x * x * x + 1.0); }, 0.0, kX,
                                 std::min(0.25, kPi / (4.0 * std::max(r, 1e-9)))) +
                          j0(kX * r) / (2.0 * kX * kX);
  return integral * 3.0 * std::sqrt(3.0) / (2.0 * kPi);
}

double point_contact_depth_limit(const PlateContact& plate, const fe::AxisymmetricNeedle& needle) {
  const auto& h = needle.heights_m;
  const auto& r = needle.radii_m;
  const double widest = r.empty() ? 0.0 : *std::max_element(r.begin(), r.end());
  if (!(widest > 0.0)) return std::numeric_limits<double>::infinity();
  // The plate's shape on 129 radii to the needle's widest, linear between them (it is smooth on
  // that scale: l is hundreds of micrometres).
  constexpr int kRadii = 128;
  std::vector<double> shape(kRadii + 1);
  for (int j = 0; j <= kRadii; ++j) shape[j] = plate_deflection_shape(plate, widest * j / kRadii);
  auto shape_at = [&](double radius) {
    const double u = std::clamp(radius / widest * kRadii, 0.0, static_cast<double>(kRadii));
    const int j = std::min(static_cast<int>(u), kRadii - 1);
    return shape[j] + (u - j) * (shape[j + 1] - shape[j]);
  };
  double limit = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < h.size(); ++i)
    for (int k = 1; k <= 4; ++k) {  // four points along each piece, its upper corner included
      const double f = k / 4.0;
      const double radius = r[i - 1] + f * (r[i] - r[i - 1]);
      const double gap = 1.0 - shape_at(radius);
      if (radius > 0.0 && gap > 0.0)
        limit = std::min(limit, (h[i - 1] + f * (h[i] - h[i - 1])) / gap);
    }
  return limit;
}

namespace {

// The top layer alone as a half-space: one layer a metre thick and wide, where Hayes' and the
// block's corrections vanish (a/H below 1e-3).
Tissue top_layer_half_space(const Tissue& tissue) {
  Tissue half;
  half.size = {1.0, 1.0, 1.0};
  TissueLayer layer = tissue.layers.front();
  layer.thickness = 1.0;
  layer.top = 0.0;
  half.layers = {layer};
  return half;
}

double local_force(const Tissue& half, const fe::AxisymmetricNeedle& needle, double indentation) {
  if (!(indentation > 0.0)) return 0.0;
  return analytic_indentation(half, needle, {indentation}).front().force_N;
}

}  // namespace

double plate_depth_at_force(const PlateContact& plate, const Tissue& tissue,
                            const fe::AxisymmetricNeedle& needle, double force_N) {
  if (!(force_N > 0.0)) return 0.0;
  const Tissue half = top_layer_half_space(tissue);
  // The local indentation carrying force_N: bracket, then bisect (the force rises with it).
  double lo = 0.0, hi = 1e-9;
  while (local_force(half, needle, hi) < force_N && hi < 1.0) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (local_force(half, needle, mid) < force_N ? lo : hi) = mid;
  }
  return force_N / plate.stiffness_N_per_m + 0.5 * (lo + hi);
}

double plate_force_at_depth(const PlateContact& plate, const Tissue& tissue,
                            const fe::AxisymmetricNeedle& needle, double depth_m) {
  if (!(depth_m > 0.0)) return 0.0;
  const Tissue half = top_layer_half_space(tissue);
  // The travel splits into the plate's deflection F / k_p and the local indentation delta, with
  // F = Sneddon(delta): bisect on delta in [0, d], where F / k_p + delta - d rises from -d.
  double lo = 0.0, hi = depth_m;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * depth_m; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double excess = local_force(half, needle, mid) / plate.stiffness_N_per_m + mid - depth_m;
    (excess < 0.0 ? lo : hi) = mid;
  }
  return local_force(half, needle, 0.5 * (lo + hi));
}

}  // namespace mneedle
