#pragma once
// PRIVATE to mneedle::core: the one VTU writer of both FE models (ParaView and meshio open it),
// so the 3-D and axisymmetric fields carry the same names and units (docs/cli.md, "Fields").
// Binary: every array is raw bytes in one appended block (VTK's "appended, raw" encoding with
// UInt64 block headers), a tenth of the ASCII size and written without formatting numbers.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace mneedle::fe {

/// One data array: `components` values per point (or cell), Float64 unless `int32` is filled.
struct VtuArray {
  std::string name;
  int components = 1;
  std::vector<double> float64;
  std::vector<std::int32_t> int32;
};

struct VtuFile {
  std::vector<Eigen::Vector3d> points_m;
  std::vector<std::int64_t> connectivity;  ///< the cells' nodes one after the other, VTK order
  std::vector<std::int64_t> offsets;       ///< end of each cell in `connectivity`
  std::vector<std::uint8_t> types;         ///< VTK codes: 5 triangle, 10 TET4, 24 TET10, 22 T6
  std::vector<VtuArray> point_data;
  std::vector<VtuArray> cell_data;
  std::vector<VtuArray> field_data;  ///< whole-file values (one tuple each), e.g. depth_m
  /// Free text written as an XML comment after the header (a "--" in it is written "-\u002d",
  /// which keeps JSON valid and the comment legal).
  std::string comment;
};

/// Throws InputError naming `path` when it cannot be written, SolverError when an array's size
/// does not match its points or cells (a bug in the caller).
void write_vtu(const std::string& path, const VtuFile& file);

/// One entry of a ParaView collection: the file (relative to the .pvd), its time (here the
/// needle's depth, m) and its part (0 tissue, 1 needles).
struct PvdEntry {
  double time = 0.0;
  int part = 0;
  std::string file;
};

/// Writes the collection through a temporary file renamed over `path`, so a run stopped between
/// steps leaves a valid .pvd of the steps written so far. InputError naming `path` on failure.
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries,
               const std::string& comment);

/// Removes step_<k>.vtu, needles_<k>.vtu and steps.pvd left in `directory` by an earlier run, so
/// the folder holds exactly this run's steps. Nothing else in the folder is touched.
void clear_step_files(const std::string& directory);

}  // namespace mneedle::fe
