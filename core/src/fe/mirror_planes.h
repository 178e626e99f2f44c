#pragma once
// PRIVATE to mneedle::core: a 3-D scene reduced by its mirror planes x = 0 and y = 0. The model
// keeps the needles with x >= 0 (y >= 0) and each dropped needle shares the results of its
// mirror image among the kept ones.

#include <Eigen/Core>
#include <vector>

#include "mneedle/fe/indentation3d.h"

namespace mneedle::fe {

struct MirrorSelection {
  std::vector<Needle3d> kept;          ///< needles of the modelled part, in the scene's order
  std::vector<std::size_t> kept_from;  ///< for every kept needle: its index in the scene
  /// For every needle of the scene: index into `kept` of the needle whose results it takes.
  std::vector<std::size_t> source;
  /// For every needle of the scene: +1 or -1 per lateral force component (an image across x = 0
  /// pushes the other way in x).
  std::vector<Eigen::Vector2d> lateral_sign;
};

/// Splits `needles` for the active mirror planes. Throws InputError naming the needle when the
/// set does not map onto itself under a plane (a needle without an image of the same mesh at
/// the mirrored position) or a needle is not itself symmetric about the plane's direction.
MirrorSelection select_mirrored_part(const std::vector<Needle3d>& needles, bool mirror_x,
                                     bool mirror_y);

/// One step of the reduced model (one entry per kept needle) as a step of the whole scene (one
/// entry per needle, in the scene's order, names from `needles`).
Step3d whole_scene_step(const Step3d& reduced, const MirrorSelection& selection,
                        const std::vector<Needle3d>& needles);

}  // namespace mneedle::fe
