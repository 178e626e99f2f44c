#pragma once
// PRIVATE to mneedle::core: one ASCII VTU writer for both FE models (ParaView opens it), so the
// 3-D and axisymmetric fields carry the same names and units.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace mneedle::fe {

struct VtuFields {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<std::int64_t> connectivity;  ///< nodes_per_cell entries per cell, VTK's order
  int nodes_per_cell = 0;
  int cell_type = 0;                            ///< VTK code: 10 TET4, 24 TET10, 22 T6
  std::vector<Eigen::Vector3d> displacement_m;  ///< one per point
  std::vector<double> von_mises_Pa;             ///< one per cell
  std::vector<double> energy_density_J_per_m3;  ///< one per cell
  std::vector<int> layer;                       ///< one per cell
};

/// Throws InputError naming `path` when it cannot be written.
void write_vtu(const std::string& path, const VtuFields& fields);

}  // namespace mneedle::fe
