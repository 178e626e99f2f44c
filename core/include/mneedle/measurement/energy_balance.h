#pragma once
// Toughness from the energy balance of a deep, through-and-through insertion (paper C, §2 and §5):
// a recording is cut into the five stages of its Fig. 2, and over the cutting stretch
// W_ext = W_f + W_eps + W_Gc gives G_c = W_Gc / (w_mean d). docs/model.md, "Energy balance of a
// deep insertion".

#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "mneedle/measurement/force_curve.h"

namespace mneedle {

/// Where paper C's stages meet on one loading curve (depth from contact, strictly increasing):
/// A deformation [0, puncture], B puncture and relaxation [puncture, relaxed], C cutting
/// [relaxed, peak], D exit relaxation [peak, sliding start], E sliding [sliding start, end].
/// D and E exist only when the record goes through the block (`through`).
struct InsertionStages {
  std::size_t puncture_index = 0;  ///< first force peak followed by a drop (end of A)
  std::size_t relaxed_index = 0;   ///< lowest force between the puncture and the peak (end of B)
  std::size_t peak_index = 0;      ///< highest force after the puncture drop (end of C)
  bool through = false;            ///< the force drops after the peak and settles: D and E found
  std::size_t sliding_index = 0;   ///< start of E (when `through`)
  std::size_t sliding_samples = 0;
  double sliding_force_N = 0.0;  ///< mean force over E: the friction of the whole block
  /// ∫F dx over A..E (trapezoidal, J); 0 for a stage that is absent.
  double stage_work_J[5] = {0, 0, 0, 0, 0};
};

struct StageOptions {
  /// The puncture drop: the force falls below its running peak by this fraction of the peak ...
  double min_drop_fraction = 0.1;
  /// ... and by this fraction of the record's highest force (a small early dip, a layer giving
  /// way under a fraction of the load, is not the puncture that starts the crack) ...
  double min_drop_of_max_fraction = 0.05;
  /// ... and by this many baseline noise deviations (`noise_N`, from the loading branch).
  double noise_factor = 5.0;
  double noise_N = 0.0;
  /// Look for D and E at all: only for a record the user says goes through the block (`energy
  /// --depth`). In a layered tissue the puncture of a deeper layer followed by a steady force
  /// looks like an exit; on the 73 phantom recordings of docs/validation.md, which never go
  /// through, 13 would be read as through.
  bool seek_exit = true;
  /// The exit: after the peak the force falls by at least this fraction of the peak (a smaller
  /// dip is read as scatter of the cutting force, not as the tip leaving the block).
  double min_exit_drop_fraction = 0.2;
  /// E starts where the force first comes within this fraction of the peak force of its sliding
  /// level (the median force over the second half of the samples after the peak) ...
  double sliding_band_fraction = 0.02;
  /// ... and needs at least this many samples, and its force must stay flat: the spread between
  /// its 5th and 95th percentiles at most this fraction of the peak force (a force that climbs
  /// again after a drop is a puncture followed by more cutting, not sliding after the exit).
  std::size_t min_sliding_samples = 3;
  double max_sliding_spread_fraction = 0.1;
};

/// Cuts a loading curve into the stages. Throws InputError naming the curve's source when it has
/// fewer than 3 samples, a depth that does not increase, or no puncture drop (saying by how much
/// the force fell at most).
InsertionStages split_stages(const ForceCurve& loading, const StageOptions& options = {});

/// The crack width w(z) through the block: a polynomial of degree min(2, distinct depths - 1)
/// fitted by least squares to measured (depth, width) pairs (paper C fits a quadratic through
/// three), and its mean over 0 <= z <= d.
struct CrackWidthFit {
  std::vector<double> coefficients;  ///< w(z) = c0 + c1 z + c2 z^2 (m), degree + 1 entries
  double mean_width_m = 0.0;         ///< (1/d) ∫0^d w dz, exact for the polynomial
  double min_width_m = 0.0;          ///< smallest w on [0, d]
  double max_residual_m = 0.0;       ///< largest |fit - measured| (0 when the fit interpolates)
};

/// Throws InputError (naming --crack-widths) for no pairs, a width that is not positive, a depth
/// outside [0, d], a non-positive d, or a fit that is not positive everywhere on [0, d].
CrackWidthFit fit_crack_width(std::span<const std::pair<double, double>> depth_width_m,
                              double block_depth_m);

/// What the balance needs besides the record, SI.
struct EnergyBalanceInputs {
  double block_depth_m = 0.0;              ///< d: thickness of the block along the needle
  double mean_crack_width_m = 0.0;         ///< w_mean
  double strain_energy_J_per_m = 0.0;      ///< U_eps: strain energy per unit crack length
  std::optional<double> friction_force_N;  ///< F_max; unset = the record's sliding force (E)
};

/// Paper C's balance over the cutting stretch [x_peak - d, x_peak] of one record (its §5: the
/// crack is cut from one block depth before the maximum force to the maximum force).
struct EnergyBalance {
  double cut_start_m = 0.0, cut_end_m = 0.0;  ///< the stretch, depth from contact
  double external_work_J = 0.0;               ///< W_ext = ∫F dx over the stretch (eq. 5)
  double friction_force_N = 0.0;              ///< F_max
  bool friction_from_record = false;          ///< F_max is the record's stage E mean
  double friction_work_J = 0.0;     ///< W_f = ∫0^d F_max x/d dx = F_max d / 2 (eqs. 2, 3)
  double strain_work_J = 0.0;       ///< W_eps = U_eps d (eq. 4)
  double crack_work_J = 0.0;        ///< W_Gc = W_ext - W_f - W_eps (eq. 1)
  double toughness_J_per_m2 = 0.0;  ///< G_c = W_Gc / (w_mean d) (eq. 6)
};

/// Throws InputError naming the source when the inputs are not positive and finite, when the
/// peak lies less than d after contact (the needle did not go through a block that deep), or when
/// F_max is neither given nor measured (the record has no stage E).
EnergyBalance energy_balance(const ForceCurve& loading, const InsertionStages& stages,
                             const EnergyBalanceInputs& inputs);

/// ∫F dx from a to b (a < b, both inside the curve) by the trapezoidal rule on the samples, the
/// ends linearly interpolated.
double work_between(const ForceCurve& curve, double a_m, double b_m);

}  // namespace mneedle
