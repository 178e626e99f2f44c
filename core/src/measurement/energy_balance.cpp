#include "mneedle/measurement/energy_balance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"

namespace mneedle {
namespace {

std::string length(double m) {
  return format_quantity(m, Dimension::Length);
}

double work_of_samples(const ForceCurve& c, std::size_t from, std::size_t to) {
  double w = 0.0;
  for (std::size_t i = from; i < to; ++i)
    w += 0.5 * (c.force_N[i] + c.force_N[i + 1]) * (c.depth_m[i + 1] - c.depth_m[i]);
  return w;
}

void check_curve(const ForceCurve& c) {
  if (c.depth_m.size() < 3 || c.force_N.size() != c.depth_m.size())
    throw InputError(c.source + ": an energy balance needs at least 3 samples of depth and force");
  for (std::size_t i = 0; i < c.depth_m.size(); ++i) {
    if (!std::isfinite(c.depth_m[i]) || !std::isfinite(c.force_N[i]))
      throw InputError(c.source + ": sample " + std::to_string(i + 1) + " is not finite");
    if (i > 0 && !(c.depth_m[i] > c.depth_m[i - 1]))
      throw InputError(c.source + ": the depth must increase from sample to sample (sample " +
                       std::to_string(i + 1) + ")");
  }
}

double polynomial(const std::vector<double>& c, double z) {
  double v = 0.0;
  for (std::size_t k = c.size(); k-- > 0;) v = v * z + c[k];
  return v;
}

}  // namespace

double work_between(const ForceCurve& c, double a, double b) {
  check_curve(c);
  if (!(a < b) || a < c.depth_m.front() || b > c.depth_m.back())
    throw InputError(c.source + ": work between " + length(a) + " and " + length(b) +
                     ": outside the record (" + length(c.depth_m.front()) + " to " +
                     length(c.depth_m.back()) + ")");
  const auto& d = c.depth_m;
  const auto i0 = static_cast<std::size_t>(std::upper_bound(d.begin(), d.end(), a) - d.begin());
  const auto i1 = static_cast<std::size_t>(std::lower_bound(d.begin(), d.end(), b) - d.begin());
  // Samples strictly inside (a, b), with the interpolated ends as the first and last points.
  double w = 0.0, x = a, f = force_at(c, a);
  for (std::size_t i = i0; i < i1; ++i) {
    w += 0.5 * (f + c.force_N[i]) * (d[i] - x);
    x = d[i];
    f = c.force_N[i];
  }
  return w + 0.5 * (f + force_at(c, b)) * (b - x);
}

InsertionStages split_stages(const ForceCurve& c, const StageOptions& o) {
  check_curve(c);
  const auto& F = c.force_N;
  const std::size_t n = F.size();
  InsertionStages s;
  // A ends at the first peak that the force falls below by the drop threshold (paper C's
  // puncture: the crack starts and the tissue relaxes).
  const double highest = *std::max_element(F.begin(), F.end());
  const double min_fall =
      std::max(o.min_drop_of_max_fraction * highest, o.noise_factor * o.noise_N);
  std::size_t peak = 0, drop_at = n;
  double deepest_fall = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    if (F[i] > F[peak]) peak = i;
    const double fall = F[peak] - F[i];
    deepest_fall = std::max(deepest_fall, F[peak] > 0 ? fall / F[peak] : 0.0);
    if (F[peak] > 0.0 && fall >= o.min_drop_fraction * F[peak] && fall >= min_fall) {
      drop_at = i;
      break;
    }
  }
  if (drop_at == n) {
    std::ostringstream m;
    m << c.source << ": no puncture: the force never falls by " << 100 * o.min_drop_fraction
      << " % below a peak and by " << 100 * o.min_drop_of_max_fraction
      << " % of its highest force (at most " << 100 * deepest_fall << " %)";
    throw InputError(m.str());
  }
  s.puncture_index = peak;
  // C ends at the highest force after the drop: full penetration (paper C, Fig. 2).
  s.peak_index =
      static_cast<std::size_t>(std::max_element(F.begin() + drop_at, F.end()) - F.begin());
  // B ends at the lowest force between the puncture and that peak.
  s.relaxed_index = static_cast<std::size_t>(
      std::min_element(F.begin() + peak, F.begin() + s.peak_index + 1) - F.begin());
  // D and E: the force falls after the peak by the exit threshold and settles on a level.
  const std::size_t p = s.peak_index;
  if (o.seek_exit && p + 1 < n) {
    const double lowest_after = *std::min_element(F.begin() + p + 1, F.end());
    if (F[p] - lowest_after >= o.min_exit_drop_fraction * F[p]) {
      std::vector<double> tail(F.begin() + p + 1 + (n - p - 1) / 2, F.end());
      std::nth_element(tail.begin(), tail.begin() + tail.size() / 2, tail.end());
      const double level = tail[tail.size() / 2];
      const double band = o.sliding_band_fraction * F[p];
      std::size_t e = p + 1;
      while (e < n && F[e] > level + band) ++e;
      std::vector<double> sliding(F.begin() + static_cast<std::ptrdiff_t>(e), F.end());
      std::sort(sliding.begin(), sliding.end());
      const auto percentile = [&](double q) {
        return sliding[static_cast<std::size_t>(q * static_cast<double>(sliding.size() - 1))];
      };
      if (e < n && n - e >= o.min_sliding_samples &&
          percentile(0.95) - percentile(0.05) <= o.max_sliding_spread_fraction * F[p]) {
        s.through = true;
        s.sliding_index = e;
        s.sliding_samples = n - e;
        double sum = 0.0;
        for (std::size_t i = e; i < n; ++i) sum += F[i];
        s.sliding_force_N = sum / static_cast<double>(n - e);
      }
    }
  }
  const std::size_t end_c = p, end_d = s.through ? s.sliding_index : p;
  s.stage_work_J[0] = work_of_samples(c, 0, s.puncture_index);
  s.stage_work_J[1] = work_of_samples(c, s.puncture_index, s.relaxed_index);
  s.stage_work_J[2] = work_of_samples(c, s.relaxed_index, end_c);
  s.stage_work_J[3] = s.through ? work_of_samples(c, p, end_d) : 0.0;
  s.stage_work_J[4] = s.through ? work_of_samples(c, end_d, n - 1) : 0.0;
  return s;
}

