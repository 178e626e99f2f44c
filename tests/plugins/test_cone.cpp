#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mneedle/base/error.h"
#include "shape_test_support.h"

namespace mneedle::test {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadius = 115e-6;
constexpr double kLength = 1000e-6;
const double kHalfAngle = 15 * kPi / 180;
const double kTan = std::tan(kHalfAngle);

// Sharp cone: a shaft plus a cone of height R/tanα (one third of its cylinder).
double sharp_solid_volume() {
  const double taper = kRadius / kTan;
  return kPi * kRadius * kRadius * (kLength - 2 * taper / 3);
}

// Spherical cap (height ρ(1 - sin α)) + frustum from the tangent circle + shaft.
double rounded_solid_volume(double rho) {
  const double cap_h = rho * (1 - std::sin(kHalfAngle));
  const double rt = rho * std::cos(kHalfAngle);
  const double shaft_z = cap_h + (kRadius - rt) / kTan;
  const double cap = kPi * cap_h * cap_h * (3 * rho - cap_h) / 3;
  const double frustum = kPi * (std::pow(kRadius, 3) - std::pow(rt, 3)) / (3 * kTan);
  return cap + frustum + kPi * kRadius * kRadius * (kLength - shaft_z);
}

// A bore turns the point into a knife edge at radius r, which sits at z = 0.
double hollow_sharp_volume(double r) {
  const double taper = (kRadius - r) / kTan;
  const double frustum = kPi * (std::pow(kRadius, 3) - std::pow(r, 3)) / (3 * kTan);
  return frustum - kPi * r * r * taper + kPi * (kRadius * kRadius - r * r) * (kLength - taper);
}

TEST(Cone, DefaultMeshIsValidClosedAndOutwardWithApexAtOrigin) {
  const TriangleMesh mesh = builtin_registry().generate("cone", {});
  const MeshValidation v = validate_mesh(mesh);
  EXPECT_TRUE(v.valid) << (v.errors.empty() ? "" : v.errors.front());
  EXPECT_TRUE(v.outward);
  int apex = 0;
  for (const auto& p : mesh.vertices) {
    if (p[2] < 1e-12) {
      ++apex;
      EXPECT_NEAR(std::hypot(p[0], p[1]), 0, 1e-15);
    }
  }
  EXPECT_EQ(apex, 1);
  EXPECT_NEAR(bounding_box(mesh).max[2], kLength, 1e-15);
}

TEST(Cone, SharpSolidVolumeWithinHalfPercent) {
  const double volume = signed_volume(builtin_registry().generate("cone", {}));
  EXPECT_LT(relative_error(volume, sharp_solid_volume()), 0.005);
}

TEST(Cone, RoundedSolidVolumeWithinHalfPercent) {
  const TriangleMesh mesh = builtin_registry().generate("cone", {{"tip_radius", 20e-6}});
  EXPECT_TRUE(validate_mesh(mesh).valid);
  EXPECT_NEAR(bounding_box(mesh).min[2], 0, 1e-15);
  EXPECT_LT(relative_error(signed_volume(mesh), rounded_solid_volume(20e-6)), 0.005);
}

TEST(Cone, HollowVolumeWithinHalfPercentAndEdgeAtZero) {
  const TriangleMesh mesh = builtin_registry().generate("cone", {{"bore", 90e-6}});
  EXPECT_TRUE(validate_mesh(mesh).valid);
  EXPECT_NEAR(bounding_box(mesh).min[2], 0, 1e-15);
  EXPECT_LT(relative_error(signed_volume(mesh), hollow_sharp_volume(45e-6)), 0.005);
}

TEST(Cone, HollowRoundedMeshIsValid) {
  const Parameters p{{"bore", 20e-6}, {"tip_radius", 30e-6}};
  const TriangleMesh mesh = builtin_registry().generate("cone", p);
  EXPECT_TRUE(validate_mesh(mesh).valid);
  EXPECT_LT(relative_error(signed_volume(mesh), integrated_section_volume("cone", p, kLength)),
            0.005);
}

TEST(Cone, VolumeConvergesAsResolutionRises) {
  double previous = 1;
  for (const double n : {16.0, 64.0, 256.0}) {
    const double error =
        relative_error(signed_volume(builtin_registry().generate("cone", {{"resolution", n}})),
                       sharp_solid_volume());
    EXPECT_LT(error, previous / 10) << "resolution " << n;
    previous = error;
  }
}

TEST(Cone, SectionAreaIntegratesToTheAnalyticVolume) {
  EXPECT_LT(relative_error(integrated_section_volume("cone", {}, kLength), sharp_solid_volume()),
            1e-6);
  EXPECT_LT(relative_error(integrated_section_volume("cone", {{"tip_radius", 20e-6}}, kLength),
                           rounded_solid_volume(20e-6)),
            1e-6);
  EXPECT_LT(relative_error(integrated_section_volume("cone", {{"bore", 90e-6}}, kLength),
                           hollow_sharp_volume(45e-6)),
            1e-6);
}

TEST(Cone, SectionPropertiesOnTheTaperAreThoseOfADisc) {
  const double h = 200e-6;
  const double r = h * kTan;
  const auto s = builtin_registry().section_properties("cone", {}, h).value();
  EXPECT_LT(relative_error(s.area_m2, kPi * r * r), 1e-12);
  EXPECT_LT(relative_error(s.i_min_m4, kPi / 4 * std::pow(r, 4)), 1e-12);
}

TEST(Cone, CapWiderThanTheShaftIsAnInputError) {
  EXPECT_THROW(builtin_registry().generate("cone", {{"tip_radius", 200e-6}}), InputError);
}

}  // namespace
}  // namespace mneedle::test
