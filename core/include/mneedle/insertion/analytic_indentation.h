#pragma once
// The fast analytic path of the pre-puncture stage: closed-form indentation of the layered block
// by the needle's equivalent body of revolution (equal section area at every height), for
// screening where the FE model is not needed. Its error against the FE reference is measured in
// docs/speed-accuracy.md. SI units.

#include <vector>

#include "mneedle/fe/axisymmetric.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/scene/scene.h"

namespace mneedle {

struct AnalyticStep {
  double depth_m = 0.0;
  double force_N = 0.0;
  double contact_area_m2 = 0.0;  ///< projected on the surface plane
  double contact_pressure_Pa = 0.0;
};

/// The body of revolution with the mesh's solid section area at each height above the tip
/// (needle frame, metres); `samples` heights up to `height_m`.
fe::AxisymmetricNeedle equivalent_axisymmetric_needle(const TriangleMesh& mesh, double height_m,
                                                      int samples = 200);

/// Force, contact area and mean pressure at each depth (ascending, m). Throws InputError for a
/// tissue or needle it cannot represent.
std::vector<AnalyticStep> analytic_indentation(const Tissue& tissue,
                                               const fe::AxisymmetricNeedle& needle,
                                               const std::vector<double>& depths_m);

}  // namespace mneedle
