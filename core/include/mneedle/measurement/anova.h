#pragma once
// One-way analysis of variance and Tukey's honestly significant difference test (Tukey–Kramer
// for unequal group sizes), as paper B compares puncture forces between speeds and angles.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace mneedle {

struct GroupSummary {
  std::string name;
  std::size_t n = 0;
  double mean = 0.0;
  double sd = 0.0;  ///< sample standard deviation (0 for a single value)
};

struct AnovaTable {
  double ss_between = 0.0;
  double ss_within = 0.0;
  std::size_t df_between = 0;
  std::size_t df_within = 0;
  double ms_between = 0.0;
  double ms_within = 0.0;
  /// sqrt(ms_within), found without squaring the values' unit (so it does not underflow where
  /// ms_within does: values of 1e-200)
  double root_ms_within = 0.0;
  double f = 0.0;
  double p = 1.0;  ///< P(F' > f) for F' ~ F(df_between, df_within)
};

struct TukeyComparison {
  std::string group1;
  std::string group2;
  double mean_difference = 0.0;  ///< mean(group1) - mean(group2), paper B's convention
  double p_adjusted = 1.0;       ///< family-wise adjusted p (studentized range)
  double ci_low = 0.0;           ///< simultaneous (1 - alpha) interval of the difference
  double ci_high = 0.0;
  bool reject = false;  ///< p_adjusted < alpha: the means differ
};

struct OneWayAnova {
  std::vector<GroupSummary> groups;  ///< in order of first appearance
  AnovaTable anova;
  std::vector<TukeyComparison> tukey;  ///< every pair (i < j in group order)
  double alpha = 0.05;
  double q_critical = 0.0;  ///< studentized range quantile q(1 - alpha; k, df_within)
};

/// Runs the ANOVA and every Tukey comparison. Throws InputError when the labels and values differ
/// in length, there are fewer than two groups, no degrees of freedom within groups, or no
/// variance within groups (the F ratio would be infinite).
OneWayAnova one_way_anova(const std::vector<std::string>& labels, const std::vector<double>& values,
                          double alpha = 0.05);

/// The studentized range distribution of k means with df degrees of freedom of the variance
/// estimate (df may be infinity). Construction tabulates the range distribution of k standard
/// normals once (about 30 to 90 ms for k from 10 to 5000), so that each cdf after it is one
/// integral over the variance estimate (about 20 us): build one per (k, df) and evaluate every
/// pair of a Tukey test with it (docs/model.md, "Statistics").
class StudentizedRange {
 public:
  /// Throws InputError for k < 2 or df <= 0.
  StudentizedRange(int k, double df);
  /// P(Q <= q); about 1e-12 absolute accuracy.
  double cdf(double q) const;
  /// The q with cdf(q) = p, for 0 < p < 1.
  double quantile(double p) const;
  /// Tabulates P(Q <= q) with its first two derivatives on the range table's grid (three
  /// integrals per point), after which cdf(q) inside it is an interpolation, not an integral:
  /// worth it for more than about 3 table_points() evaluations.
  void tabulate_cdf();
  std::size_t table_points() const { return range_cdf_.size(); }

  struct Smooth {
    double value = 0.0, slope = 0.0, curve = 0.0;  ///< f, f', f''
  };

 private:
  /// Step of the tables in w and q and of the trapezoidal rule in z.
  static constexpr double kRangeStep = 0.02;
  Smooth range_cdf(double w) const;  ///< W, W', W'' (quintic Hermite); 1, 0, 0 beyond the table
  /// int_0^upper f_s(s) g(s) ds to about `tolerance` absolute (f_s negligible beyond the default).
  double over_scale(const std::function<double(double)>& g, double tolerance,
                    double upper = std::numeric_limits<double>::infinity()) const;
  bool direct() const;  ///< df infinite (or > 1e5): P(Q <= q) = W(q)
  double df_;
  double log_constant_ = 0.0;        ///< log normalisation of the density of the variance estimate
  std::vector<double> range_cdf_;    ///< W(m h)
  std::vector<double> range_pdf_;    ///< W'(m h)
  std::vector<double> range_slope_;  ///< W''(m h)
  std::vector<double> cdf_table_, cdf_slope_, cdf_curve_;  ///< P, P', P'' at q = m h, if tabulated
};

/// P(Q <= q) for the studentized range of k means with df degrees of freedom of the variance
/// estimate (df may be infinity): StudentizedRange(k, df).cdf(q).
double studentized_range_cdf(double q, int k, double df);

/// The q with studentized_range_cdf(q, k, df) = p, for 0 < p < 1:
/// StudentizedRange(k, df).quantile(p).
double studentized_range_quantile(double p, int k, double df);

/// Grouped values from a CSV with a header: one text column of group names and one numeric
/// column. Throws InputError naming file:line for a missing column or a value that is not a
/// number.
void read_grouped_csv(const std::filesystem::path& file, const std::string& value_column,
                      const std::string& group_column, std::vector<std::string>& labels,
                      std::vector<double>& values);

}  // namespace mneedle
