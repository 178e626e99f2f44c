#pragma once
// The needle frame used by everything downstream (the same one tip-shape plugins generate in):
// the shaft's axis is the z axis, the tip (the lowest point) is at z = 0, the body runs along
// +z, insertion toward -z into tissue whose undeformed surface is the plane z = 0. A symmetric
// tip is at the origin; a bevel's tip is on the rim, one radius from it.

#include <optional>
#include <string>
#include <string_view>

#include "mneedle/needle/mesh.h"

namespace mneedle {

struct FrameInfo {
  Vec3 axis{};  ///< unit direction the tip points, in the input coordinates
  Vec3 tip{};   ///< tip point in the input coordinates (metres)
  /// Where the shaft's axis crosses the tip's level, in the input coordinates: the frame's
  /// origin. The tip lies tip_offset_m from it (a bevel's tip is on the rim, one radius off).
  Vec3 origin{};
  double tip_offset_m = 0.0;
  bool auto_axis = false;  ///< axis found by principal-component analysis
  /// `auto` or a line was asked for but no end is narrower (a cube, a cylinder with flat ends):
  /// the input z was used, a guess the caller should show (the note says why).
  bool fell_back_to_input_z = false;
  std::string note;  ///< how the tip was found, e.g. which end `auto` chose
};

/// How the caller names the tip direction.
struct AxisChoice {
  /// input_z: the input z, tip at the lowest z. given: `tip_direction`. line: the axis along
  /// `tip_direction` (either sign), the tip at its narrower end. automatic: the principal axis
  /// of the surface, tip at the narrower end; a body that is not longer than it is wide (largest
  /// principal moment under 1.5x the next) has no principal axis to trust and takes input_z.
  enum class Kind { input_z, given, line, automatic };
  Kind kind = Kind::input_z;
  Vec3 tip_direction{0.0, 0.0, -1.0};  ///< used by given and line (need not be unit length)
};

/// "auto", "x", "y", "z" (a line, tip at its narrower end) or "a,b,c" (the tip direction).
/// Throws InputError naming the text and the accepted forms.
AxisChoice parse_axis_choice(std::string_view text);

/// Moves `mesh` into the needle frame. Without a direction the input z is the axis and the
/// tip is at the lowest z; a direction names where the tip points. The tip is the single
/// extreme vertex along the direction; a flat or hollow tip (several extreme vertices apart)
/// has no tip point, and the tip is then the point of the centroid's axis line in the lowest
/// cross-section. The tip direction's line through the volume centroid (area centroid when the
/// mesh encloses no volume) finds the tip; the frame's axis is the shaft's, through the area
/// centroid of the base (the faces at the end farthest from the tip that face away from it; the
/// volume centroid when there is no such flat base). Throws mneedle::InputError for an empty
/// mesh or a zero or non-finite direction.
FrameInfo place_in_needle_frame(TriangleMesh& mesh, std::optional<Vec3> tip_direction);

/// As above with the automatic choice available: the principal axis of the surface
/// (area-weighted), with the tip at the end whose cross-section near the end is smaller.
FrameInfo place_in_needle_frame(TriangleMesh& mesh, const AxisChoice& choice);

/// Finds the frame without moving the mesh.
FrameInfo find_needle_frame(const TriangleMesh& mesh, const AxisChoice& choice);

}  // namespace mneedle
