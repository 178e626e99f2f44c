#pragma once
// A needle exported from CAD usually stands on its holder or base plate. What touches tissue is
// the needle: the part from the tip up to the jump in cross-section where the holder begins.
// Finding that jump and cutting the mesh there gives everything downstream (tissue mesh size,
// column capacity, surface loads) the needle alone (docs/model.md, "Needle on a holder").

#include <optional>

#include "mneedle/needle/mesh.h"

namespace mneedle {

struct HolderJump {
  double height_m = 0.0;           ///< above the tip, where the holder begins
  double needle_outline_m2 = 0.0;  ///< outline area just below the jump
  double holder_outline_m2 = 0.0;  ///< outline area just above it
  double total_height_m = 0.0;     ///< the whole mesh, tip to top
};

/// Walking up from the tip of a mesh in the needle frame (tip at z = 0, body along +z), the first
/// height where the outline area grows by `ratio` or more within 1/400 of the mesh's height (a
/// step, not a taper: a cone's area grows by (4/3)^2 at most between such samples beyond the
/// third). nullopt when there is none: the whole mesh is the needle.
std::optional<HolderJump> find_holder_jump(const TriangleMesh& needle_frame_mesh,
                                           double ratio = 4.0);

/// The part of the mesh below `height_m` above the tip, closed by a flat cap at the cut (CGAL's
/// clip). Throws InputError when the result is empty or not closed.
TriangleMesh cut_above(const TriangleMesh& needle_frame_mesh, double height_m);

}  // namespace mneedle
