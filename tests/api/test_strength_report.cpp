// strength as a library call: the capacity is the smaller of buckling and material strength,
// the plugin's analytic sections and the sliced mesh agree, bad settings are one-line errors.
#include "mneedle/api/strength_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

NeedleSource cone(const PluginRegistry& registry) {
  return needle_from_plugin(
      registry, "cone",
      parse_parameter_settings(registry.shape("cone"), {"diameter=200um", "length=600um"}));
}

TEST(StrengthReport, CapacityIsTheSmallerOfBucklingAndStrength) {
  const PluginRegistry registry = PluginRegistry::discover({});
  StrengthSettings s;
  s.material = "pla";
  const nlohmann::json r = strength_report(registry, cone(registry), s);
  EXPECT_EQ(r["material"], "pla");
  EXPECT_DOUBLE_EQ(r["capacity_N"].get<double>(),
                   std::min(r["buckling_N"].get<double>(), r["strength_N"].get<double>()));
  EXPECT_DOUBLE_EQ(r["length_m"].get<double>(), 600e-6);
}

TEST(StrengthReport, PluginSectionsAndTheSlicedMeshAgree) {
  // The cone's hook gives exact circles; its mesh is a 64-gon, whose section properties are
  // within (2π/64)² ≈ 1 % of the circle's (measured: the buckling load 0.16 % low).
  const PluginRegistry registry = PluginRegistry::discover({});
  StrengthSettings s;
  s.material = "silicon";
  const NeedleSource analytic = cone(registry);
  NeedleSource sliced = analytic;
  sliced.plugin.reset();
  const double a = strength_report(registry, analytic, s)["buckling_N"].get<double>();
  const double b = strength_report(registry, sliced, s)["buckling_N"].get<double>();
  EXPECT_NEAR(b / a, 1.0, std::pow(2.0 * std::numbers::pi / 64.0, 2));
  EXPECT_LT(b, a);  // an inscribed polygon is thinner than its circle
}

// A plugin's hook that does not describe its own mesh (here: the 200 um cone's hook over a
// 300 um cone's mesh, 2.25 times its area) is named, not trusted: a plugin whose hook had a
// unit slip gave a capacity 1000 times too large, exit 0.
TEST(StrengthReport, AHookThatDisagreesWithItsMeshIsRefused) {
  const PluginRegistry registry = PluginRegistry::discover({});
  NeedleSource needle = cone(registry);
  needle.mesh = needle_from_plugin(registry, "cone",
                                   parse_parameter_settings(registry.shape("cone"),
                                                            {"diameter=300um", "length=600um"}))
                    .mesh;
  StrengthSettings s;
  s.material = "pla";
  try {
    strength_report(registry, needle, s);
    ADD_FAILURE() << "a hook 2.25 times off its mesh was trusted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the hook does not describe the shape"), std::string::npos)
        << e.what();
  }
}

TEST(StrengthReport, BadSettingsAreInputErrors) {
  const PluginRegistry registry = PluginRegistry::discover({});
  const NeedleSource needle = cone(registry);
  StrengthSettings s;
  EXPECT_THROW(strength_report(registry, needle, s), InputError);  // no material
  s.material = "pla";
  s.lateral_ratio = -1.0;
  EXPECT_THROW(strength_report(registry, needle, s), InputError);
  s.lateral_ratio = 0.0;
  s.depth = "300";  // no unit: named as the option it came from
  try {
    strength_report(registry, needle, s);
    ADD_FAILURE() << "a depth without a unit was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--depth: \"300\" needs a unit", 0), 0u) << e.what();
  }
  s.depth = "";
  s.end = "glued";
  EXPECT_THROW(strength_report(registry, needle, s), InputError);
}

}  // namespace
}  // namespace mneedle
