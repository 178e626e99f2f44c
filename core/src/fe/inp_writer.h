#pragma once
// PRIVATE to mneedle::core: the 3-D model of one depth as a CalculiX/Abaqus input deck
// (docs/cli.md, "mneedle export"), so that an independent solver can solve our own mesh with our
// own constraints: on one mesh two correct solvers agree to round-off.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::fe {

struct InpProblem {
  const TetMesh* mesh = nullptr;
  std::vector<int> prescribed_nodes;          ///< nodes held by a needle
  std::vector<Eigen::Vector3d> prescribed_u;  ///< their displacement (m)
  std::vector<std::string> comment_lines;     ///< written as "** " lines after *HEADING
};

/// Writes nodes (m), C3D4/C3D10 elements in one set per layer, linear elastic materials (Pa),
/// the block's fixed faces, the mirror planes (u_y = 0 on y = 0, u_x = 0 on x = 0) and every
/// prescribed node, and one static step that prints the reactions of the prescribed nodes
/// (*NODE PRINT, TOTALS=YES). Throws InputError naming the layer when a layer is not linear
/// (the deck would not describe our model) and naming `path` when it cannot be written.
void write_inp_deck(const std::string& path, const InpProblem& problem);

}  // namespace mneedle::fe
