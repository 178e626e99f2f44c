#include "mneedle/measurement/anova.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mneedle/base/error.h"

namespace {

// Montgomery & Runger, "Applied Statistics and Probability for Engineers", Example 13-1
// (tensile strength of paper against hardwood concentration 5/10/15/20 %, six specimens each)
// and its Minitab output, Table S13-2: F = 19.61, MS_error = 6.51, Tukey critical value 3.96,
// simultaneous 95 % intervals for (column mean - row mean).
void hardwood(std::vector<std::string>& labels, std::vector<double>& values) {
  const std::vector<std::pair<std::string, std::vector<double>>> data{
      {"5%", {7, 8, 15, 11, 9, 10}},
      {"10%", {12, 17, 13, 18, 19, 15}},
      {"15%", {14, 18, 19, 17, 16, 18}},
      {"20%", {19, 25, 22, 23, 18, 20}}};
  for (const auto& [name, xs] : data) {
    for (double x : xs) {
      labels.push_back(name);
      values.push_back(x);
    }
  }
}

TEST(Anova, HardwoodExampleMatchesMontgomeryTable) {
  std::vector<std::string> labels;
  std::vector<double> values;
  hardwood(labels, values);
  const auto r = mneedle::one_way_anova(labels, values);
  EXPECT_NEAR(r.anova.ss_between, 382.79, 0.01);
  EXPECT_NEAR(r.anova.ss_within, 130.17, 0.01);
  EXPECT_EQ(r.anova.df_between, 3u);
  EXPECT_EQ(r.anova.df_within, 20u);
  EXPECT_NEAR(r.anova.ms_within, 6.51, 0.005);
  EXPECT_NEAR(r.anova.f, 19.61, 0.005);
  EXPECT_LT(r.anova.p, 1e-4);  // Minitab prints 0.000
  EXPECT_NEAR(r.groups[1].mean, 15.667, 5e-4);
  EXPECT_NEAR(r.groups[2].sd, 1.789, 5e-4);
  EXPECT_NEAR(r.q_critical, 3.96, 0.005);
}

TEST(Anova, HardwoodTukeyIntervalsMatchMontgomeryTable) {
  std::vector<std::string> labels;
  std::vector<double> values;
  hardwood(labels, values);
  const auto r = mneedle::one_way_anova(labels, values);
  ASSERT_EQ(r.tukey.size(), 6u);
  // Order: (5,10) (5,15) (5,20) (10,15) (10,20) (15,20); difference = first - second.
  const double low[] = {-9.791, -11.124, -15.291, -5.458, -9.624, -8.291};
  const double high[] = {-1.542, -2.876, -7.042, 2.791, -1.376, -0.042};
  const bool differ[] = {true, true, true, false, true, true};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(r.tukey[i].ci_low, low[i], 0.01) << i;
    EXPECT_NEAR(r.tukey[i].ci_high, high[i], 0.01) << i;
    EXPECT_EQ(r.tukey[i].reject, differ[i]) << i;
    // A difference is significant exactly when its simultaneous interval excludes zero.
    EXPECT_EQ(r.tukey[i].reject, r.tukey[i].ci_high < 0.0 || r.tukey[i].ci_low > 0.0) << i;
  }
  EXPECT_EQ(r.tukey[0].group1, "5%");
  EXPECT_EQ(r.tukey[0].group2, "10%");
  EXPECT_NEAR(r.tukey[0].mean_difference, 10.0 - 15.6667, 1e-3);
}

// NIST/SEMATECH e-Handbook of Statistical Methods, section 7.4.3 (one-way ANOVA example):
// three groups of five, SS treatments 27.897, SS error 17.452, F = 9.59.
TEST(Anova, NistHandbookExample) {
  const std::vector<std::string> labels{"1", "1", "1", "1", "1", "2", "2", "2",
                                        "2", "2", "3", "3", "3", "3", "3"};
  const std::vector<double> values{6.9, 5.4, 5.8, 4.6,  4.0, 8.3, 6.8, 7.8,
                                   9.2, 6.5, 8.0, 10.5, 8.1, 6.9, 9.3};
  const auto r = mneedle::one_way_anova(labels, values);
  EXPECT_NEAR(r.anova.ss_between, 27.897, 1e-3);
  EXPECT_NEAR(r.anova.ss_within, 17.452, 1e-3);
  EXPECT_NEAR(r.anova.f, 9.59, 0.005);
  EXPECT_NEAR(r.q_critical, 3.773, 0.001);
}

