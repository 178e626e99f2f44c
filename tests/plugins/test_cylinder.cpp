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

// A rim rounded by a quarter torus of radius rho: what it removes from the square rim is the
// spandrel of area rho^2 (1 - pi / 4) whose centroid lies rho (10 - 3 pi) / (12 - 3 pi) in from the
// rim's corner, revolved (Pappus). The section at h < rho is the annulus out to
// R - rho + sqrt(rho^2 - (rho - h)^2), the flat keeps its width R - rho, and the mesh is valid.
TEST(Cylinder, RoundedRimRemovesThePappusVolumeOfItsSpandrel) {
  const double rho = 20e-6, bore = 45e-6;
  const Parameters p{{"bore", 2 * bore}, {"edge_radius", rho}, {"resolution", 256}};
  const TriangleMesh mesh = builtin_registry().generate("cylinder", p);
  const MeshValidation v = validate_mesh(mesh);
  EXPECT_TRUE(v.valid) << (v.errors.empty() ? "" : v.errors.front());
  EXPECT_TRUE(v.outward);
  const double spandrel = rho * rho * (1 - kPi / 4);
  const double centroid = kRadius - rho * (10 - 3 * kPi) / (12 - 3 * kPi);
  const double closed =
      kPi * (kRadius * kRadius - bore * bore) * kLength - 2 * kPi * centroid * spandrel;
  // Simpson on the exact sections: the sqrt's kink at h = rho limits it to about 1e-9.
  EXPECT_LT(relative_error(integrated_section_volume("cylinder", p, kLength, 20000), closed), 1e-7);
  // The polygon of 256 sides inscribed: (1 - sin(2 pi / 256) / (2 pi / 256)) = 1e-4 of the area.
  EXPECT_LT(relative_error(signed_volume(mesh), closed), 3e-4);
  const auto at = [&](double h) {
    return builtin_registry().section_properties("cylinder", p, h).value().area_m2;
  };
  const double outer = kRadius - rho + std::sqrt(rho * rho - (rho - 5e-6) * (rho - 5e-6));
  EXPECT_NEAR(at(5e-6), kPi * (outer * outer - bore * bore), 1e-22);
  EXPECT_NEAR(at(0.0), kPi * ((kRadius - rho) * (kRadius - rho) - bore * bore), 1e-22);
  EXPECT_NEAR(at(rho), kPi * (kRadius * kRadius - bore * bore), 1e-22);
  const BoundingBox box = bounding_box(mesh);
  EXPECT_NEAR(box.min[2], 0, 1e-15);
  EXPECT_NEAR(box.max[0], kRadius, 1e-15);
}

// The default is the sharp rim, the same mesh as before the key existed; a rounding wider than
// the wall or negative is an InputError.
TEST(Cylinder, ZeroEdgeRadiusIsTheSharpRimAndTooWideARoundingIsAnInputError) {
  const TriangleMesh sharp = builtin_registry().generate("cylinder", {});
  const TriangleMesh zero = builtin_registry().generate("cylinder", {{"edge_radius", 0.0}});
  EXPECT_EQ(signed_volume(sharp), signed_volume(zero));
  EXPECT_THROW(builtin_registry().generate("cylinder", {{"bore", 90e-6}, {"edge_radius", 80e-6}}),
               InputError);
  EXPECT_THROW(builtin_registry().generate("cylinder", {{"edge_radius", -1e-6}}), InputError);
  // As wide as the solid needle's radius: a hemispherical end, still valid.
  EXPECT_TRUE(
      validate_mesh(builtin_registry().generate("cylinder", {{"edge_radius", kRadius}})).valid);
}

TEST(Cylinder, BoreAsWideAsTheNeedleIsAnInputError) {
  EXPECT_THROW(builtin_registry().generate("cylinder", {{"bore", 230e-6}}), InputError);
}

}  // namespace
}  // namespace mneedle::test