CrackWidthFit fit_crack_width(std::span<const std::pair<double, double>> pairs, double d) {
  if (!(d > 0.0) || !std::isfinite(d))
    throw InputError("--depth: the block depth must be a positive length");
  if (pairs.empty()) throw InputError("--crack-widths: no depth:width pair given");
  std::vector<double> depths;
  for (const auto& [z, w] : pairs) {
    if (!(w > 0.0) || !std::isfinite(w))
      throw InputError("--crack-widths: width " + length(w) + " at " + length(z) +
                       " is not a positive length");
    if (!(z >= 0.0 && z <= d))
      throw InputError("--crack-widths: depth " + length(z) + " lies outside the block (0 to " +
                       length(d) + ")");
    if (std::find(depths.begin(), depths.end(), z) == depths.end()) depths.push_back(z);
  }
  const int degree = static_cast<int>(std::min<std::size_t>(2, depths.size() - 1));
  // Least squares in z/d, so that the columns are of one size whatever the unit.
  Eigen::MatrixXd A(static_cast<Eigen::Index>(pairs.size()), degree + 1);
  Eigen::VectorXd b(static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const double t = pairs[i].first / d;
    for (int k = 0; k <= degree; ++k) A(static_cast<Eigen::Index>(i), k) = std::pow(t, k);
    b(static_cast<Eigen::Index>(i)) = pairs[i].second;
  }
  const Eigen::VectorXd a = A.colPivHouseholderQr().solve(b);
  CrackWidthFit fit;
  double mean = 0.0;
  for (int k = 0; k <= degree; ++k) {
    fit.coefficients.push_back(a(k) / std::pow(d, k));
    mean += a(k) / (k + 1);  // (1/d) ∫0^d (z/d)^k dz = 1/(k+1)
  }
  fit.mean_width_m = mean;
  // The polynomial's smallest value on [0, d]: at an end or at the quadratic's vertex.
  double lowest = std::min(polynomial(fit.coefficients, 0.0), polynomial(fit.coefficients, d));
  if (degree == 2 && a(2) > 0.0) {
    const double t = -a(1) / (2.0 * a(2));
    if (t > 0.0 && t < 1.0) lowest = std::min(lowest, polynomial(fit.coefficients, t * d));
  }
  fit.min_width_m = lowest;
  for (const auto& [z, w] : pairs)
    fit.max_residual_m =
        std::max(fit.max_residual_m, std::abs(polynomial(fit.coefficients, z) - w));
  if (!(lowest > 0.0))
    throw InputError("--crack-widths: the fitted width falls to " + length(lowest) +
                     " inside the block: measure more depths, or give --crack-width");
  return fit;
}

EnergyBalance energy_balance(const ForceCurve& c, const InsertionStages& s,
                             const EnergyBalanceInputs& in) {
  check_curve(c);
  const auto positive = [&](double v, const char* what) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw InputError(c.source + ": " + what + " must be positive and finite");
  };
  positive(in.block_depth_m, "the block depth (--depth)");
  positive(in.mean_crack_width_m, "the mean crack width");
  if (!(in.strain_energy_J_per_m >= 0.0) || !std::isfinite(in.strain_energy_J_per_m))
    throw InputError(c.source + ": the strain energy per length must be >= 0 and finite");
  EnergyBalance e;
  e.cut_end_m = c.depth_m[s.peak_index];
  e.cut_start_m = e.cut_end_m - in.block_depth_m;
  if (e.cut_start_m < c.depth_m.front())
    throw InputError(c.source + ": the force peaks " + length(e.cut_end_m) +
                     " after contact, less than the block depth " + length(in.block_depth_m) +
                     ": the needle did not cut through the block (or --depth is wrong)");
  if (in.friction_force_N) {
    positive(*in.friction_force_N, "the friction force (--friction-force)");
    e.friction_force_N = *in.friction_force_N;
  } else if (s.through) {
    e.friction_force_N = s.sliding_force_N;
    e.friction_from_record = true;
  } else {
    throw InputError(c.source + ": no sliding stage after the peak at " + length(e.cut_end_m) +
                     " (the record ends while cutting): give --friction-force");
  }
  e.external_work_J = work_between(c, e.cut_start_m, e.cut_end_m);
  e.friction_work_J = 0.5 * e.friction_force_N * in.block_depth_m;
  e.strain_work_J = in.strain_energy_J_per_m * in.block_depth_m;
  e.crack_work_J = e.external_work_J - e.friction_work_J - e.strain_work_J;
  e.toughness_J_per_m2 = e.crack_work_J / (in.mean_crack_width_m * in.block_depth_m);
  return e;
}

}  // namespace mneedle