TEST(Anova, FDistributionTailMatchesClosedFormForTwoDenominatorDegrees) {
  // F(2, 2): P(F > f) = 1 / (1 + f); groups of 1, 1 and 3 values give df = (2, 2).
  const std::vector<std::string> labels{"a", "b", "c", "c", "c"};
  const std::vector<double> values{1.0, 3.0, 2.0, 2.5, 1.0};
  const auto r = mneedle::one_way_anova(labels, values);
  ASSERT_EQ(r.anova.df_between, 2u);
  ASSERT_EQ(r.anova.df_within, 2u);
  EXPECT_NEAR(r.anova.p, 1.0 / (1.0 + r.anova.f), 1e-10);
}

// Harter (1960) tables of the studentized range, upper 5 % and 1 % points.
TEST(StudentizedRange, QuantilesMatchPublishedTables) {
  EXPECT_NEAR(mneedle::studentized_range_quantile(0.95, 3, 12), 3.773, 0.001);
  EXPECT_NEAR(mneedle::studentized_range_quantile(0.95, 4, 20), 3.958, 0.001);
  EXPECT_NEAR(mneedle::studentized_range_quantile(0.95, 5, 10), 4.654, 0.001);
  EXPECT_NEAR(mneedle::studentized_range_quantile(0.99, 3, 12), 5.046, 0.001);
  EXPECT_NEAR(mneedle::studentized_range_quantile(0.95, 10, 30), 4.824, 0.001);
}

TEST(StudentizedRange, TwoMeansWithInfiniteDfIsTheNormalDifference) {
  // Range of two standard normals = |Z1 - Z2| ~ sqrt(2) |Z|: P(Q <= 1.96 sqrt 2) = 0.95.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NEAR(mneedle::studentized_range_cdf(1.959963985 * std::sqrt(2.0), 2, inf), 0.95, 1e-8);
}

TEST(StudentizedRange, TwoMeansIsTheTwoSidedTTest) {
  // k = 2: Q = sqrt(2) |T|, T ~ t(df). t(0.975; 10) = 2.228139.
  EXPECT_NEAR(mneedle::studentized_range_cdf(2.228139 * std::sqrt(2.0), 2, 10), 0.95, 1e-6);
}

// P(Q <= q) by 25-digit quadrature of the defining double integral (mpmath 1.3:
// P = int_0^inf f_s(s) k int phi(z) [Phi(z) - Phi(z - q s)]^(k-1) dz ds, split at the peaks),
// an implementation independent of ours. 1e-12: the accuracy StudentizedRange states; the two
// agree to 4e-15 here.
TEST(StudentizedRange, CdfMatchesHighPrecisionQuadrature) {
  struct Case {
    double q;
    int k;
    double df, cdf;
  };
  for (const auto& c :
       {Case{3.5, 3, 12, 0.930004514724813574}, Case{2.5, 3, 12, 0.778400109070008115},
        Case{5.0, 3, 12, 0.989400418426442057}, Case{0.5, 4, 20, 0.0156035201059124779},
        Case{3.958, 4, 20, 0.949978788864849552}, Case{6.0, 4, 20, 0.997919356744369291}}) {
    EXPECT_NEAR(mneedle::studentized_range_cdf(c.q, c.k, c.df), c.cdf, 1e-12)
        << "q " << c.q << " k " << c.k << " df " << c.df;
  }
}

