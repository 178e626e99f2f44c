#pragma once
// Test helper: a 800 x 800 um block of a stiff 20 um layer on a soft 300 um one, the smallest
// layered case the 3-D tests press needles into.
#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::test {

inline fe::TissueBlockSpec small_skin() {
  fe::TissueBlockSpec block;
  block.size_x = block.size_y = 800e-6;
  block.layers = {{"top", 20e-6, {MaterialModel::Linear, 2e6, 0.4, 0.0, 0.0}},
                  {"bottom", 300e-6, {MaterialModel::Linear, 0.1e6, 0.4, 0.0, 0.0}}};
  return block;
}

}  // namespace mneedle::test
