#include "mneedle/measurement/anova.h"

#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/special_functions/gamma.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include "mneedle/base/csv.h"
#include "mneedle/base/error.h"

namespace mneedle {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double normal_pdf(double z) {
  return std::exp(-0.5 * z * z) / std::sqrt(2.0 * std::numbers::pi);
}

// log density of s = sqrt(chi^2_df / df), without its constant
// 0.5 df log df - lgamma(df / 2) - (df / 2 - 1) log 2.
double log_scale_density_shape(double s, double df) {
  return (df - 1.0) * std::log(s) - 0.5 * df * s * s;
}

double log_scale_density_constant(double df) {
  return 0.5 * df * std::log(df) - std::lgamma(0.5 * df) - (0.5 * df - 1.0) * std::log(2.0);
}

std::size_t column_index(const std::vector<std::string>& header, const std::string& name,
                         const std::string& where) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  std::string names;
  for (const auto& h : header) names += (names.empty() ? "" : ", ") + h;
  throw InputError(where + ": no column '" + name + "' (columns: " + names + ")");
}

// Squares of values beyond this overflow (and sums of them lose the group's spread).
constexpr double kLargestValue = 1e150;

AnovaTable anova_table(const std::vector<GroupSummary>& groups, std::size_t total) {
  // F and p are computed on the values over their largest magnitude, so that neither 1e200 nor
  // 1e-200 overflows or underflows when squared; the sums of squares are then scaled back.
  double scale = 0.0;
  for (const auto& g : groups) scale = std::max({scale, std::abs(g.mean), g.sd});
  if (!(scale <= kLargestValue))
    throw InputError(
        "ANOVA: values beyond 1e150 in magnitude (their squares overflow); "
        "give the column in a larger unit");
  if (!(scale > 0.0)) scale = 1.0;
  double grand = 0.0;
  for (const auto& g : groups) grand += g.mean / scale * static_cast<double>(g.n);
  grand /= static_cast<double>(total);
  double between = 0.0, within = 0.0;  // in units of scale^2
  for (const auto& g : groups) {
    const double offset = g.mean / scale - grand, spread = g.sd / scale;
    between += static_cast<double>(g.n) * offset * offset;
    within += spread * spread * static_cast<double>(g.n - 1);
  }
  AnovaTable t;
  t.df_between = groups.size() - 1;
  t.df_within = total - groups.size();
  if (!(within > 0.0)) {
    throw InputError("ANOVA: no variance within the groups (all values of each group equal)");
  }
  t.ss_between = between * scale * scale;
  t.ss_within = within * scale * scale;
  t.ms_between = t.ss_between / static_cast<double>(t.df_between);
  t.ms_within = t.ss_within / static_cast<double>(t.df_within);
  t.root_ms_within = std::sqrt(within / static_cast<double>(t.df_within)) * scale;
  t.f = (between / static_cast<double>(t.df_between)) / (within / static_cast<double>(t.df_within));
  const boost::math::fisher_f_distribution<double> dist(static_cast<double>(t.df_between),
                                                        static_cast<double>(t.df_within));
  t.p = boost::math::cdf(boost::math::complement(dist, t.f));
  return t;
}

}  // namespace