TEST(Anova, HardwoodTukeyPValuesMatchHighPrecisionQuadrature) {
  // p_adj = 1 - P(Q <= q; 4, 20) at the q of three pairs of Montgomery's example, P from the
  // same 25-digit quadrature as above; 1e-12 as above.
  std::vector<std::string> labels;
  std::vector<double> values;
  hardwood(labels, values);
  const auto r = mneedle::one_way_anova(labels, values);
  EXPECT_NEAR(r.tukey[0].p_adjusted, 1.0 - 0.994889190414608666, 1e-12);  // 5 %, 10 %: q 5.441
  EXPECT_NEAR(r.tukey[3].p_adjusted, 1.0 - 0.197772519828025554, 1e-12);  // 10 %, 15 %: q 1.280
  EXPECT_NEAR(r.tukey[5].p_adjusted, 1.0 - 0.952974884419200345, 1e-12);  // 15 %, 20 %: q 4.001
}

TEST(StudentizedRange, TabulatedCdfIsTheIntegralToTwelveDigits) {
  // Many groups: P(Q <= q) is tabulated once and interpolated for every pair. Reference: the
  // integral itself; 1e-12 as above (the interpolation error measured for k up to 5000 and df up
  // to 15000 is at most 1.3e-12, here 1e-13).
  const mneedle::StudentizedRange direct(300, 600);
  mneedle::StudentizedRange table(300, 600);
  table.tabulate_cdf();
  for (double q = 0.013; q < 40.0; q += 0.137) {
    EXPECT_NEAR(table.cdf(q), direct.cdf(q), 1e-12) << q;
  }
}

TEST(Anova, SingleGroupIsRejected) {
  EXPECT_THROW(mneedle::one_way_anova({"a", "a"}, {1.0, 2.0}), mneedle::InputError);
}

TEST(Anova, NoVarianceWithinGroupsIsRejected) {
  EXPECT_THROW(mneedle::one_way_anova({"a", "a", "b", "b"}, {1.0, 1.0, 2.0, 2.0}),
               mneedle::InputError);
}

// F, p and the Tukey intervals do not depend on the values' unit: the same data times 1e-200
// (whose squares underflow) and 1e140 give Montgomery's F to round-off, and 1e200 (whose squares
// overflow) is refused rather than failing inside the F distribution.
TEST(Anova, ResultsDoNotDependOnTheValuesScaleAndOverflowingValuesAreRefused) {
  const std::vector<std::string> labels{"a", "a", "a", "b", "b", "b", "c", "c", "c"};
  const std::vector<double> base{1.0, 2.0, 3.5, 4.0, 5.5, 6.0, 2.0, 2.5, 4.0};
  const auto reference = mneedle::one_way_anova(labels, base);
  for (const double scale : {1e-200, 1e140}) {
    std::vector<double> values;
    for (double v : base) values.push_back(v * scale);
    const auto r = mneedle::one_way_anova(labels, values);
    EXPECT_NEAR(r.anova.f, reference.anova.f, 1e-12 * reference.anova.f) << scale;
    EXPECT_NEAR(r.tukey[0].ci_low / scale, reference.tukey[0].ci_low,
                1e-12 * std::abs(reference.tukey[0].ci_low))
        << scale;
  }
  std::vector<double> huge;
  for (double v : base) huge.push_back(v * 1e200);
  EXPECT_THROW(mneedle::one_way_anova(labels, huge), mneedle::InputError);
}

TEST(Anova, GroupedCsvTextValueNamesFileAndLine) {
  std::vector<std::string> labels;
  std::vector<double> values;
  try {
    mneedle::read_grouped_csv(std::string(MNEEDLE_TEST_ASSETS) + "/curves/grouped_bad.csv",
                              "force_N", "group", labels, values);
    FAIL() << "text accepted as a number";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("grouped_bad.csv:4"), std::string::npos) << e.what();
  }
}

TEST(Anova, GroupedCsvIsRead) {
  std::vector<std::string> labels;
  std::vector<double> values;
  mneedle::read_grouped_csv(std::string(MNEEDLE_TEST_ASSETS) + "/curves/grouped.csv", "force_N",
                            "group", labels, values);
  ASSERT_EQ(values.size(), 6u);
  EXPECT_EQ(labels[3], "2mm/s");
  EXPECT_EQ(values[3], 5.3);
}

}  // namespace
