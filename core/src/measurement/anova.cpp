#include "mneedle/measurement/anova.h"

#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <charconv>
#include <cmath>
#include <fstream>
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
double normal_cdf(double z) {
  return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

// P(range of k standard normals <= w) = k int phi(z) [Phi(z) - Phi(z - w)]^(k-1) dz.
double normal_range_cdf(double w, int k) {
  if (w <= 0.0) return 0.0;
  const auto integrand = [&](double z) {
    const double inside = normal_cdf(z) - normal_cdf(z - w);
    return normal_pdf(z) * std::pow(std::max(inside, 0.0), k - 1);
  };
  // phi(z) is negligible outside [-9, 9 + w] for the accuracy wanted.
  using boost::math::quadrature::gauss_kronrod;
  const double value = gauss_kronrod<double, 31>::integrate(integrand, -9.0, 0.5 * w, 10, 1e-11) +
                       gauss_kronrod<double, 31>::integrate(integrand, 0.5 * w, 9.0 + w, 10, 1e-11);
  return std::min(1.0, k * value);
}

// log density of s = sqrt(chi^2_df / df).
double log_scale_density(double s, double df) {
  return 0.5 * df * std::log(df) - std::lgamma(0.5 * df) - (0.5 * df - 1.0) * std::log(2.0) +
         (df - 1.0) * std::log(s) - 0.5 * df * s * s;
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

AnovaTable anova_table(const std::vector<GroupSummary>& groups, std::size_t total) {
  double grand = 0.0;
  for (const auto& g : groups) grand += g.mean * static_cast<double>(g.n);
  grand /= static_cast<double>(total);
  AnovaTable t;
  for (const auto& g : groups) {
    t.ss_between += static_cast<double>(g.n) * (g.mean - grand) * (g.mean - grand);
    t.ss_within += g.sd * g.sd * static_cast<double>(g.n - 1);
  }
  t.df_between = groups.size() - 1;
  t.df_within = total - groups.size();
  t.ms_between = t.ss_between / static_cast<double>(t.df_between);
  t.ms_within = t.ss_within / static_cast<double>(t.df_within);
  if (!(t.ms_within > 0.0)) {
    throw InputError("ANOVA: no variance within the groups (all values of each group equal)");
  }
  t.f = t.ms_between / t.ms_within;
  const boost::math::fisher_f_distribution<double> dist(static_cast<double>(t.df_between),
                                                        static_cast<double>(t.df_within));
  t.p = boost::math::cdf(boost::math::complement(dist, t.f));
  return t;
}

}  // namespace

double studentized_range_cdf(double q, int k, double df) {
  if (k < 2) throw InputError("studentized range: k = " + std::to_string(k) + " must be >= 2");
  if (!(df > 0.0)) throw InputError("studentized range: df must be > 0");
  if (!(q > 0.0)) return 0.0;
  if (std::isinf(df) || df > 1e5) return normal_range_cdf(q, k);
  // P(Q <= q) = int_0^inf f(s) P(range <= q s) ds, s the scaled chi of the variance estimate.
  const auto integrand = [&](double s) {
    return s <= 0.0 ? 0.0 : std::exp(log_scale_density(s, df)) * normal_range_cdf(q * s, k);
  };
  using boost::math::quadrature::gauss_kronrod;
  // The density of s is concentrated near 1 with spread ~ 1/sqrt(2 df); split there.
  const double spread = 1.0 / std::sqrt(2.0 * df);
  const double upper = 1.0 + 40.0 * spread + 10.0 / df;
  double total = 0.0;
  double a = 0.0;
  for (double b : {std::max(0.0, 1.0 - 3.0 * spread), 1.0 + 3.0 * spread, upper}) {
    if (b > a) total += gauss_kronrod<double, 61>::integrate(integrand, a, b, 12, 1e-11);
    a = std::max(a, b);
  }
  return std::clamp(total, 0.0, 1.0);
}

double studentized_range_quantile(double p, int k, double df) {
  if (!(p > 0.0 && p < 1.0)) throw InputError("studentized range quantile: p must lie in (0, 1)");
  double hi = 1.0;
  while (studentized_range_cdf(hi, k, df) < p) hi *= 2.0;
  const auto gap = [&](double q) { return studentized_range_cdf(q, k, df) - p; };
  std::uintmax_t iterations = 100;
  const auto [lo_q, hi_q] = boost::math::tools::toms748_solve(
      gap, 0.0, hi, -p, gap(hi), boost::math::tools::eps_tolerance<double>(36), iterations);
  return 0.5 * (lo_q + hi_q);
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
  for (std::size_t g = 0; g < members.size(); ++g) {
    auto& s = out.groups[g];
    s.n = members[g].size();
    for (double v : members[g]) s.mean += v;
    s.mean /= static_cast<double>(s.n);
    double ss = 0.0;
    for (double v : members[g]) ss += (v - s.mean) * (v - s.mean);
    s.sd = s.n > 1 ? std::sqrt(ss / static_cast<double>(s.n - 1)) : 0.0;
  }
  out.anova = anova_table(out.groups, values.size());
  const int k = static_cast<int>(out.groups.size());
  const double df = static_cast<double>(out.anova.df_within);
  out.q_critical = studentized_range_quantile(1.0 - alpha, k, df);
  for (std::size_t i = 0; i < out.groups.size(); ++i) {
    for (std::size_t j = i + 1; j < out.groups.size(); ++j) {
      const auto& a = out.groups[i];
      const auto& b = out.groups[j];
      TukeyComparison c{a.name, b.name, a.mean - b.mean};
      // Tukey–Kramer standard error of a difference of means.
      const double se =
          std::sqrt(out.anova.ms_within / 2.0 *
                    (1.0 / static_cast<double>(a.n) + 1.0 / static_cast<double>(b.n)));
      c.p_adjusted = std::clamp(
          1.0 - studentized_range_cdf(std::abs(c.mean_difference) / se, k, df), 0.0, 1.0);
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
    labels.push_back(fields[gi]);
    values.push_back(v);
  }
}

}  // namespace mneedle