StudentizedRange::StudentizedRange(int k, double df) : df_(df) {
  if (k < 2) throw InputError("studentized range: k = " + std::to_string(k) + " must be >= 2");
  if (!(df > 0.0)) throw InputError("studentized range: df must be > 0");
  // The range cdf W(w) = k int phi(z) [Phi(z) - Phi(z - w)]^(k-1) dz, its density
  // W'(w) = k (k-1) int phi(z) phi(z - w) [Phi(z) - Phi(z - w)]^(k-2) dz and W'', tabulated at w =
  // m h by the trapezoidal rule on z = i h: the integrands are entire functions decaying like a
  // Gaussian, for which that rule converges exponentially (a step of h leaves an error of about
  // exp(-2 pi^2 sigma^2 / h^2), sigma >= 0.25 the width of the integrand's peak), and with the
  // same step in z and w every Phi(z - w) is a Phi of the grid.
  const double h = kRangeStep;
  // W(w) >= 1 - k (k-1) Phi(-w / sqrt 2) (a pair of the k at least w apart): the table ends
  // where that bound is below 1e-17.
  const double pairs = static_cast<double>(k) * static_cast<double>(k - 1);
  double w_end = 1.0;
  while (pairs * 0.5 * std::erfc(w_end / 2.0) > 1e-17) w_end += 0.5;
  const auto steps = static_cast<std::ptrdiff_t>(std::ceil(w_end / h));
  // phi(z) is below 1e-18 outside [-9, 9].
  const auto half = static_cast<std::ptrdiff_t>(std::ceil(9.0 / h));
  // Grid z_i = (i - half - steps) h, i = 0 .. 2 half + steps: z from -9 - w_end to 9.
  const std::ptrdiff_t offset = half + steps;
  const std::ptrdiff_t size = 2 * half + steps + 1;
  std::vector<double> lower(static_cast<std::size_t>(size)), upper(lower), density(lower);
  for (std::ptrdiff_t i = 0; i < size; ++i) {
    const double z = static_cast<double>(i - offset) * h;
    lower[static_cast<std::size_t>(i)] = 0.5 * std::erfc(-z / std::numbers::sqrt2);
    upper[static_cast<std::size_t>(i)] = 0.5 * std::erfc(z / std::numbers::sqrt2);
    density[static_cast<std::size_t>(i)] = normal_pdf(z);
  }
  range_cdf_.assign(static_cast<std::size_t>(steps) + 1, 0.0);
  range_pdf_.assign(range_cdf_.size(), 0.0);
  range_slope_.assign(range_cdf_.size(), 0.0);
  const double others = static_cast<double>(k - 2);
  for (std::ptrdiff_t m = 0; m <= steps; ++m) {
    const double w = static_cast<double>(m) * h;
    double cdf = 0.0, pdf = 0.0, slope = 0.0;
    for (std::ptrdiff_t i = offset - half; i <= offset + half; ++i) {
      const auto at = static_cast<std::size_t>(i);
      const auto shifted = static_cast<std::size_t>(i - m);
      // G = Phi(z) - Phi(z - w), from the tail that keeps its digits.
      const double inside =
          std::max(0.0, i >= offset ? upper[shifted] - upper[at] : lower[at] - lower[shifted]);
      // G^(k-3) and G^(k-2), with 0^0 = 1 (W'(0) > 0 for k = 2, W''(0) > 0 for k = 3).
      const double power3 = k == 2 ? 0.0 : std::pow(inside, others - 1.0);
      const double power2 = k == 2 ? 1.0 : power3 * inside;
      const double z = static_cast<double>(i - offset) * h;
      cdf += density[at] * power2 * inside;
      pdf += density[at] * density[shifted] * power2;
      // d/dw of phi(z - w) G^(k-2): (z - w) phi(z - w) G^(k-2) + (k-2) phi(z - w)^2 G^(k-3).
      slope +=
          density[at] * density[shifted] * ((z - w) * power2 + others * density[shifted] * power3);
    }
    range_cdf_[static_cast<std::size_t>(m)] = std::min(1.0, static_cast<double>(k) * h * cdf);
    range_pdf_[static_cast<std::size_t>(m)] = pairs * h * pdf;
    range_slope_[static_cast<std::size_t>(m)] = pairs * h * slope;
  }
  if (std::isfinite(df)) log_constant_ = log_scale_density_constant(df);
}

