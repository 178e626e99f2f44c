// Geometry at the extremes: depths of 1 nm and 2 mm, cone half-angles 1..89 deg, blunt flats
// from 0 to the full diameter, needles 10 um and 10 mm long, tissue blocks 10x and 0.1x the
// needle. Each case gives a finite, right answer (against Sneddon where a closed form exists) or
// stops with an InputError naming the problem.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <string>

#include "../core/needle_shapes.h"
#include "mneedle/base/error.h"
#include "mneedle/fe/axisymmetric.h"
#include "mneedle/insertion/analytic_indentation.h"

namespace mneedle {
namespace {

using std::numbers::pi;
constexpr double kDeg = pi / 180.0;

Tissue homogeneous(double E, double nu, double width, double depth) {
  Tissue t;
  t.size = {width, width, depth};
  TissueLayer l;
  l.name = "block";
  l.thickness = depth;
  l.material.youngs_modulus = E;
  l.material.poisson_ratio = nu;
  t.layers = {l};
  return t;
}

double sneddon_cone(double E, double nu, double alpha, double d) {
  return 2.0 / pi * E / (1 - nu * nu) * std::tan(alpha) * d * d;
}

fe::InsertionResult axisymmetric(const fe::AxisymmetricNeedle& needle, double depth,
                                 double block_depth, double radius,
                                 fe::ContactMode contact = fe::ContactMode::Frictionless,
                                 fe::Fidelity fidelity = fe::Fidelity::Fast, double nu = 0.3) {
  fe::AxisymmetricProblem p;
  p.layers = {{block_depth, {MaterialModel::Linear, 1e5, nu, 0.0, 0.0}}};
  p.radius_m = radius;
  p.needle = needle;
  p.depth_m = depth;
  p.fidelity = fidelity;
  p.contact = contact;
  p.output_steps = 2;
  return fe::simulate_axisymmetric(p);
}

TEST(ExtremeGeometry, AnalyticConeIsSneddonFromOneToEightyNineDegrees) {
  const Tissue block = homogeneous(1e5, 0.45, 100.0, 100.0);
  for (double deg : {1.0, 5.0, 30.0, 60.0, 85.0, 89.0}) {
    const auto step =
        analytic_indentation(block, fe::AxisymmetricNeedle::cone(deg * kDeg, 10.0), {1e-4})[0];
    EXPECT_NEAR(step.force_N / sneddon_cone(1e5, 0.45, deg * kDeg, 1e-4), 1.0, 1e-3) << deg;
  }
}

// The sticking cone is stiffer than frictionless Sneddon: no slip, and Sneddon neglects the
// radial surface displacement (Hay, Bolshakov & Pharr 1998), more so for sharp cones (measured
// 2.7 at 1 deg, 1.56 at 10 deg, 1.21 at 30 deg, 1.13 at 45 deg; converged to 0.5 % over three
// meshes at 10-45 deg).
TEST(ExtremeGeometry, StickingFeConeFromOneToEightyNineDegreesIsFiniteAndBounded) {
  for (double deg : {1.0, 10.0, 45.0, 80.0, 89.0}) {
    const double alpha = deg * kDeg, d = 20e-6;
    const double a = 2.0 / pi * d * std::tan(alpha);
    const double size = std::max(40 * a, 200e-6);
    const auto needle = fe::AxisymmetricNeedle::cone(alpha, std::max(3 * a, 1e-6));
    const auto r = axisymmetric(needle, d, size, size, fe::ContactMode::Sticking);
    const double ratio = r.steps.back().force_N / sneddon_cone(1e5, 0.3, alpha, d);
    std::cout << "sticking cone " << deg << " deg: F_FE / F_Sneddon " << ratio << "\n";
    EXPECT_TRUE(std::isfinite(ratio));
    EXPECT_GT(ratio, 0.98) << deg;
    EXPECT_LT(ratio, 3.5) << deg;
  }
}

// Cone on a bonded layer of depth h (Garcia 2018): Sneddon times this, y = d tan(alpha) / h.
double garcia_layer(double y) {
  return 1 + 0.721 * y + 0.650 * y * y + 0.491 * y * y * y + 0.225 * y * y * y * y;
}

// The linear model's frictionless contact is Sneddon's own small-strain condition (vertical gap
// and force, radial sliding free), so it must reproduce Sneddon at any angle: measured FE /
// (Sneddon x layer factor) 0.99-1.01 at 10-80 deg, nu 0.3 and 0.45, on fast, standard and fine
// meshes, hence 3 %; refinement changes it by < 1 % (it used to soften the 10 deg cone to 0.81x
// per level, 0.22 -> 0.13 of Sneddon). This says nothing about the real force under a sharp cone,
// which Sneddon's small-slope theory underestimates (Hay, Bolshakov & Pharr: x1.06 at 45 deg,
// 1.11 at 30 deg, 1.41 at 10 deg for nu = 0.45, x3.6 at 10 deg for nu = 0.3); no linear model
// captures that, and tissue-like nu = 0.45 keeps it smallest.
TEST(ExtremeGeometry, FrictionlessFeConeMatchesSneddon) {
  const double nu = 0.45;
  for (double deg : {10.0, 30.0, 45.0}) {
    const double alpha = deg * kDeg, d = 20e-6;
    const double a = 2.0 / pi * d * std::tan(alpha);
    const double size = std::max(40 * a, 200e-6);
    const auto needle = fe::AxisymmetricNeedle::cone(alpha, std::max(3 * a, 1e-6));
    const double reference =
        sneddon_cone(1e5, nu, alpha, d) * garcia_layer(d * std::tan(alpha) / size);
    const auto fast =
        axisymmetric(needle, d, size, size, fe::ContactMode::Frictionless, fe::Fidelity::Fast, nu);
    const auto standard = axisymmetric(needle, d, size, size, fe::ContactMode::Frictionless,
                                       fe::Fidelity::Standard, nu);
    const double f_fast = fast.steps.back().force_N, f_standard = standard.steps.back().force_N;
    std::cout << "frictionless cone " << deg << " deg: F / (Sneddon x layer) fast "
              << f_fast / reference << ", standard " << f_standard / reference << "; area / pi a^2 "
              << standard.steps.back().contact_area_m2 / (pi * a * a) << "\n";
    EXPECT_NEAR(f_fast / reference, 1.0, 0.03) << deg;
    EXPECT_NEAR(f_standard / f_fast, 1.0, 0.02) << deg;
    // Sneddon's contact radius a = (2/pi) d tan(alpha), known to half an element (measured
    // 0.97-1.16 of pi a^2; it was 1.6-2.3 with the sloped constraint).
    EXPECT_NEAR(standard.steps.back().contact_area_m2 / (pi * a * a), 1.0, 0.25) << deg;
  }
}

TEST(ExtremeGeometry, BluntFlatFromZeroToFullDiameterGrowsTheForceMonotonically) {
  const double R = 115e-6, alpha = 30 * kDeg, d = 10e-6;
  double previous = 0.0;
  for (double fraction : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double flat = fraction * R;
    fe::AxisymmetricNeedle n;
    if (fraction < 1.0) {
      n.heights_m = {0.0, (R - flat) / std::tan(alpha), 2e-3};
      n.radii_m = {flat, R, R};
    } else {
      n = fe::AxisymmetricNeedle::flat_punch(R);
    }
    const double sticking =
        axisymmetric(n, d, 3e-3, 3e-3, fe::ContactMode::Sticking).steps.back().force_N;
    EXPECT_TRUE(std::isfinite(sticking));
    EXPECT_GT(sticking, previous) << fraction;
    previous = sticking;
    if (fraction == 0.0) continue;  // sharp: see FrictionlessFeConeMatchesSneddon
    const double frictionless = axisymmetric(n, d, 3e-3, 3e-3).steps.back().force_N;
    const double closed =
        analytic_indentation(homogeneous(1e5, 0.3, 6e-3, 3e-3), n, {d})[0].force_N;
    std::cout << "flat " << fraction << " of R: FE " << frictionless << " N, analytic " << closed
              << " N\n";
    EXPECT_NEAR(frictionless / closed, 1.0, 0.05) << fraction;
  }
}

TEST(ExtremeGeometry, OneNanometreDepthIsLinearInDepth) {
  const auto punch = fe::AxisymmetricNeedle::flat_punch(100e-6);
  const double f_nm = axisymmetric(punch, 1e-9, 2e-3, 2e-3).steps.back().force_N;
  const double f_um = axisymmetric(punch, 1e-6, 2e-3, 2e-3).steps.back().force_N;
  EXPECT_TRUE(std::isfinite(f_nm));
  EXPECT_NEAR(f_nm / f_um, 1e-3, 1e-6);
  const Tissue block = homogeneous(1e5, 0.3, 4e-3, 2e-3);
  const auto nm =
      analytic_indentation(block, fe::AxisymmetricNeedle::cone(15 * kDeg, 1e-4), {1e-9});
  EXPECT_NEAR(nm[0].force_N / sneddon_cone(1e5, 0.3, 15 * kDeg, 1e-9), 1.0, 1e-6);
}

TEST(ExtremeGeometry, TwoMillimetreDepthBeyondTheBlockStopsWithAnInputError) {
  const auto cone = fe::AxisymmetricNeedle::cone(15 * kDeg, 115e-6);
  // Paper A's 1.15 mm block: a 2 mm insertion would pass through its rigid base.
  EXPECT_THROW(analytic_indentation(homogeneous(1e5, 0.3, 3e-3, 1.15e-3), cone, {2e-3}),
               InputError);
}

// 2 mm into a 1.15 mm block: the tip would pass through the rigid base.
TEST(ExtremeGeometry, FeDepthBeyondTheBlockStopsWithAnInputError) {
  const auto cone = fe::AxisymmetricNeedle::cone(15 * kDeg, 115e-6);
  EXPECT_THROW(axisymmetric(cone, 2e-3, 1.15e-3, 1.7e-3), InputError);
}

TEST(ExtremeGeometry, TwoMillimetreDepthInADeepBlockIsFinite) {
  const auto cone = fe::AxisymmetricNeedle::cone(15 * kDeg, 115e-6);
  const auto r = axisymmetric(cone, 2e-3, 10e-3, 10e-3, fe::ContactMode::Sticking);
  ASSERT_EQ(r.steps.size(), 2u);
  EXPECT_TRUE(std::isfinite(r.steps.back().force_N));
  EXPECT_GT(r.steps.back().force_N, r.steps.front().force_N);
  // A cone on a shaft is softer than the flat punch of the shaft's radius (bonded: x1.03).
  const auto punch = analytic_indentation(homogeneous(1e5, 0.3, 20e-3, 10e-3),
                                          fe::AxisymmetricNeedle::flat_punch(115e-6), {2e-3});
  std::cout << "2 mm: FE " << r.steps.back().force_N << " N, flat-punch bound " << punch[0].force_N
            << " N\n";
  EXPECT_LT(r.steps.back().force_N, 1.03 * punch[0].force_N);
}

TEST(ExtremeGeometry, NeedlesTenMicronsAndTenMillimetresLongGiveFiniteProfiles) {
  for (double length : {10e-6, 10e-3}) {
    test::ShapeOptions o;
    o.length = length;
    o.radius = 115e-6;
    const TriangleMesh mesh = test::cone(o, 15 * kDeg);
    const auto needle = equivalent_axisymmetric_needle(mesh, length, 100);
    for (double r : needle.radii_m) EXPECT_TRUE(std::isfinite(r));
    // A 10 um needle is all tip: its largest equivalent radius is the cone's at 10 um.
    const double tip_radius = std::min(length * std::tan(15 * kDeg), o.radius);
    EXPECT_NEAR(needle.max_radius() / tip_radius, 1.0, 0.01) << length;
    const double depth = std::min(0.5 * length, 200e-6);
    const auto step = analytic_indentation(homogeneous(1e5, 0.3, 0.1, 0.05), needle, {depth})[0];
    EXPECT_TRUE(std::isfinite(step.force_N) && step.force_N > 0.0) << length;
  }
}

TEST(ExtremeGeometry, BlockTenTimesTheNeedleIsFineAndATenthIsRefused) {
  const double R = 115e-6;
  const auto punch = fe::AxisymmetricNeedle::flat_punch(R);
  // 10x: 2.3 mm wide, 2.3 mm deep.
  const double f10 = axisymmetric(punch, 1e-6, 20 * R, 20 * R / std::sqrt(pi)).steps.back().force_N;
  const double closed10 =
      analytic_indentation(homogeneous(1e5, 0.3, 20 * R, 20 * R), punch, {1e-6})[0].force_N;
  std::cout << "block 10x: FE " << f10 << " analytic " << closed10 << "\n";
  EXPECT_NEAR(f10 / closed10, 1.0, 0.06);
  // 0.1x: the block is narrower than the needle.
  EXPECT_THROW(analytic_indentation(homogeneous(1e5, 0.3, 0.2 * R, 0.2 * R), punch, {1e-6}),
               InputError);
}

// A tissue cylinder of radius 0.1 R under a punch of radius R: its clamped side is under the
// needle.
TEST(ExtremeGeometry, FeBlockNarrowerThanTheNeedleStopsWithAnInputError) {
  const double R = 115e-6;
  EXPECT_THROW(axisymmetric(fe::AxisymmetricNeedle::flat_punch(R), 1e-6, 0.2 * R, 0.1 * R),
               InputError);
}

}  // namespace
}  // namespace mneedle
