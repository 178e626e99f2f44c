#include "mneedle/strength/needle_strength.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mneedle/base/error.h"

namespace {

constexpr double kPi = std::numbers::pi;

mneedle::NeedleMaterial material(double e, double strength) {
  return {"test", e, 0.3, strength, mneedle::FailureMode::Yield, "test"};
}

TEST(NeedleStrength, SlenderSolidRodBucklesAtEulersLoad) {
  const double d = 100e-6, length = 5e-3, e = 200e9;
  mneedle::StrengthOptions o;
  o.length_m = length;
  o.end = mneedle::EndCondition::FixedFree;
  const auto r =
      mneedle::needle_strength(mneedle::circular_rod_profile(d, 0.0), material(e, 1e9), o);
  const double i = kPi * std::pow(d, 4) / 64.0;
  EXPECT_NEAR(r.elastic_buckling_n / (kPi * kPi * e * i / std::pow(2.0 * length, 2)), 1.0, 1e-6);
  EXPECT_FALSE(r.johnson);
  EXPECT_EQ(r.governing, "buckling");
  EXPECT_NEAR(r.i_min_m4, i, 1e-12 * i);
}

TEST(NeedleStrength, StubbyHollowNeedleIsLimitedByItsCrushingLoad) {
  const double d = 230e-6, bore = 90e-6, length = 300e-6, sigma = 50e6;
  mneedle::StrengthOptions o;
  o.length_m = length;
  const auto r =
      mneedle::needle_strength(mneedle::circular_rod_profile(d, bore), material(169e9, sigma), o);
  const double area = kPi / 4.0 * (d * d - bore * bore);
  EXPECT_NEAR(r.strength_n, sigma * area, 1e-9 * sigma * area);
  // Johnson's parabola tends to the crushing load σA as the column gets short.
  EXPECT_TRUE(r.johnson);
  EXPECT_NEAR(r.capacity_n / (sigma * area), 1.0, 0.01);
  EXPECT_DOUBLE_EQ(r.capacity_n, std::min(r.strength_n, r.buckling_n));
}

TEST(NeedleStrength, WeakestLoadedSectionOfATaperDecidesStrength) {
  // A cone: area grows with height; at depth z the weakest loaded section is the one at z.
  const double length = 1e-3, base_r = 100e-6, z = 200e-6, sigma = 50e6;
  mneedle::SectionProfile cone = [&](double h) {
    const double r = base_r * h / length;
    return mneedle::SectionProperties{kPi * r * r, kPi * std::pow(r, 4) / 4.0, r};
  };
  mneedle::StrengthOptions o;
  o.length_m = length;
  o.load_height_m = z;
  const auto r = mneedle::needle_strength(cone, material(3.5e9, sigma), o);
  const double rz = base_r * z / length;
  EXPECT_NEAR(r.strength_n, sigma * kPi * rz * rz, 1e-9);
  EXPECT_NEAR(r.critical_height_m, z, 1e-12);
}

TEST(NeedleStrength, LateralForceLowersTheStrengthCapacity) {
  mneedle::StrengthOptions o;
  o.length_m = 1e-3;
  const auto profile = mneedle::circular_rod_profile(230e-6, 0.0);
  const auto axial = mneedle::needle_strength(profile, material(169e9, 1e9), o);
  o.lateral_ratio = 0.2;
  const auto bent = mneedle::needle_strength(profile, material(169e9, 1e9), o);
  EXPECT_LT(bent.strength_n, axial.strength_n);
  EXPECT_NEAR(bent.critical_height_m, 1e-3, 1e-12);  // largest lever arm at the base
}

TEST(NeedleStrength, RejectsDepthBeyondTheNeedleAndEmptySections) {
  mneedle::StrengthOptions o;
  o.length_m = 1e-3;
  o.load_height_m = 1e-3;
  const auto profile = mneedle::circular_rod_profile(230e-6, 0.0);
  EXPECT_THROW(mneedle::needle_strength(profile, material(1e9, 1e6), o), mneedle::InputError);
  o.load_height_m = 0.0;
  mneedle::SectionProfile sharp = [](double h) {
    return mneedle::SectionProperties{h * h, h * h * h * h, h};
  };
  EXPECT_THROW(mneedle::needle_strength(sharp, material(1e9, 1e6), o), mneedle::InputError);
  EXPECT_THROW(mneedle::circular_rod_profile(100e-6, 100e-6), mneedle::InputError);
}

TEST(NeedleStrength, MarginIsCapacityOverPeakForce) {
  EXPECT_DOUBLE_EQ(mneedle::strength_margin(2.0, 0.5), 4.0);
  EXPECT_TRUE(std::isinf(mneedle::strength_margin(2.0, 0.0)));
}

}  // namespace

namespace {

TEST(NeedleStrength, BucklingColumnStartsAtTheTissueSurface) {
  // A sharp cone tip below a cylindrical shaft: pinned at the surface, the column is the shaft
  // alone, so Euler's load for the shaft length above the surface applies.
  const double r = 115e-6, length = 1e-3, tip = 300e-6, e = 169e9;
  mneedle::SectionProfile profile = [&](double h) {
    const double rr = h < tip ? r * h / tip : r;
    return mneedle::SectionProperties{kPi * rr * rr, kPi * std::pow(rr, 4) / 4.0, rr};
  };
  mneedle::StrengthOptions o;
  o.length_m = length;
  o.load_height_m = tip;
  const auto report = mneedle::needle_strength(profile, material(e, 1e12), o);
  const double euler =
      kPi * kPi * e * kPi * std::pow(r, 4) / 4.0 / std::pow(0.7 * (length - tip), 2);
  EXPECT_NEAR(report.elastic_buckling_n / euler, 1.0, 3e-3);
}

}  // namespace
