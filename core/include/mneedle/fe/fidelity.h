#pragma once
// The speed–accuracy levels every FE model offers; each model maps them to its own mesh sizes.
// Explicit overrides let a user (or a convergence study) pin any one of those choices.

#include <optional>

namespace mneedle::fe {

enum class Fidelity { Fast, Standard, Fine };

/// Each set field replaces what the fidelity level would choose; unset fields keep the level's.
struct FidelityOverrides {
  std::optional<int> order;                 ///< 1: linear elements (TET4), 2: quadratic (TET10, T6)
  std::optional<double> tip_size_m;         ///< element size at the needle tip
  std::optional<double> growth;             ///< size ratio between neighbouring elements
  std::optional<double> domain_scale;       ///< tissue block lateral size relative to the scene's
  std::optional<double> tolerance;          ///< Newton residual tolerance (relative)
  std::optional<int> steps;                 ///< depth steps of the insertion
  std::optional<int> elements_through_top;  ///< elements through the top layer's thickness
  /// 3-D tissue only: the grid is built 2^n coarser at the needle and bisected back to the tip
  /// size along the needle's path (0: the plain tensor grid; at most 6). Unset: TET10 gets 2 at
  /// standard and fine and 0 at fast (2 with a criterion length), TET4 0
  /// (default_refinement_levels).
  std::optional<int> refinement_levels;
  /// 3-D tissue with refinement levels: the top layer around each needle's first contact (its
  /// lowest points) is bisected down to this element size, within contact_zone_reach times the
  /// larger of it and the criterion length of that contact (docs/model.md, "Tissue block and
  /// mesh"; unset at every fidelity, but fine takes its own under one pointed tip with a
  /// criterion length, and every level one of 2 L over each flat first contact no wider than
  /// kMostFlatRadiusPerLength L; without refinement levels, none).
  std::optional<double> contact_zone_size_m;
  /// The contact zone's lateral reach beyond the first contact, in multiples of the larger of
  /// its size and the criterion length (unset: kContactZoneReach).
  std::optional<double> contact_zone_reach;
  /// With a contact zone and a pointed first contact (one lowest point): elements no wider than
  /// half their distance from that point, down to this size (m; unset: none, but fine's own tip
  /// size where fine takes its own zone), wherever
  /// that is finer than the zone's own law, so the tip's own contact patch is resolved
  /// (docs/model.md, "Tissue block and mesh"). Needs contact_zone_size_m, as does the reach.
  std::optional<double> contact_zone_tip_size_m;
};

/// Default contact_zone_reach: one criterion length around the first contact holds the ball
/// under the tip where the stress criterion peaks (docs/validation.md, "The 3-D model under a
/// point load, resolved").
inline constexpr double kContactZoneReach = 1.0;

/// Largest refinement_levels: each level halves the element size along the needle's path. From
/// four levels a thin stiff top layer (skin's) caps the base grid and its cells degenerate
/// (dihedral angles down to 1.5 deg), reading the puncture 5-10 % shallow (docs/validation.md,
/// "Refinement levels beyond two").
inline constexpr int kMaxRefinementLevels = 3;

/// Contact between the rigid needle and the tissue surface.
enum class ContactMode { Sticking, Frictionless };

}  // namespace mneedle::fe
