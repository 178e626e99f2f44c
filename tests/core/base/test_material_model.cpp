#include "mneedle/base/material_model.h"

#include <gtest/gtest.h>

namespace mneedle {
namespace {

TEST(MaterialModel, NamesAreTheOnesSceneFilesUse) {
  EXPECT_EQ(to_string(MaterialModel::Linear), "linear");
  EXPECT_EQ(to_string(MaterialModel::StVenantKirchhoff), "svk");
  EXPECT_EQ(to_string(MaterialModel::NeoHookean), "neo_hookean");
  EXPECT_EQ(to_string(MaterialModel::MooneyRivlin), "mooney_rivlin");
}

}  // namespace
}  // namespace mneedle
