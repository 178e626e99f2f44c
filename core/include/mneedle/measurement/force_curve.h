#pragma once
// Measured force–depth recordings: CSV reading with units taken from the column names, contact
// detection and the loading branch (the part a force model is fitted to). Shared by the tri-force
// fit and the toughness command.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace mneedle {

/// A force–depth recording in SI units, one entry per sample, in file order.
struct ForceCurve {
  std::string source;             ///< file name, used in messages
  std::vector<double> time_s;     ///< empty when the file has no time column
  std::vector<double> depth_m;    ///< needle travel along its axis
  std::vector<double> force_N;    ///< axial force, positive resisting insertion
  std::vector<std::size_t> line;  ///< 1-based line of each sample in the source file
  std::string depth_column;       ///< header of the depth column, for messages ("" if not read)
};

/// Which CSV columns to read. An empty name picks the first column whose name (without its unit)
/// is, or starts with followed by '_', one of the usual prefixes (depth: depth, travel, position,
/// displacement, z; force: force, fz, f; time: time, t). An empty unit is read from the column
/// name: a trailing `[unit]` or `(unit)` (`z [mm]`, `Force (mN)`), else the suffix after the last
/// '_' (`travel_mm`, `fz_N`). A name without either needs the unit given explicitly.
struct CurveColumns {
  std::string depth;
  std::string force;
  std::string time;
  std::string depth_unit;  ///< e.g. "mm", "um", "m"
  std::string force_unit;  ///< e.g. "N", "mN"
};

/// Reads a comma-separated file with one header line. Blank lines and lines starting with '#'
/// are skipped. Throws InputError naming file:line for a missing column, a unit that cannot be
/// read, a field that is not a number or a row with too few fields.
ForceCurve read_force_curve_csv(const std::filesystem::path& file,
                                const CurveColumns& columns = {});

struct LoadingBranchOptions {
  /// Contact is where the force leaves the baseline by more than this many noise deviations.
  double noise_factor = 5.0;
  /// ... and by at least this fraction of the peak force (digitised curves have no noise).
  double min_rise_fraction = 0.01;
};

/// The loading part of a recording: from contact to the first sample at the deepest travel.
struct LoadingBranch {
  ForceCurve curve;               ///< depth from contact, force minus the baseline
  double contact_travel_m = 0.0;  ///< travel at contact in the raw recording
  double baseline_N = 0.0;        ///< sensor offset removed from the force
  double noise_N = 0.0;           ///< robust standard deviation of the baseline
  std::size_t contact_index = 0;  ///< raw sample index of contact
  std::size_t end_index = 0;      ///< raw sample index of the deepest point (inclusive)
  std::size_t hold_samples = 0;   ///< samples cut after the deepest point while travel stays there
  std::size_t retraction_samples = 0;  ///< samples cut after the hold
  /// Fewer than 3 samples precede contact (the force rises from about the first sample): no
  /// baseline is removed (docs/model.md, "Curve reading").
  bool starts_at_contact = false;
  /// ... and the first sample is already loaded within one step of travel 0: contact is taken
  /// at travel 0 (a curve written from the surface on, like `mneedle simulate --csv`).
  bool contact_before_first_sample = false;
  std::string summary;  ///< one line saying what was kept and what was cut
};

/// Detects the contact point and cuts the approach, the hold and the retraction. The baseline
/// comes from the leading samples while they stay flat; a curve that rises from its first sample
/// starts at contact. Throws InputError naming file:line when there is no loading branch: the
/// travel decreases from the first sample (checked first, naming the depth column), the force
/// never leaves the noise, or the needle does not advance after contact.
LoadingBranch extract_loading_branch(const ForceCurve& raw,
                                     const LoadingBranchOptions& options = {});

/// A curve whose depth only increases: each sample that does not go deeper than every sample
/// before it (a repeated depth, or a digitising step back) is merged into the point it fails to
/// pass, whose force becomes the mean of the merged samples.
struct MonotoneCurve {
  ForceCurve curve;  ///< strictly increasing depth; time and line of each group's first sample
  std::size_t repeated_samples = 0;  ///< merged samples at exactly the group's depth
  std::size_t receding_samples = 0;  ///< merged samples shallower than the group's depth
};

MonotoneCurve merge_repeated_depths(const ForceCurve& curve);

/// The force at `depth_m` on a curve of strictly increasing depth: linear between samples,
/// constant beyond the ends.
double force_at(const ForceCurve& curve, double depth_m);

/// Samples of `raw` after the loading branch while the travel stays at its maximum, as
/// (time from the end of loading, force minus baseline). Empty without a time column.
ForceCurve hold_segment(const ForceCurve& raw, const LoadingBranch& branch);

/// Mean speed of the loading branch (least-squares slope of depth against time). Throws
/// InputError when the curve has no time column or the travel does not advance.
double loading_speed(const LoadingBranch& branch);

}  // namespace mneedle
