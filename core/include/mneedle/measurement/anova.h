#pragma once
// One-way analysis of variance and Tukey's honestly significant difference test (Tukey–Kramer
// for unequal group sizes), as paper B compares puncture forces between speeds and angles.

#include <cstddef>
#include <filesystem>
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

/// P(Q <= q) for the studentized range of k means with df degrees of freedom of the variance
/// estimate (df may be infinity). Numerical integration; about 1e-8 absolute accuracy.
double studentized_range_cdf(double q, int k, double df);

/// The q with studentized_range_cdf(q, k, df) = p, for 0 < p < 1.
double studentized_range_quantile(double p, int k, double df);

/// Grouped values from a CSV with a header: one text column of group names and one numeric
/// column. Throws InputError naming file:line for a missing column or a value that is not a
/// number.
void read_grouped_csv(const std::filesystem::path& file, const std::string& value_column,
                      const std::string& group_column, std::vector<std::string>& labels,
                      std::vector<double>& values);

}  // namespace mneedle
