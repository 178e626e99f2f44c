#pragma once
// Section properties of a needle along its axis, from polygons (a sliced mesh) or a plugin's
// analytic hook, tabulated once so that the strength and buckling solvers can query them cheaply.

#include <array>
#include <vector>

#include "mneedle/needle/mesh.h"
#include "mneedle/strength/needle_strength.h"

namespace mneedle {

/// Area, smallest principal second moment about the centroid and extreme fibre distance of nested
/// closed loops (x, y in metres): a loop inside an odd number of others is a hole (a bore).
SectionProperties polygon_section_properties(
    const std::vector<std::vector<std::array<double, 2>>>& loops);

/// Section properties tabulated at increasing heights, linearly interpolated between them.
class SectionTable {
 public:
  /// `exact`, when given, is the section the table samples (a mesh's slice, a plugin's hook):
  /// tip_length_m() solves on it between the tabulated heights.
  SectionTable(std::vector<double> heights_m, std::vector<SectionProperties> sections,
               SectionProfile exact = {});

  /// Tabulates `exact` at `samples` + 1 equally spaced heights from 0 to length_m (and keeps it
  /// for tip_length_m()).
  static SectionTable from_profile(SectionProfile exact, double length_m, int samples);

  /// Slices a mesh in the needle frame at `samples` + 1 heights from the tip to the base.
  static SectionTable from_mesh(const TriangleMesh& mesh, int samples = 200);

  SectionProperties at(double height_m) const;
  SectionProfile profile() const;  // a copy-capturing callable of at()
  double length_m() const { return heights_.back(); }

  /// Height where the section first reaches `fraction` of its largest area: the tip's length
  /// (0 for a flat-ended cylinder). Found on the exact section between the two tabulated heights
  /// that bracket it (to 1e-9 of their spacing), else linearly between them: the same tip on a
  /// longer shaft, tabulated on a coarser grid, reads the same length.
  double tip_length_m(double fraction = 0.99) const;

 private:
  std::vector<double> heights_;
  std::vector<SectionProperties> sections_;
  SectionProfile exact_;
};

}  // namespace mneedle
