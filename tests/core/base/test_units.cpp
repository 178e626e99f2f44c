#include "mneedle/base/units.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"

namespace {

using mneedle::Dimension;
using mneedle::InputError;
using mneedle::parse_quantity;

// The message of the InputError that `f` throws; fails the test when nothing is thrown.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

TEST(Units, MicrometresConvertToMetres) {
  EXPECT_DOUBLE_EQ(parse_quantity("230 um", Dimension::Length), 230e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("230um", Dimension::Length), 230e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("230 \xC2\xB5m", Dimension::Length), 230e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("230 \xCE\xBCm", Dimension::Length), 230e-6);
}

TEST(Units, SubmultiplesGiveTheDoubleNearestTheDecimalValue) {
  // Exactly equal, not DOUBLE_EQ: a plugin's minimum of 10e-6 m must accept "10 um"
  // (10 × 1e-6 is 9.999…e-6, one ulp below).
  EXPECT_EQ(parse_quantity("10 um", Dimension::Length), 10e-6);
  EXPECT_EQ(parse_quantity("230 um", Dimension::Length), 230e-6);
  EXPECT_EQ(parse_quantity("0.5 mm", Dimension::Length), 0.5e-3);
  EXPECT_EQ(parse_quantity("3 nm", Dimension::Length), 3e-9);
  EXPECT_EQ(parse_quantity("7 mN", Dimension::Force), 7e-3);
  EXPECT_EQ(parse_quantity("0.7 kPa", Dimension::Pressure), 700.0);
}

TEST(Units, EveryLengthUnitScales) {
  EXPECT_DOUBLE_EQ(parse_quantity("5 nm", Dimension::Length), 5e-9);
  EXPECT_DOUBLE_EQ(parse_quantity("1.5 mm", Dimension::Length), 1.5e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("2 cm", Dimension::Length), 2e-2);
  EXPECT_DOUBLE_EQ(parse_quantity("3 m", Dimension::Length), 3.0);
}

TEST(Units, QuantityCarriesItsDimension) {
  const auto q = parse_quantity("0.2 MPa");
  EXPECT_EQ(q.dimension, Dimension::Pressure);
  EXPECT_DOUBLE_EQ(q.value_si, 2e5);
}

TEST(Units, PressureUnitsIncludingPsi) {
  EXPECT_DOUBLE_EQ(parse_quantity("80 kPa", Dimension::Pressure), 8e4);
  EXPECT_DOUBLE_EQ(parse_quantity("1 GPa", Dimension::Pressure), 1e9);
  EXPECT_DOUBLE_EQ(parse_quantity("7 Pa", Dimension::Pressure), 7.0);
  // Paper A quotes its silicone as 29 psi = 0.2 MPa.
  EXPECT_NEAR(parse_quantity("29 psi", Dimension::Pressure), 0.2e6, 0.001e6);
}

TEST(Units, DegreesConvertToRadians) {
  EXPECT_DOUBLE_EQ(parse_quantity("90 deg", Dimension::Angle), std::numbers::pi / 2.0);
  EXPECT_DOUBLE_EQ(parse_quantity("30 \xC2\xB0", Dimension::Angle), std::numbers::pi / 6.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.5 rad", Dimension::Angle), 0.5);
}

TEST(Units, ForceSpeedTimeDensityViscosity) {
  EXPECT_DOUBLE_EQ(parse_quantity("14 mN", Dimension::Force), 0.014);
  EXPECT_DOUBLE_EQ(parse_quantity("3 uN", Dimension::Force), 3e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("2 kN", Dimension::Force), 2e3);
  EXPECT_DOUBLE_EQ(parse_quantity("1 mm/s", Dimension::Speed), 1e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("500 um/s", Dimension::Speed), 5e-4);
  EXPECT_DOUBLE_EQ(parse_quantity("20 ms", Dimension::Time), 0.02);
  EXPECT_DOUBLE_EQ(parse_quantity("1100 kg/m^3", Dimension::Density), 1100.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1.1 g/cm3", Dimension::Density), 1100.0);
  EXPECT_DOUBLE_EQ(parse_quantity("3 Pa s", Dimension::Viscosity), 3.0);
  EXPECT_DOUBLE_EQ(parse_quantity("3 Pa*s", Dimension::Viscosity), 3.0);
  EXPECT_DOUBLE_EQ(parse_quantity("4 mPa   s", Dimension::Viscosity), 4e-3);
}

TEST(Units, ToughnessInNewtonPerMillimetreEqualsJoulePerSquareMetre) {
  EXPECT_DOUBLE_EQ(parse_quantity("0.019 N/mm", Dimension::Toughness), 19.0);
  EXPECT_DOUBLE_EQ(parse_quantity("19 J/m^2", Dimension::Toughness), 19.0);
  EXPECT_DOUBLE_EQ(parse_quantity("19 J/m2", Dimension::Toughness), 19.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.1 kJ/m^2", Dimension::Toughness), 100.0);
  EXPECT_DOUBLE_EQ(parse_quantity("5 mJ/m^2", Dimension::Toughness), 5e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("73.2 mJ/m", Dimension::Force), 73.2e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("0.0732 J/m", Dimension::Force), 0.0732);
  EXPECT_THROW(parse_quantity("73.2 mJ/m", Dimension::Toughness), mneedle::InputError);
}

TEST(Units, EnergyIsJouleAndNotAnEnergyPerLengthOrArea) {
  EXPECT_DOUBLE_EQ(parse_quantity("84 mJ", Dimension::Energy), 84e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("3 uJ", Dimension::Energy), 3e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("0.5 J", Dimension::Energy), 0.5);
  EXPECT_THROW(parse_quantity("84 mJ/m", Dimension::Energy), mneedle::InputError);
  EXPECT_THROW(parse_quantity("84 mJ", Dimension::Force), mneedle::InputError);
  EXPECT_THROW(parse_quantity("19 J", Dimension::Toughness), mneedle::InputError);
  EXPECT_EQ(mneedle::si_unit(Dimension::Energy), "J");
}

TEST(Units, ToughnessAndStiffnessShareNewtonPerMetre) {
  EXPECT_DOUBLE_EQ(parse_quantity("2 N/m", Dimension::Stiffness), 2.0);
  EXPECT_DOUBLE_EQ(parse_quantity("2 N/m", Dimension::Toughness), 2.0);
  EXPECT_DOUBLE_EQ(parse_quantity("2 J/m^2", Dimension::Stiffness), 2.0);
  EXPECT_TRUE(mneedle::dimensions_compatible(Dimension::Toughness, Dimension::Stiffness));
  EXPECT_FALSE(mneedle::dimensions_compatible(Dimension::Pressure, Dimension::Stiffness));
}

TEST(Units, PlainNumberIsDimensionlessSi) {
  const auto q = parse_quantity("1e-3");
  EXPECT_EQ(q.dimension, Dimension::Dimensionless);
  EXPECT_DOUBLE_EQ(q.value_si, 1e-3);
}

TEST(Units, PlainNumberWhereAUnitIsNeededIsAnErrorListingTheUnits) {
  // "--speed 2" was 2 m/s and "bevel_angle=30" 1718.87 deg: a plain number is refused there.
  const auto msg = error_of([] { parse_quantity("2.3e-4", Dimension::Length); });
  EXPECT_NE(msg.find("\"2.3e-4\" needs a unit: a length (nm, um, mm, cm, m)"), std::string::npos)
      << msg;
  EXPECT_DOUBLE_EQ(parse_quantity("0.4", Dimension::Dimensionless), 0.4);
  EXPECT_DOUBLE_EQ(parse_quantity("0", Dimension::Length), 0.0);  // 0 in every unit
}

TEST(Units, SignsAndExponentsParse) {
  EXPECT_DOUBLE_EQ(parse_quantity("-500 um", Dimension::Length), -5e-4);
  EXPECT_DOUBLE_EQ(parse_quantity("+5 um", Dimension::Length), 5e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("  2.5e2um ", Dimension::Length), 2.5e-4);
}

TEST(Units, UnknownUnitIsNamed) {
  const auto msg = error_of([] { parse_quantity("230 xm"); });
  EXPECT_NE(msg.find("unknown unit 'xm'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("\"230 xm\""), std::string::npos) << msg;
}

TEST(Units, UnknownUnitForExpectedDimensionListsTheAcceptedOnes) {
  const auto msg = error_of([] { parse_quantity("230 microns", Dimension::Length); });
  EXPECT_NE(msg.find("unknown unit 'microns'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("um"), std::string::npos) << msg;
}

TEST(Units, WrongDimensionNamesGivenAndExpected) {
  const auto msg = error_of([] { parse_quantity("30 deg", Dimension::Length); });
  EXPECT_NE(msg.find("is an angle"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected a length"), std::string::npos) << msg;
}

TEST(Units, UnitWhereAPlainNumberIsExpectedIsRejected) {
  const auto msg = error_of([] { parse_quantity("0.4 MPa", Dimension::Dimensionless); });
  EXPECT_NE(msg.find("expected a plain number"), std::string::npos) << msg;
}

TEST(Units, NanInfinityEmptyAndMissingNumberAreRejected) {
  EXPECT_THROW(parse_quantity("nan um"), InputError);
  EXPECT_THROW(parse_quantity("inf"), InputError);
  EXPECT_THROW(parse_quantity("-infinity m"), InputError);
  EXPECT_THROW(parse_quantity("1e400 m"), InputError);
  EXPECT_THROW(parse_quantity("   "), InputError);
  const auto msg = error_of([] { parse_quantity("um 230"); });
  EXPECT_NE(msg.find("expected a number first"), std::string::npos) << msg;
}

TEST(Units, OverflowToInfinityInSiIsRejected) {
  EXPECT_THROW(parse_quantity("1e300 GPa"), InputError);
}

TEST(Units, QuantityInConvertsOrNamesTheValue) {
  const mneedle::Quantity diameter{230e-6, Dimension::Length};
  EXPECT_DOUBLE_EQ(mneedle::quantity_in(diameter, Dimension::Length, "diameter"), 230e-6);
  const mneedle::Quantity plain{64, Dimension::Dimensionless};
  const auto unitless =
      error_of([&] { mneedle::quantity_in(plain, Dimension::Length, "diameter"); });
  EXPECT_NE(unitless.find("diameter needs a unit: a length"), std::string::npos) << unitless;
  const auto msg =
      error_of([&] { mneedle::quantity_in(diameter, Dimension::Angle, "bevel_angle"); });
  EXPECT_NE(msg.find("bevel_angle is a length; expected an angle"), std::string::npos) << msg;
}

TEST(Units, MeshFileUnitsScaleToMetres) {
  EXPECT_DOUBLE_EQ(mneedle::length_unit_scale("um"), 1e-6);
  EXPECT_DOUBLE_EQ(mneedle::length_unit_scale("mm"), 1e-3);
  EXPECT_DOUBLE_EQ(mneedle::length_unit_scale("m"), 1.0);
  const auto msg = error_of([] { mneedle::length_unit_scale("inch"); });
  EXPECT_NE(msg.find("'inch'"), std::string::npos) << msg;
}

TEST(Units, DimensionNamesAreLowerCaseWords) {
  EXPECT_EQ(mneedle::dimension_name(Dimension::Length), "length");
  EXPECT_EQ(mneedle::dimension_name(Dimension::Pressure), "pressure");
  EXPECT_EQ(mneedle::dimension_name(Dimension::Toughness), "toughness");
  EXPECT_EQ(mneedle::dimension_name(Dimension::Viscosity), "viscosity");
}

TEST(Units, FormatQuantityPicksAReadableUnit) {
  EXPECT_EQ(mneedle::format_quantity(230e-6, Dimension::Length), "230 um");
  EXPECT_EQ(mneedle::format_quantity(2e-3, Dimension::Length), "2 mm");
  EXPECT_EQ(mneedle::format_quantity(8e4, Dimension::Pressure), "80 kPa");
  EXPECT_EQ(mneedle::format_quantity(1e9, Dimension::Pressure), "1 GPa");
  EXPECT_EQ(mneedle::format_quantity(std::numbers::pi / 2.0, Dimension::Angle), "90 deg");
  EXPECT_EQ(mneedle::format_quantity(0.014, Dimension::Force), "14 mN");
  EXPECT_EQ(mneedle::format_quantity(19.0, Dimension::Toughness), "19 J/m^2");
  EXPECT_EQ(mneedle::format_quantity(0.4, Dimension::Dimensionless), "0.4");
}

TEST(Units, FormattedQuantitiesParseBack) {
  for (const double v : {1.15e-3, 3e-3, 5e-9, 0.7}) {
    const auto text = mneedle::format_quantity(v, Dimension::Length);
    EXPECT_NEAR(parse_quantity(text, Dimension::Length), v, 1e-6 * v) << text;
  }
}

}  // namespace
