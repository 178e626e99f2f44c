#include "mneedle/strength/needle_material.h"

#include <gtest/gtest.h>

#include "mneedle/base/error.h"

namespace {

TEST(NeedleMaterial, LibraryHoldsTheMaterialsTheDesignersUse) {
  for (const char* name : {"silicon", "stainless_steel_304", "titanium_grade1", "ti6al4v", "pla",
                           "pga", "plga", "cmc", "polycarbonate"}) {
    const auto m = mneedle::find_needle_material(name);
    EXPECT_GT(m.youngs_modulus_pa, 0.0) << name;
    EXPECT_GT(m.strength_pa, 0.0) << name;
    EXPECT_FALSE(m.source.empty()) << name;
  }
}

TEST(NeedleMaterial, SteelValuesMatchTheHandbook) {
  const auto steel = mneedle::find_needle_material("stainless_steel_304");
  EXPECT_DOUBLE_EQ(steel.youngs_modulus_pa, 193e9);
  EXPECT_DOUBLE_EQ(steel.strength_pa, 215e6);
  EXPECT_EQ(steel.failure, mneedle::FailureMode::Yield);
}

TEST(NeedleMaterial, UserMaterialsShadowBuiltInOnes) {
  mneedle::NeedleMaterial mine{"silicon", 130e9, 0.28, 2e9, mneedle::FailureMode::Fracture, "mine"};
  EXPECT_DOUBLE_EQ(mneedle::find_needle_material("silicon", {mine}).youngs_modulus_pa, 130e9);
}

TEST(NeedleMaterial, UnknownNameListsTheKnownOnes) {
  try {
    mneedle::find_needle_material("unobtainium");
    FAIL() << "expected an InputError";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("silicon"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("unobtainium"), std::string::npos);
  }
}

TEST(NeedleMaterial, NonPhysicalUserMaterialIsRejected) {
  mneedle::NeedleMaterial bad{"goo", 1e9, 0.5, 1e6, mneedle::FailureMode::Fracture, ""};
  EXPECT_THROW(mneedle::find_needle_material("goo", {bad}), mneedle::InputError);
  bad.poisson_ratio = 0.3;
  bad.youngs_modulus_pa = -1.0;
  EXPECT_THROW(mneedle::validate_needle_material(bad, "scene.toml"), mneedle::InputError);
}

}  // namespace
