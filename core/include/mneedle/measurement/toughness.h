#pragma once
// Fracture toughness from two insertions into the same spot (paper A, eqs. 12-14): the first pass
// cracks the tissue, the second finds the crack made, so J = ∫(F - F') dz / A. Also the two
// second-pass constructions used when a recording has no second pass (docs/model.md).

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mneedle/measurement/force_curve.h"
#include "mneedle/needle/mesh.h"

namespace mneedle {

/// What was kept from one recording and what was cut, in data rows of its file.
struct PassCut {
  std::string source;
  std::size_t rows = 0;            ///< data rows read (0 for a constructed pass)
  std::size_t points = 0;          ///< points of the pass inside the integration range
  std::size_t before_contact = 0;  ///< approach, before the detected contact
  std::size_t hold = 0;            ///< after the deepest travel while the travel stays there
  std::size_t retraction = 0;      ///< after the hold
  std::size_t repeated_depth = 0;  ///< merged into a point at the same depth (mean force)
  std::size_t receding_depth = 0;  ///< merged: shallower than a depth already reached
  std::size_t beyond_end = 0;      ///< deeper than the end of the integration
  double contact_travel_m = 0.0;   ///< travel at contact in the file
  double baseline_N = 0.0;         ///< sensor offset removed
  double noise_N = 0.0;            ///< baseline noise (robust standard deviation)
};

/// One insertion ready to integrate: depth from the contact point (strictly increasing), force
/// minus the baseline.
struct InsertionPass {
  ForceCurve curve;
  LoadingBranch branch;  ///< as cut from the raw recording (empty for a constructed pass)
  PassCut cut;
};

/// Loading branch (contact, hold and retraction cut; force_curve.h) with repeated and receding
/// depths merged. Throws InputError naming file:line when there is no loading branch.
InsertionPass prepare_pass(const ForceCurve& raw, const LoadingBranchOptions& options = {});

/// How the depth axes of the two passes are matched.
enum class DepthAlignment {
  Contact,  ///< each pass from its own detected contact (files zeroed independently)
  Travel,   ///< both from the first pass's contact travel (one rig, one zero)
};

DepthAlignment parse_depth_alignment(std::string_view text);  ///< "contact" | "travel"

struct ToughnessOptions {
  DepthAlignment alignment = DepthAlignment::Contact;
  /// End of the integral (`--max-depth`); unset = the shallower pass's deepest point.
  std::optional<double> max_depth_m;
};

/// Fewest samples of each pass force_difference integrates over: two intervals, so that the
/// integral follows the curve rather than one straight line between its ends.
inline constexpr std::size_t kMinIntegrationSamples = 3;

/// The two passes on one depth grid (the union of their depths, linear interpolation) and the
/// trapezoidal integrals of F, F' and F - F' from 0 to the end depth.
struct ForceDifference {
  std::vector<double> depth_m;
  std::vector<double> first_force_N;
  std::vector<double> second_force_N;
  double end_depth_m = 0.0;
  double first_work_J = 0.0;       ///< ∫F dz
  double second_work_J = 0.0;      ///< ∫F' dz
  double difference_work_J = 0.0;  ///< ∫(F - F') dz
  PassCut first, second;           ///< with points and beyond_end filled in
};

/// Aligns (second shifted for DepthAlignment::Travel: zero force before its own contact) and
/// integrates. Throws InputError when the common depth range is empty, when max_depth_m is set but
/// not a positive finite length (naming --max-depth), and when the range keeps fewer than
/// kMinIntegrationSamples samples of either pass (saying how many it keeps).
ForceDifference force_difference(const InsertionPass& first, const InsertionPass& second,
                                 const ToughnessOptions& options = {});

/// J = ∫(F - F') dz / A (paper A eq. 14). Throws InputError for a non-positive or non-finite A.
double toughness_J_per_m2(const ForceDifference& difference, double crack_area_m2);

/// Crack area of a needle inserted to `depth_m` (its tip that far below the surface): the largest
/// material cross-section (bores excluded) between the tip and that height, i.e. paper A's dA
/// (the section's circular segment) grown to the depth; the shaft's section once the whole tip is
/// in. The mesh must be in the needle frame. A depth beyond the mesh uses its top section.
struct CrackArea {
  double area_m2 = 0.0;
  double height_m = 0.0;  ///< height above the tip where the section was taken
  double needle_length_m = 0.0;
  double tip_length_m = 0.0;  ///< where the section first reaches 99 % of its largest area
};
CrackArea needle_crack_area(const TriangleMesh& needle_frame_mesh, double depth_m);

/// "1.27 mm^2", "1.27mm2", "4e-7 m^2": a length unit squared. Throws InputError naming the text
/// for anything else (a bare number included), a non-positive or non-finite value.
double parse_area_m2(std::string_view text);

/// The largest drop of the force below its running maximum: the first puncture of a recording.
struct ForceDrop {
  std::size_t peak_index = 0, bottom_index = 0;
  double peak_depth_m = 0.0, peak_force_N = 0.0;
  double bottom_depth_m = 0.0, bottom_force_N = 0.0;
};
/// Throws InputError naming the source when the largest drop is below `min_fraction` of the peak.
ForceDrop largest_force_drop(const ForceCurve& curve, double min_fraction = 0.1);

/// Second pass built from the first's retraction: F'(z) = -(F_retraction(z) - baseline), the
/// friction met on the way out, as the force of a pass that cuts nothing. Throws InputError when
/// the recording has no retraction reaching back over the loading branch.
InsertionPass second_pass_from_retraction(const ForceCurve& raw, const InsertionPass& first);

/// Second pass built from the first's post-puncture part: F'(z) = F(z) from the bottom of the
/// largest force drop on (the crack is made there and nothing more is cracked after it), and
/// before it a straight line from zero at contact to that post-puncture force.
InsertionPass second_pass_from_tail(const InsertionPass& first, ForceDrop* drop = nullptr);

}  // namespace mneedle
