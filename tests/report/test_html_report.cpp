#include "mneedle/report/html_report.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <unistd.h>

#include "mneedle/base/error.h"

namespace {

using mneedle::InputError;
using mneedle::report::NeedleView;
using mneedle::report::ReportInput;
using mneedle::report::ResultKind;
using nlohmann::json;

json curve(double puncture_depth) {
  return json::array({{{"depth_m", 0.5 * puncture_depth}, {"force_N", 1e-3}, {"stage", "pre"}},
                      {{"depth_m", puncture_depth}, {"force_N", 2e-3}, {"stage", "pre"}},
                      {{"depth_m", puncture_depth}, {"force_N", 1e-3}, {"stage", "post"}},
                      {{"depth_m", 2 * puncture_depth}, {"force_N", 1.5e-3}, {"stage", "post"}}});
}

json screen_result() {
  json good = {{"design", "cone <b>&"},
               {"ok", true},
               {"passes", true},
               {"curve", curve(100e-6)},
               {"puncture", {{"depth_m", 100e-6}, {"force_N", 2e-3}}},
               {"puncture_depth_m", 100e-6},
               {"puncture_force_N", 2e-3},
               {"peak_force_N", 2e-3},
               {"capacity_N", 0.5},
               {"margin", 250.0},
               {"governing", "buckling"}};
  json bad = {{"design", "broken"}, {"ok", false}, {"error", "broken.stl: not a mesh"}};
  return {{"scene", "skin.toml"},
          {"ranking", {"puncture_depth_m"}},
          {"designs", {good, bad}},
          {"provenance", {{"tool", "mneedle"}, {"version", "0.1.0"}}}};
}

NeedleView tetrahedron(const std::string& name, int entry = -1) {
  NeedleView v;
  v.name = name;
  v.entry = entry;
  v.mesh.vertices = {{0, 0, 0}, {1e-4, 0, 1e-3}, {0, 1e-4, 1e-3}, {-1e-4, -1e-4, 1e-3}};
  v.mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}};
  return v;
}

TEST(ResultKind, IsToldByTheKeysOfEachCommandsResult) {
  EXPECT_EQ(mneedle::report::result_kind(screen_result(), "r.json"), ResultKind::Screen);
  EXPECT_EQ(mneedle::report::result_kind({{"history", json::array()}, {"best", json::object()}},
                                         "r.json"),
            ResultKind::Optimize);
  EXPECT_EQ(mneedle::report::result_kind(
                {{"needles", json::array()}, {"total_curve", json::array()}}, "r.json"),
            ResultKind::Simulate);
}

TEST(ResultKind, AnythingElseIsAnErrorNamingTheFile) {
  try {
    mneedle::report::result_kind({{"rows", 1}}, "fit.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fit.json: not a result of simulate, screen or optimize"),
              std::string::npos)
        << e.what();
  }
}

TEST(ReportFigures, ScreenDrawsOneCurvePerEvaluatedDesignWithItsPuncture) {
  const auto figures = mneedle::report::report_figures(screen_result(), "r.json");
  ASSERT_EQ(figures.size(), 1u);
  ASSERT_EQ(figures[0].series.size(), 1u);  // the error row has no curve
  EXPECT_EQ(figures[0].series[0].label, "cone <b>&");
  EXPECT_EQ(figures[0].series[0].x.size(), 4u);
  ASSERT_EQ(figures[0].points.size(), 1u);
  EXPECT_DOUBLE_EQ(figures[0].points[0].x, 100e-6);
}

TEST(ReportFigures, MalformedCurvePointIsNamedByItsPath) {
  json r = screen_result();
  r["designs"][0]["curve"][2].erase("force_N");
  try {
    mneedle::report::report_figures(r, "r.json");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("r.json: designs[0].curve[2]: needs numbers"),
              std::string::npos)
        << e.what();
  }
}

TEST(HtmlReport, KeyOfTheWrongTypeIsAMalformedResultNotACrash) {
  ReportInput in;
  in.result = screen_result();
  in.source = "edited.json";
  in.result["designs"][0]["ok"] = "yes";  // a string where a boolean belongs
  try {
    mneedle::report::html_report(in);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("edited.json: malformed result (", 0), 0u) << e.what();
  }
}

