#pragma once
// Checks on raw shape-kit meshes, independent of mneedle::core's validation.

#include <map>
#include <utility>

#include "shape_kit.h"

namespace mneedle::shape_kit {

/// True when every directed edge appears exactly once and its reverse exactly once: the
/// mesh is closed, edge-manifold and consistently oriented.
inline bool closed_and_consistent(const MeshBuilder& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const auto& t : mesh.triangles()) {
    for (int i = 0; i < 3; ++i) ++edges[{t[i], t[(i + 1) % 3]}];
  }
  for (const auto& [edge, count] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    if (count != 1 || reverse == edges.end() || reverse->second != 1) return false;
  }
  return !edges.empty();
}

}  // namespace mneedle::shape_kit
