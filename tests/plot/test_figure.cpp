#include "mneedle/plot/figure.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "svg_reader.h"

namespace {

namespace fs = std::filesystem;
using mneedle::Dimension;
using mneedle::plot::Figure;
using mneedle::plot::Series;
using mneedle::test::has_text;
using mneedle::test::polyline;
using mneedle::test::texts;

const fs::path kWork =
    fs::temp_directory_path() / ("mneedle_test_figure_" + std::to_string(::getpid()));

struct ScratchCleanup {
  ~ScratchCleanup() {
    std::error_code ignored;
    fs::remove_all(kWork, ignored);
  }
} const kScratchCleanup;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Figure force_figure() {
  Figure f;
  f.title = "cone in skin";
  f.x = {"depth below the surface", Dimension::Length, "", false};
  f.y = {"force", Dimension::Force, "", false};
  Series s;
  s.label = "FE";
  for (int i = 0; i <= 40; ++i) {
    s.x.push_back(i * 5e-6);                      // 0 to 200 um
    s.y.push_back(2e-3 * std::pow(i / 40.0, 2));  // 0 to 2 mN
  }
  f.series.push_back(s);
  f.points.push_back({"puncture", 150e-6, 2e-3 * 0.5625});
  f.lines.push_back({"A|B", 150e-6});
  return f;
}

TEST(SvgElement, TwoFiguresInOnePageShareNoIdAndCarryNoXmlProlog) {
  const std::string a = mneedle::plot::svg_element(force_figure());
  const std::string b = mneedle::plot::svg_element(force_figure());
  EXPECT_EQ(a.rfind("<svg", 0), 0u);
  const auto ids = [](const std::string& svg) {
    std::vector<std::string> found;
    for (std::size_t pos = 0; (pos = svg.find(" id=\"", pos)) != std::string::npos; ++pos)
      found.push_back(svg.substr(pos + 5, svg.find('"', pos + 5) - pos - 5));
    return found;
  };
  ASSERT_FALSE(ids(a).empty());
  for (const std::string& id : ids(a)) {
    EXPECT_EQ(b.find("\"" + id + "\""), std::string::npos) << id;
    EXPECT_NE(a.find("url(#" + id + ")"), std::string::npos) << id;  // still referenced
  }
}

TEST(DisplayUnit, PicksTheUnitByMagnitude) {
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Length, 200e-6).name, "um");
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Length, 2e-3).name, "mm");
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Force, 2e-3).name, "mN");
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Force, 2.0).name, "N");
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Length, 1e-9).name, "um");
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Energy, 84e-3).name, "mJ");
  EXPECT_EQ(mneedle::plot::display_unit(Dimension::Energy, 5e-6).name, "uJ");
}

TEST(WriteSvg, AxesCarryTheirUnitsAndTheLabelsAreWritten) {
  fs::create_directories(kWork);
  const auto file = kWork / "labels.svg";
  Figure f = force_figure();
  f.series.push_back({"analytic", {0.0, 200e-6}, {0.0, 2e-3}, mneedle::plot::Mark::Line});
  mneedle::plot::write_svg(file, f);
  const auto t = texts(read(file));
  EXPECT_TRUE(has_text(t, "depth below the surface [um]"));
  EXPECT_TRUE(has_text(t, "force [mN]"));
  EXPECT_TRUE(has_text(t, "cone in skin"));
  EXPECT_TRUE(has_text(t, "puncture"));
  EXPECT_TRUE(has_text(t, "FE"));
  EXPECT_TRUE(has_text(t, "analytic"));
  EXPECT_TRUE(has_text(t, "A|B"));
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
}

TEST(WriteSvg, CurvePointsLieWhereTheAxisTicksPutTheirValues) {
  fs::create_directories(kWork);
  const auto file = kWork / "mapping.svg";
  const Figure f = force_figure();
  mneedle::plot::write_svg(file, f);
  const std::string svg = read(file);
  const auto t = texts(svg);
  // The x ticks (numbers along the bottom, all at one height) give the map um -> device x.
  std::vector<std::pair<double, double>> ticks;  // (value, device x)
  const double bottom = [&] {
    double lowest = 1e9;
    for (const auto& x : t)
      if (std::regex_match(x.text, std::regex(R"(-?[0-9.]+)"))) lowest = std::min(lowest, x.y);
    return lowest;
  }();
  for (const auto& x : t)
    if (std::abs(x.y - bottom) < 1e-6 && std::regex_match(x.text, std::regex(R"(-?[0-9.]+)")))
      ticks.emplace_back(std::stod(x.text), x.x);
  ASSERT_GE(ticks.size(), 3u);
  const double scale =
      (ticks.back().second - ticks.front().second) / (ticks.back().first - ticks.front().first);
  const double offset = ticks.front().second - scale * ticks.front().first;
  const auto line = polyline(svg, "#1F77B4");
  ASSERT_EQ(line.size(), f.series[0].x.size());
  // PLplot maps to integer internal coordinates and the svg driver writes 2 decimals: measured
  // up to 0.022 device units off the exact map; held to 0.05 (1e-4 of the 500-unit-wide box).
  for (std::size_t i = 0; i < line.size(); ++i)
    EXPECT_NEAR(line[i].first, offset + scale * f.series[0].x[i] * 1e6, 0.05) << i;
  // y: the curve is y = 2 mN (x / 200 um)^2, so device y is affine in x^2 with one slope.
  const double y0 = line.front().second, slope = (line.back().second - y0) / 1.0;
  for (std::size_t i = 0; i < line.size(); ++i)
    EXPECT_NEAR(line[i].second, y0 + slope * std::pow(i / 40.0, 2), 0.05) << i;
}