namespace {

// Quintic Hermite interpolation in a table of f, f' and f'' at x = m h, cell m, t = x / h - m:
// the value and its first two derivatives.
StudentizedRange::Smooth quintic(const std::vector<double>& f, const std::vector<double>& d,
                                 const std::vector<double>& c, double h, std::size_t m, double t) {
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  const double f0 = f[m], f1 = f[m + 1];
  const double d0 = h * d[m], d1 = h * d[m + 1];
  const double c0 = h * h * c[m], c1 = h * h * c[m + 1];
  StudentizedRange::Smooth out;
  out.value = (1 - 10 * t3 + 15 * t4 - 6 * t5) * f0 + (t - 6 * t3 + 8 * t4 - 3 * t5) * d0 +
              (0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5) * c0 + (0.5 * t3 - t4 + 0.5 * t5) * c1 +
              (-4 * t3 + 7 * t4 - 3 * t5) * d1 + (10 * t3 - 15 * t4 + 6 * t5) * f1;
  out.slope = ((-30 * t2 + 60 * t3 - 30 * t4) * f0 + (1 - 18 * t2 + 32 * t3 - 15 * t4) * d0 +
               (t - 4.5 * t2 + 6 * t3 - 2.5 * t4) * c0 + (1.5 * t2 - 4 * t3 + 2.5 * t4) * c1 +
               (-12 * t2 + 28 * t3 - 15 * t4) * d1 + (30 * t2 - 60 * t3 + 30 * t4) * f1) /
              h;
  out.curve = ((-60 * t + 180 * t2 - 120 * t3) * f0 + (-36 * t + 96 * t2 - 60 * t3) * d0 +
               (1 - 9 * t + 18 * t2 - 10 * t3) * c0 + (3 * t - 12 * t2 + 10 * t3) * c1 +
               (-24 * t + 84 * t2 - 60 * t3) * d1 + (60 * t - 180 * t2 + 120 * t3) * f1) /
              (h * h);
  return out;
}

}  // namespace

StudentizedRange::Smooth StudentizedRange::range_cdf(double w) const {
  if (!(w > 0.0)) return {0.0, range_pdf_.front(), range_slope_.front()};
  const double x = w / kRangeStep;
  const auto m = static_cast<std::size_t>(x);
  if (m + 1 >= range_cdf_.size()) return {1.0, 0.0, 0.0};
  return quintic(range_cdf_, range_pdf_, range_slope_, kRangeStep, m, x - static_cast<double>(m));
}

double StudentizedRange::over_scale(const std::function<double(double)>& g, double tolerance,
                                    double upper) const {
  // int_0^inf f(s) g(s) ds, f the density of s, the scaled chi of the variance estimate.
  const auto integrand = [&](double s) {
    return s <= 0.0 ? 0.0 : std::exp(log_constant_ + log_scale_density_shape(s, df_)) * g(s);
  };
  using boost::math::quadrature::gauss_kronrod;
  // The density of s is concentrated near 1 with spread ~ 1/sqrt(2 df); split there.
  const double spread = 1.0 / std::sqrt(2.0 * df_);
  const double end = 1.0 + 40.0 * spread + 10.0 / df_;
  // Each piece to an absolute error of about `tolerance`: one 61-point Gauss–Kronrod rule,
  // refined adaptively (relative tolerance 1e-11, or as coarse as `tolerance` allows) only when
  // its error estimate is larger. A relative tolerance alone would refine a tiny P(Q <= q) (most
  // pairs of many similar groups: p near 1) to digits no p-value shows.
  const auto piece = [&](double a, double b) {
    double error = 0.0, size = 0.0;
    const double rough =
        gauss_kronrod<double, 61>::integrate(integrand, a, b, 0, 0.0, &error, &size);
    if (error <= tolerance) return rough;
    const double relative = std::max(1e-11, tolerance / std::max(size, 1e-300));
    return gauss_kronrod<double, 61>::integrate(integrand, a, b, 12, relative);
  };
  double total = 0.0;
  double a = 0.0;
  for (double b : {std::max(0.0, 1.0 - 3.0 * spread), 1.0 + 3.0 * spread, end}) {
    b = std::min(b, upper);
    if (b > a) total += piece(a, b);
    a = std::max(a, b);
  }
  return total;
}

bool StudentizedRange::direct() const {
  return std::isinf(df_) || df_ > 1e5;
}