TEST(ReportFigures, OptimizationPlotsFeasibleAndInfeasibleEvaluationsApart) {
  json r = {
      {"objective", "puncture_depth_m"},
      {"best", {{"curve", curve(50e-6)}, {"puncture_depth_m", 50e-6}, {"puncture_force_N", 2e-3}}},
      {"history",
       {{{"objective", 80e-6}, {"feasible", false}},
        {{"objective", 50e-6}, {"feasible", true}},
        {{"objective", nullptr}, {"failed", true}, {"feasible", false}}}}};
  const auto figures = mneedle::report::report_figures(r, "r.json");
  ASSERT_EQ(figures.size(), 2u);
  ASSERT_EQ(figures[0].series.size(), 2u);
  EXPECT_EQ(figures[0].series[0].label, "feasible");
  EXPECT_EQ(figures[0].series[0].x, std::vector<double>{2.0});  // evaluations counted from 1
  EXPECT_EQ(figures[0].series[1].x, std::vector<double>{1.0});  // the failed one has no point
  EXPECT_EQ(figures[1].points.size(), 1u);
}

TEST(HtmlReport, NamesAreEscapedAndTheViewersJsonCannotCloseItsScript) {
  ReportInput in;
  in.result = screen_result();
  in.source = "r.json";
  in.needles = {tetrahedron("cone <b>&"), tetrahedron("x</script><script>alert(1)"),
                tetrahedron("<!--<script")};
  in.result["designs"][1] = in.result["designs"][0];  // two curves: a legend with the name
  in.result["designs"][1]["design"] = "cone <b>& 2";
  const std::string page = mneedle::report::html_report(in);
  EXPECT_NE(page.find("cone &lt;b&gt;&amp;"), std::string::npos);
  // Raw only inside the viewer's JSON, which is not HTML.
  const std::string html = page.substr(0, page.find("<script type=\"application/json\""));
  EXPECT_EQ(html.find("cone <b>&"), std::string::npos);
  // One </script> per script element: the JSON one and the viewer's.
  std::size_t closes = 0;
  for (std::size_t pos = 0; (pos = page.find("</script>", pos)) != std::string::npos; ++pos)
    ++closes;
  EXPECT_EQ(closes, 2u);
  // Inside the JSON element: no < or > at all, whatever the names hold.
  const auto start = page.find("<script type=\"application/json\" id=\"mneedle-needles\">");
  ASSERT_NE(start, std::string::npos);
  const auto body =
      start + std::string("<script type=\"application/json\" id=\"mneedle-needles\">").size();
  const std::string inside = page.substr(body, page.find("</script>", body) - body);
  EXPECT_EQ(inside.find_first_of("<>"), std::string::npos) << inside.substr(0, 200);
  EXPECT_NE(inside.find("\\u003c!--\\u003cscript"), std::string::npos);
}

TEST(HtmlReport, NeedlesReachTheViewerInMillimetresAndRowsPointAtThem) {
  ReportInput in;
  in.result = screen_result();
  in.source = "r.json";
  in.needles = {tetrahedron("cone <b>&", 0)};
  const std::string page = mneedle::report::html_report(in);
  EXPECT_NE(page.find("\"positions\":[0,0,0,0.1,0,1,0,0.1,1,-0.1,-0.1,1]"), std::string::npos);
  EXPECT_NE(page.find("\"indices\":[0,1,2,0,2,3,0,3,1,1,3,2]"), std::string::npos);
  EXPECT_NE(page.find("<tr data-needle=\"0\" class=\"viewable\">"), std::string::npos);
  // The error row says why and is not clickable.
  EXPECT_NE(page.find("broken.stl: not a mesh"), std::string::npos);
  EXPECT_NE(page.find("<option value=\"0\">cone &lt;b&gt;&amp;</option>"), std::string::npos);
}