// A point's label is written rightwards from it, except in the last quarter of the x axis,
// where it would run out of the frame and be cut: a curve that ends at a marked point (simulate's
// "FE stopped") keeps its label in view.
TEST(WriteSvg, APointsLabelNearTheRightEdgeIsWrittenLeftOfIt) {
  fs::create_directories(kWork);
  const auto file = kWork / "labels.svg";
  Figure f = force_figure();
  f.points = {{"early", 40e-6, 2e-3 * 0.04}, {"at the end", 200e-6, 2e-3}};
  mneedle::plot::write_svg(file, f);
  const std::string svg = read(file);
  const auto line = polyline(svg, "#1F77B4");
  ASSERT_EQ(line.size(), 41u);
  double early = -1.0, end = -1.0;
  for (const auto& t : texts(svg)) {
    if (t.text == "early") early = t.x;
    if (t.text == "at the end") end = t.x;
  }
  ASSERT_GE(early, 0.0);
  ASSERT_GE(end, 0.0);
  EXPECT_GT(early, line[8].first);    // right of the point at 40 um (the curve's 9th point)
  EXPECT_LT(end, line.back().first);  // left of the point at 200 um, the curve's last
}

TEST(WriteSvg, OneCurveHasNoLegend) {
  fs::create_directories(kWork);
  const auto file = kWork / "single.svg";
  mneedle::plot::write_svg(file, force_figure());
  EXPECT_FALSE(has_text(texts(read(file)), "FE"));
}

// 30 records in one figure (mneedle energy rec*.csv): the legend keeps 7 names and counts the
// rest in its last line instead of covering the curves; every curve is still drawn.
TEST(WriteSvg, LongLegendCountsWhatItDoesNotName) {
  fs::create_directories(kWork);
  Figure f = force_figure();
  f.series.clear();
  for (int k = 0; k < 30; ++k) {
    Series s;
    s.label = "record " + std::to_string(k);
    s.x = {0.0, 1e-4};
    s.y = {0.0, 1e-3 * (k + 1)};
    f.series.push_back(s);
  }
  const auto file = kWork / "many.svg";
  mneedle::plot::write_svg(file, f);
  const auto labels = texts(read(file));
  EXPECT_TRUE(has_text(labels, "record 6"));
  EXPECT_FALSE(has_text(labels, "record 7"));
  EXPECT_TRUE(has_text(labels, "and 23 more"));
}

TEST(WriteSvg, GapsInTheDataSplitTheLine) {
  fs::create_directories(kWork);
  const auto file = kWork / "gap.svg";
  Figure f = force_figure();
  f.series[0].y[20] = std::nan("");
  mneedle::plot::write_svg(file, f);
  EXPECT_EQ(polyline(read(file), "#1F77B4").size(), f.series[0].x.size() - 1);
}

TEST(WriteSvg, BadSeriesAndUnwritableFilesAreRefusedByName) {
  fs::create_directories(kWork);
  Figure f = force_figure();
  f.series[0].y.pop_back();
  try {
    mneedle::plot::write_svg(kWork / "bad.svg", f);
    FAIL();
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("plot series 'FE' has 41 x values and 40 y values"),
              std::string::npos)
        << e.what();
  }
  Figure g = force_figure();
  g.x.logarithmic = true;  // x = 0 at the first point
  EXPECT_THROW(mneedle::plot::write_svg(kWork / "log.svg", g), mneedle::InputError);
  EXPECT_THROW(mneedle::plot::write_svg(kWork / "no" / "such" / "dir.svg", force_figure()),
               mneedle::InputError);
  EXPECT_FALSE(fs::exists(kWork / "bad.svg"));
}

TEST(WriteSvg, LogarithmicAxesTakeDecades) {
  fs::create_directories(kWork);
  const auto file = kWork / "loglog.svg";
  Figure f;
  f.x = {"time", Dimension::Time, "", true};
  f.y = {"error", Dimension::Dimensionless, "%", true};
  f.series.push_back(
      {"runs", {0.01, 0.1, 1.0, 10.0}, {30.0, 10.0, 3.0, 1.0}, mneedle::plot::Mark::Dots});
  mneedle::plot::write_svg(file, f);
  const auto t = texts(read(file));
  EXPECT_TRUE(has_text(t, "error [%]"));
  EXPECT_TRUE(has_text(t, "time [s]") || has_text(t, "time [ms]"));
}

}  // namespace
