// The top layer as a thin plate on the layer beneath: its exact similarity in the foundation's
// modulus, the averaged stress against the averaging length, and refused tissues and needles. Its
// agreement with the FE models in skin is checked end to end in test_cmd_simulate
// (docs/validation.md, "The stress criterion on the analytic path").

#include "mneedle/insertion/plate_contact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

// Paper A's stratum corneum (1 GPa, 20 um, nu 0.4, 21.6 MPa over 10 um) on one soft layer.
Tissue two_layers(double foundation_E, double length = 10e-6) {
  Tissue t;
  t.size = {3e-3, 3e-3, 1.15e-3};
  TissueLayer top;
  top.name = "stratum_corneum";
  top.thickness = 20e-6;
  top.material.youngs_modulus = 1e9;
  top.material.poisson_ratio = 0.4;
  top.strength = LayerStrength{21.6e6, length};
  TissueLayer below;
  below.name = "dermis";
  below.thickness = 1.13e-3;
  below.top = 20e-6;
  below.material.youngs_modulus = foundation_E;
  below.material.poisson_ratio = 0.4;
  t.layers = {top, below};
  return t;
}

std::string message_of(const Tissue& t, double radius) {
  try {
    plate_contact(t, radius);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// On one foundation layer (a half-space of E*_f for the plate), l = (2 D / E*_f)^(1/3) and the
// point stiffness 3 sqrt(3) (E*_f / 2) l, so it scales as E*_f^(2/3) exactly.
TEST(PlateContact, APointsStiffnessScalesAsTheFoundationModulusToTheTwoThirds) {
  const PlateContact soft = plate_contact(two_layers(0.1e6), 0.0);
  const PlateContact stiff = plate_contact(two_layers(0.8e6), 0.0);
  EXPECT_NEAR(stiff.stiffness_N_per_m / soft.stiffness_N_per_m, 4.0, 1e-9);
  EXPECT_NEAR(soft.bending_length_m / stiff.bending_length_m, 2.0, 1e-9);
  const double D = 1e9 * 8e-15 / (12.0 * (1.0 - 0.16));
  EXPECT_NEAR(soft.bending_length_m, std::cbrt(2.0 * D / (0.1e6 / 0.84)), 1e-15);
}

// Averaged through the layer's bending gradient, the stress rises as the averaging length L
// shrinks: the area-weighted mean of 1 - 2 z / t over the ball's half in the layer is
// 1 - 3 L / (4 t), 0.625 at L = 10 um and 0.925 at 2 um (x 1.48); under a point the plate's
// moment also grows logarithmically towards the load, so the stress rises more than that.
TEST(PlateContact, APointsStressGrowsFasterThanTheBendingGradientAsTheAveragingLengthShrinks) {
  auto stress = [](double length) {
    return plate_contact(two_layers(0.134e6, length), 0.0).stress_per_force_Pa_per_N;
  };
  EXPECT_GT(stress(2e-6) / stress(10e-6), 0.925 / 0.625 + 0.3);
}

// w(r) / w(0) is 1 under the point (the integral of 1 / (x^3 + 1) is 2 pi / (3 sqrt 3)) and falls
// with the distance from it.
TEST(PlateContact, TheDeflectionIsLargestUnderThePointAndFallsAwayFromIt) {
  const PlateContact plate = plate_contact(two_layers(0.134e6), 0.0);
  EXPECT_NEAR(plate_deflection_shape(plate, 0.0), 1.0, 1e-6);
  double previous = 1.0;
  for (double r : {20e-6, 50e-6, 100e-6, 200e-6, 400e-6}) {
    const double shape = plate_deflection_shape(plate, r);
    EXPECT_LT(shape, previous) << r;
    previous = shape;
  }
}

// A cone touches the bent plate with its flank only when it is blunt: at 15 deg (the cone
// plugin's default) the flank stays clear to millimetres, at 88 deg it meets the plate within
// tens of micrometres, before the layer breaks under the tip (58 um here).
TEST(PlateContact, OnlyABluntConesFlankMeetsTheBentPlateBeforeTheLayerBreaks) {
  const PlateContact plate = plate_contact(two_layers(0.134e6), 0.0);
  auto cone = [](double half_angle_deg) {
    fe::AxisymmetricNeedle n;
    const double radius = 115e-6;
    const double height = radius / std::tan(half_angle_deg * 3.14159265358979 / 180.0);
    n.heights_m = {0.0, height, height + 1e-3};
    n.radii_m = {0.0, radius, radius};
    return n;
  };
  EXPECT_GT(point_contact_depth_limit(plate, cone(15.0)), 1e-3);
  EXPECT_LT(point_contact_depth_limit(plate, cone(88.0)), 50e-6);
}

// The tip's local indentation in series with the plate: for a sharp cone Sneddon's closed form
// F = (2/pi) E* tan(a) delta^2 on the top layer, so the travel at force F is F / k_p plus
// sqrt(pi F / (2 E* tan a)); and the travel and the force are each other's inverse.
TEST(PlateContact, ASharpConesTravelIsThePlatesDeflectionPlusItsSneddonIndentation) {
  const Tissue tissue = two_layers(0.134e6);
  const PlateContact plate = plate_contact(tissue, 0.0);
  fe::AxisymmetricNeedle cone;
  const double half_angle = 15.0 * 3.14159265358979 / 180.0, radius = 115e-6;
  cone.heights_m = {0.0, radius / std::tan(half_angle), radius / std::tan(half_angle) + 1e-3};
  cone.radii_m = {0.0, radius, radius};
  const double force = 5e-3;
  const double e_star = 1e9 / (1.0 - 0.4 * 0.4);
  const double local = std::sqrt(3.14159265358979 * force / (2.0 * e_star * std::tan(half_angle)));
  const double travel = plate_depth_at_force(plate, tissue, cone, force);
  EXPECT_NEAR(travel, force / plate.stiffness_N_per_m + local, 1e-6 * travel);
  EXPECT_NEAR(plate_force_at_depth(plate, tissue, cone, travel), force, 1e-8 * force);
}

TEST(PlateContact, ATissueThatIsNoPlateOnAFoundationIsRefusedByName) {
  Tissue one = two_layers(0.134e6);
  one.layers.pop_back();
  EXPECT_NE(message_of(one, 0.0).find("top layer on others"), std::string::npos);
  Tissue weak = two_layers(0.134e6);
  weak.layers.front().strength.reset();
  EXPECT_NE(message_of(weak, 0.0).find("'stratum_corneum' has no strength"), std::string::npos);
  // 1 MPa on 0.134 MPa bends over 21.5 um, about its own thickness: no thin plate.
  Tissue soft = two_layers(0.134e6);
  soft.layers.front().material.youngs_modulus = 1e6;
  const std::string m = message_of(soft, 0.0);
  EXPECT_NE(m.find("'stratum_corneum'"), std::string::npos) << m;
  EXPECT_NE(m.find("--model axisymmetric or 3d"), std::string::npos) << m;
  // A flat end wider than 2 L: paper A's cylinder (230 um).
  const std::string flat = message_of(two_layers(0.134e6), 115e-6);
  EXPECT_NE(flat.find("flat end (as wide as a circle of 230 um"), std::string::npos) << flat;
}

}  // namespace
}  // namespace mneedle