void StudentizedRange::tabulate_cdf() {
  if (direct() || !cdf_table_.empty()) return;
  // P(q) = int f(s) W(q s) ds, P'(q) = int f(s) s W'(q s) ds, P''(q) = int f(s) s^2 W''(q s) ds
  // at q = m h over the range table's length. The interpolation weighs P' by h times at most
  // 0.1 and P'' by h^2 times at most 0.01, so these need 1e-10 and 1e-8 for 1e-12 in P (and
  // W'' of the quintic, continuous but with kinks at the table points, would hold an adaptive
  // rule at its depth limit for more).
  const std::size_t n = range_cdf_.size();
  std::vector<double> value(n), slope(n), curve(n);
  for (std::size_t m = 0; m < n; ++m) {
    const double q = static_cast<double>(m) * kRangeStep;
    value[m] = over_scale([&](double s) { return range_cdf(q * s).value; }, 1e-12);
    slope[m] = over_scale([&](double s) { return s * range_cdf(q * s).slope; }, 1e-10);
    curve[m] = over_scale([&](double s) { return s * s * range_cdf(q * s).curve; }, 1e-8);
  }
  cdf_table_ = std::move(value);
  cdf_slope_ = std::move(slope);
  cdf_curve_ = std::move(curve);
}

double StudentizedRange::cdf(double q) const {
  if (!(q > 0.0)) return 0.0;
  if (direct()) return std::clamp(range_cdf(q).value, 0.0, 1.0);
  const double x = q / kRangeStep;
  const auto m = static_cast<std::size_t>(x);
  if (m + 1 < cdf_table_.size()) {
    return std::clamp(
        quintic(cdf_table_, cdf_slope_, cdf_curve_, kRangeStep, m, x - static_cast<double>(m))
            .value,
        0.0, 1.0);
  }
  // P(Q <= q) = int_0^inf f(s) W(q s) ds, and W(q s) = 1 from s = w_end / q on (the end of the
  // range table): that part is P(s > w_end / q), a regularised incomplete gamma function since
  // df s^2 is chi-squared with df degrees of freedom. For a large q (most pairs of groups far
  // apart) it is all there is.
  const double from = static_cast<double>(range_cdf_.size() - 1) * kRangeStep / q;
  const double below = boost::math::gamma_p(0.5 * df_, 0.5 * df_ * from * from);
  if (below < 1e-13) return 1.0 - below;
  const double loaded = over_scale([&](double s) { return range_cdf(q * s).value; }, 1e-12, from);
  return std::clamp(loaded + (1.0 - below), 0.0, 1.0);
}

double StudentizedRange::quantile(double p) const {
  if (!(p > 0.0 && p < 1.0)) throw InputError("studentized range quantile: p must lie in (0, 1)");
  double hi = 1.0;
  while (cdf(hi) < p) hi *= 2.0;
  const auto gap = [&](double q) { return cdf(q) - p; };
  std::uintmax_t iterations = 100;
  const auto [lo_q, hi_q] = boost::math::tools::toms748_solve(
      gap, 0.0, hi, -p, gap(hi), boost::math::tools::eps_tolerance<double>(36), iterations);
  return 0.5 * (lo_q + hi_q);
}

double studentized_range_cdf(double q, int k, double df) {
  return StudentizedRange(k, df).cdf(q);
}

double studentized_range_quantile(double p, int k, double df) {
  return StudentizedRange(k, df).quantile(p);
}

