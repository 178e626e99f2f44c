// fit as a library call: a recording read with its units, the fit's JSON with its parameters,
// errors and per-curve metrics; bad input is a one-line error naming the file or the setting.
#include "mneedle/api/fit_report.h"

#include <gtest/gtest.h>

#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

const std::string kCurve = std::string(MNEEDLE_TEST_ASSETS) + "/curves/loading_hold_retraction.csv";

TEST(FitReport, FixedParameterTakesTheUnitItsNameImplies) {
  EXPECT_DOUBLE_EQ(parse_fixed_parameter("K0_N=2mN").second, 2e-3);
  EXPECT_DOUBLE_EQ(parse_fixed_parameter("start_m_L1=1.5mm").second, 1.5e-3);
  EXPECT_DOUBLE_EQ(parse_fixed_parameter("mu=0.2").second, 0.2);
  EXPECT_THROW(parse_fixed_parameter("=1"), InputError);
  EXPECT_THROW(parse_fixed_parameter("K0_N=2"), InputError);  // a force without a unit
}

TEST(FitReport, ReportHasEveryParameterAndOneEntryPerCurve) {
  FitSettings s;
  s.starts = 2;
  const FitOutcome out = fit_recordings({kCurve}, s);
  ASSERT_EQ(out.report["curves"].size(), 1u);
  EXPECT_EQ(out.report["curves"][0]["file"], "loading_hold_retraction.csv");
  EXPECT_EQ(out.report["params"].size(), out.fit.parameters.size());
  EXPECT_EQ(out.report["samples_fitted"].get<std::size_t>(), out.fit.samples);
  EXPECT_EQ(out.initial_layer_starts_m.size(), 1u);
  for (const auto& p : out.fit.parameters)
    EXPECT_EQ(out.report["params"][p.name].get<double>(), p.value) << p.name;
}

TEST(FitReport, NoFileOrABadOneIsAnInputError) {
  EXPECT_THROW(fit_recordings({}, {}), InputError);
  try {
    fit_recordings({std::string(MNEEDLE_TEST_ASSETS) + "/curves/text_in_number.csv"}, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("text_in_number.csv:"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mneedle