TEST(HtmlReport, RowsPointAtTheirOwnNeedleWhenTwoDesignsShareAName) {
  ReportInput in;
  in.result = screen_result();
  in.result["designs"][1] = in.result["designs"][0];  // both "cone <b>&" (two files' stems)
  in.source = "r.json";
  in.needles = {tetrahedron("cone <b>&", 1)};  // only the second one was rebuilt
  const std::string page = mneedle::report::html_report(in);
  std::size_t clickable = 0;
  for (std::size_t pos = 0; (pos = page.find("data-needle=", pos)) != std::string::npos; ++pos)
    ++clickable;
  EXPECT_EQ(clickable, 1u);
  // The first row is not clickable; the second shows needle 0.
  const auto first = page.find("<tr><td>1</td>");
  const auto second = page.find("<tr data-needle=\"0\" class=\"viewable\"><td>2</td>");
  EXPECT_NE(first, std::string::npos);
  EXPECT_NE(second, std::string::npos);
}

TEST(HtmlReport, PageIsSelfContainedWithThePlotInlineAndNoAddressToFetch) {
  ReportInput in;
  in.result = screen_result();
  in.source = "r.json";
  in.needles = {tetrahedron("cone")};
  const std::string page = mneedle::report::html_report(in);
  EXPECT_NE(page.find("<figure class=\"plot\">\n<svg"), std::string::npos);
  EXPECT_EQ(page.find("<?xml"), std::string::npos);  // PLplot's prolog is not HTML
  // No element loads anything (the SVG namespaces are names, not loads); the bundled script is
  // checked in a browser, offline, by check_report.mjs.
  const std::string html = page.substr(0, page.rfind("<script>"));
  EXPECT_FALSE(std::regex_search(html, std::regex(R"((src|href)\s*=)")));
  EXPECT_NE(page.find("WebGLRenderer"), std::string::npos);  // three.js is in the page
}

TEST(HtmlReport, NotesAndAMissingViewAreSaid) {
  ReportInput in;
  in.result = screen_result();
  in.source = "r.json";
  in.notes = {"design cone: not shown in 3-D (cone.stl: no such file)"};
  const std::string page = mneedle::report::html_report(in);
  EXPECT_NE(page.find("<li>design cone: not shown in 3-D (cone.stl: no such file)</li>"),
            std::string::npos);
  EXPECT_NE(page.find("No needle could be shown"), std::string::npos);
}

TEST(HtmlReport, ASimulationWhoseSolverStoppedSaysWhereItsCurvesEnd) {
  const json pre = json::array({{{"depth_m", 10e-6}, {"force_N", 1e-3}, {"stage", "pre"}},
                                {{"depth_m", 40e-6}, {"force_N", 4e-3}, {"stage", "pre"}}});
  ReportInput in;
  in.result = {
      {"needles",
       {{{"name", "cone"}, {"curve", pre}, {"puncture", nullptr}, {"max_force_N", 4e-3}}}},
      {"total_curve", pre},
      {"stopped",
       {{"depth_m", 40e-6},
        {"reason", "axisymmetric insertion stopped at depth 42.47 um: inverted <element>"}}}};
  in.source = "r.json";
  const std::string page = mneedle::report::html_report(in);
  EXPECT_NE(page.find("The finite element run stopped after its step at 40 "), std::string::npos);
  EXPECT_NE(page.find("inverted &lt;element&gt;"), std::string::npos);  // escaped
  const auto figures = mneedle::report::report_figures(in.result, "r.json");
  ASSERT_EQ(figures.size(), 1u);
  ASSERT_EQ(figures[0].points.size(), 1u);  // no puncture: the stop is the only marked point
  EXPECT_EQ(figures[0].points[0].label, "FE stopped");
  EXPECT_EQ(figures[0].points[0].x, 40e-6);
  EXPECT_EQ(figures[0].points[0].y, 4e-3);
  in.result.erase("stopped");
  EXPECT_EQ(mneedle::report::html_report(in).find("run stopped"), std::string::npos);
}

TEST(WriteReport, UnwritableFileIsNamedAndLeavesNothing) {
  ReportInput in;
  in.result = screen_result();
  in.source = "r.json";
  // A file where the folder should be: cannot be written, even by root.
  const auto blocker = std::filesystem::temp_directory_path() /
                       ("mneedle_report_blocker_" + std::to_string(::getpid()));
  std::ofstream(blocker) << "a file";
  const auto file = blocker / "r.html";
  try {
    mneedle::report::write_report(file, in);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ": cannot write the report"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));
  EXPECT_EQ(std::filesystem::file_size(blocker), 6u);  // untouched
  std::filesystem::remove(blocker);
}

}  // namespace