OneWayAnova one_way_anova(const std::vector<std::string>& labels, const std::vector<double>& values,
                          double alpha) {
  if (labels.size() != values.size()) throw InputError("ANOVA: labels and values differ in length");
  if (!(alpha > 0.0 && alpha < 1.0)) throw InputError("ANOVA: alpha must lie in (0, 1)");
  OneWayAnova out;
  out.alpha = alpha;
  std::map<std::string, std::size_t> index;
  std::vector<std::vector<double>> members;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw InputError("ANOVA: value " + std::to_string(i + 1) + " is not finite");
    auto [it, inserted] = index.emplace(labels[i], members.size());
    if (inserted) {
      members.emplace_back();
      out.groups.push_back({labels[i]});
    }
    members[it->second].push_back(values[i]);
  }
  if (out.groups.size() < 2) throw InputError("ANOVA: needs at least two groups");
  if (values.size() <= out.groups.size()) {
    throw InputError("ANOVA: no degrees of freedom within groups (" +
                     std::to_string(values.size()) + " values in " +
                     std::to_string(out.groups.size()) + " groups)");
  }
  // Means and spreads on the values over their largest magnitude: squares of 1e200 overflow
  // and of 1e-200 underflow (anova_table refuses beyond kLargestValue).
  double scale = 0.0;
  for (double v : values) scale = std::max(scale, std::abs(v));
  if (!(scale <= kLargestValue))
    throw InputError(
        "ANOVA: values beyond 1e150 in magnitude (their squares overflow); "
        "give the column in a larger unit");
  if (!(scale > 0.0)) scale = 1.0;
  for (std::size_t g = 0; g < members.size(); ++g) {
    auto& s = out.groups[g];
    s.n = members[g].size();
    double mean = 0.0, ss = 0.0;
    for (double v : members[g]) mean += v / scale;
    mean /= static_cast<double>(s.n);
    for (double v : members[g]) ss += (v / scale - mean) * (v / scale - mean);
    s.mean = mean * scale;
    s.sd = s.n > 1 ? std::sqrt(ss / static_cast<double>(s.n - 1)) * scale : 0.0;
  }
  out.anova = anova_table(out.groups, values.size());
  const int k = static_cast<int>(out.groups.size());
  const double df = static_cast<double>(out.anova.df_within);
  // k and df are the same for every pair: one table serves them all.
  StudentizedRange range(k, df);
  // Tabulating P costs three integrals per table point; worth it beyond that many pairs.
  const std::size_t pairs = out.groups.size() * (out.groups.size() - 1) / 2;
  if (pairs > 3 * range.table_points()) range.tabulate_cdf();
  out.q_critical = range.quantile(1.0 - alpha);
  for (std::size_t i = 0; i < out.groups.size(); ++i) {
    for (std::size_t j = i + 1; j < out.groups.size(); ++j) {
      const auto& a = out.groups[i];
      const auto& b = out.groups[j];
      TukeyComparison c{a.name, b.name, a.mean - b.mean};
      // Tukey–Kramer standard error of a difference of means.
      const double se =
          out.anova.root_ms_within *
          std::sqrt(0.5 * (1.0 / static_cast<double>(a.n) + 1.0 / static_cast<double>(b.n)));
      c.p_adjusted = std::clamp(1.0 - range.cdf(std::abs(c.mean_difference) / se), 0.0, 1.0);
      c.ci_low = c.mean_difference - out.q_critical * se;
      c.ci_high = c.mean_difference + out.q_critical * se;
      c.reject = c.p_adjusted < alpha;
      out.tukey.push_back(c);
    }
  }
  return out;
}

void read_grouped_csv(const std::filesystem::path& file, const std::string& value_column,
                      const std::string& group_column, std::vector<std::string>& labels,
                      std::vector<double>& values) {
  const CsvTable table = read_csv(file);
  const std::size_t vi = column_index(table.header, value_column, table.where(table.header_line));
  const std::size_t gi = column_index(table.header, group_column, table.where(table.header_line));
  for (const auto& row : table.rows) {
    const auto& fields = row.fields;
    const std::string here = table.where(row.line);
    double v = 0.0;
    const auto& text = fields[vi];
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() ||
        !std::isfinite(v)) {
      throw InputError(here + ": column '" + value_column + "': '" + text + "' is not a number");
    }
    // A blank cell is no group's name (it became a group called "").
    if (fields[gi].find_first_not_of(" \t") == std::string::npos)
      throw InputError(here + ": column '" + group_column + "': no group name");
    labels.push_back(fields[gi]);
    values.push_back(v);
  }
}

}  // namespace mneedle
