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

TEST(Cylinder, DefaultMeshIsValidClosedAndOutward) {
  const MeshValidation v = validate_mesh(builtin_registry().generate("cylinder", {}));
  EXPECT_TRUE(v.valid) << (v.errors.empty() ? "" : v.errors.front());
  EXPECT_TRUE(v.outward);
}

TEST(Cylinder, FlatEndAtZeroAndBodyAlongZ) {
  const BoundingBox box = bounding_box(builtin_registry().generate("cylinder", {}));
  EXPECT_NEAR(box.min[2], 0, 1e-15);
  EXPECT_NEAR(box.max[2], kLength, 1e-15);
  EXPECT_NEAR(box.max[0], kRadius, 1e-15);
  EXPECT_NEAR(box.min[0], -kRadius, 1e-15);
}

TEST(Cylinder, SolidVolumeWithinHalfPercentOfPiR2L) {
  const double volume = signed_volume(builtin_registry().generate("cylinder", {}));
  EXPECT_LT(relative_error(volume, kPi * kRadius * kRadius * kLength), 0.005);
}

TEST(Cylinder, HollowVolumeWithinHalfPercentOfTheAnnulus) {
  const TriangleMesh mesh = builtin_registry().generate("cylinder", {{"bore", 90e-6}});
  EXPECT_TRUE(validate_mesh(mesh).valid);
  const double annulus = kPi * (kRadius * kRadius - 45e-6 * 45e-6) * kLength;
  EXPECT_LT(relative_error(signed_volume(mesh), annulus), 0.005);
}

TEST(Cylinder, VolumeConvergesAsResolutionRises) {
  double previous = 1;
  for (const double n : {16.0, 64.0, 256.0}) {
    const double error =
        relative_error(signed_volume(builtin_registry().generate("cylinder", {{"resolution", n}})),
                       kPi * kRadius * kRadius * kLength);
    EXPECT_LT(error, previous / 10) << "resolution " << n;
    previous = error;
  }
}

TEST(Cylinder, SectionPropertiesAreTheAnnulus) {
  const auto s =
      builtin_registry().section_properties("cylinder", {{"bore", 90e-6}}, 10e-6).value();
  EXPECT_NEAR(s.area_m2, kPi * (kRadius * kRadius - 45e-6 * 45e-6), 1e-20);
  EXPECT_LT(relative_error(s.i_min_m4, kPi / 4 * (std::pow(kRadius, 4) - std::pow(45e-6, 4))),
            1e-12);
  EXPECT_EQ(builtin_registry().section_area("cylinder", {}, 2 * kLength).value(), 0);
}

TEST(Cylinder, BoreAsWideAsTheNeedleIsAnInputError) {
  EXPECT_THROW(builtin_registry().generate("cylinder", {{"bore", 230e-6}}), InputError);
}

}  // namespace
}  // namespace mneedle::test
