// `mneedle optimize` end to end: the puncture-depth objective with its target-depth constraint,
// the JSON summary, the outputs on disk, multi-start and MLSL from the CLI, the time budget and
// bad input. The analytic pre-puncture model keeps each run to a second or two; the FE models are
// the same code path in run_insertion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::mneedle_binary;
using mneedle::test::run_mneedle;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;
// The skin scene with the pressure criterion: these runs use the closed-form pre-puncture model,
// whose stress criterion takes pointed tips only (the bevels' and cylinders' flat ends not).
const std::string kSkin = mneedle::test::skin_scene_with_criterion("pressure");
// Homogeneous silicone where the sharp bevel's F / A_sec rises with depth: the pressure criterion
// fires at a resolved depth (in skin it fires at first contact or not at all).
const std::string kSilicone = kRoot + "/designs/scenes/optimize_silicone.toml";
constexpr double kPi = 3.14159265358979323846;

fs::path temp_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("mneedle_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// The README's search: no --bound, so the plugin's whole ranges. Their middle is no valid bevel
// (longer than the needle); the search starts from the plugin's defaults instead.
TEST(OptimizeCommand, SearchOverThePluginsWholeRangesStartsFromItsDefaults) {
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                               "' --vary bevel_angle,diameter --model analytic --material silicon"
                               " --max-evals 3 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["best"]["params"].contains("diameter")) << j.dump(2);
  EXPECT_TRUE(j["best"]["puncture_depth_m"].is_number()) << j.dump(2);
}

TEST(OptimizeCommand, ConeWithItsDefaultSharpPointEvaluatesInSkin) {
  // Failed every evaluation ("tip_size_m must be > 0 m"): no vertex but the point lies below the
  // target depth, so the tip element size was sized from a zero radius: on the 3-D model too.
  // The cone over its half angle in the skin scene, with `extra` arguments; each run's size is
  // positive and every evaluation ran.
  const auto optimize_cone = [](const std::string& extra, int evaluations) {
    const auto run = run_mneedle("optimize --plugin cone --scene '" + kSkin +
                                 "' --vary half_angle --material silicon --fidelity fast --json " +
                                 extra + " --max-evals " + std::to_string(evaluations));
    EXPECT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.exit_code == 0 ? run.out : "{}");
    EXPECT_GT(j.value("tip_element_size_m", 0.0), 0.0);
    EXPECT_EQ(j.value("evaluations", 0), evaluations);
    return j;
  };
  auto j3d = optimize_cone("--model 3d", 1);
  EXPECT_TRUE(j3d["best"]["puncture_depth_m"].is_number()) << j3d.dump(2);
  auto j = optimize_cone("--seed 7", 3);
  EXPECT_EQ(j["optimum"]["failed_evaluations"], 0) << j["optimum"].dump(2);
  // Under the scene's own stress criterion the axisymmetric model sizes a pointed tip by its own
  // rule, and no size is imposed (docs/cli.md, "Smoothness").
  const auto own = run_mneedle("optimize --plugin cone --scene '" + kRoot +
                               "/designs/scenes/human_skin.toml' --vary half_angle --max-evals 1"
                               " --material silicon --fidelity fast --json");
  ASSERT_EQ(own.exit_code, 0) << own.err;
  EXPECT_TRUE(nlohmann::json::parse(own.out)["tip_element_size_m"].is_null());
}

// A scene without puncture data optimises a force: the tip element's size once asked the scene
// for its criterion's threshold first, and stopped on "fracture.critical_pressure: missing".
TEST(OptimizeCommand, ASceneWithoutPunctureDataOptimisesThePeakForce) {
  const auto run =
      run_mneedle("optimize --plugin sharp_bevel --scene '" + std::string(MNEEDLE_SOURCE_ROOT) +
                  "/tests/assets/scenes/axisymmetric_punch.toml' --vary bevel_angle"
                  " --objective peak-force --model analytic --max-evals 3 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["evaluations"].get<int>(), 3) << j.dump(2);
}

// --max-evals counts distinct designs: NLopt's own count includes the points the cache
// answers again, and a budget of 12 stopped at 11 designs.
TEST(OptimizeCommand, MaxEvalsIsTheNumberOfDistinctDesignsEvaluated) {
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                               "' --model analytic --vary bevel_angle --objective peak-force "
                               "--max-evals 12 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["evaluations"].get<int>(), 12);
  EXPECT_EQ(j["history"].size(), 12u);
  EXPECT_EQ(j["stop"], "max_evaluations");
}

TEST(OptimizeCommand, SummaryPrintsParametersInTheirUnits) {
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                               "' --vary bevel_angle --bound bevel_angle=15deg:60deg"
                               " --model analytic --max-evals 5");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find(" deg\n"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("(SI)"), std::string::npos) << run.out;
}

TEST(OptimizeCommand, PunctureDepthIsTheDefaultObjectiveAndTheSummaryHasItsKeys) {
  const fs::path dir = temp_dir("optimize_depth");
  const auto run =
      run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                  "' --vary bevel_angle --bound bevel_angle=15deg:60deg"
                  " --model analytic --material silicon --max-evals 20 --json --out '" +
                  dir.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["objective"], "puncture_depth_m");
  EXPECT_EQ(j["algorithm"], "cobyla");
  EXPECT_TRUE(j["feasible"].get<bool>());
  EXPECT_LE(j["evaluations"].get<int>(), 20);
  const auto& best = j["best"];
  ASSERT_TRUE(best["puncture_depth_m"].is_number()) << j.dump(2);
  const double depth = best["puncture_depth_m"].get<double>();
  EXPECT_GT(depth, 0.0);
  EXPECT_LE(depth, best["target_depth_m"].get<double>());
  EXPECT_GT(best["margin"].get<double>(), best["safety_factor"].get<double>());
  EXPECT_TRUE(best["params"].contains("bevel_angle"));
  EXPECT_FALSE(j["stop_reason"].get<std::string>().empty());
  EXPECT_TRUE(fs::exists(dir / "best.stl"));
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  std::ifstream history(dir / "history.csv");
  std::string header;
  std::getline(history, header);  // the run's provenance first (docs/cli.md, "Provenance")
  EXPECT_EQ(header.rfind("# provenance: {", 0), 0u) << header;
  std::getline(history, header);
  EXPECT_NE(header.find("puncture_depth_m"), std::string::npos) << header;
  EXPECT_NE(header.find("target_depth_constraint"), std::string::npos) << header;
  // The JSON has the same history as history.csv: one entry per evaluation, in order.
  EXPECT_EQ(j["plugin"], "sharp_bevel");
  ASSERT_EQ(j["variables"].size(), 1u);
  EXPECT_EQ(j["variables"][0]["name"], "bevel_angle");
  const auto& h = j["history"];
  ASSERT_EQ(h.size(), j["evaluations"].get<std::size_t>());
  std::size_t csv_rows = 0;
  for (std::string line; std::getline(history, line);) ++csv_rows;
  EXPECT_EQ(csv_rows, h.size());
  for (const auto& e : h) {
    EXPECT_TRUE(e["values"].contains("bevel_angle"));
    EXPECT_TRUE(e["constraints"].contains("strength_constraint"));
  }
  // The best design's curve peaks at its peak force.
  double peak = 0.0;
  for (const auto& p : best["curve"]) peak = std::max(peak, p["force_N"].get<double>());
  EXPECT_DOUBLE_EQ(peak, best["peak_force_N"].get<double>());
  fs::remove_all(dir);
}

TEST(OptimizeCommand, PeakForceObjectiveReportsTheLowestFeasiblePeakForceOfItsHistory) {
  const fs::path dir = temp_dir("optimize_force");
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                               "' --vary bevel_angle --bound bevel_angle=20deg:60deg"
                               " --objective peak-force --model analytic --material silicon"
                               " --max-evals 25 --json --out '" +
                               dir.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["objective"], "peak_force_N");
  EXPECT_TRUE(j["feasible"].get<bool>());
  // history.csv: bevel_angle_SI, peak_force_N, 3 constraints, feasible, ...
  std::ifstream history(dir / "history.csv");
  std::string line;
  std::getline(history, line);  // provenance
  std::getline(history, line);  // header
  double lowest = 1e300;
  int rows = 0;
  while (std::getline(history, line)) {
    std::vector<std::string> cells;
    std::stringstream cs(line);
    for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
    ASSERT_GE(cells.size(), 6u) << line;
    if (cells[5] == "1") lowest = std::min(lowest, std::stod(cells[1]));
    ++rows;
  }
  EXPECT_EQ(rows, j["evaluations"].get<int>());
  // history.csv is written at full precision: the same number to round-off.
  EXPECT_NEAR(j["best"]["peak_force_N"].get<double>() / lowest, 1.0, 1e-12);
  fs::remove_all(dir);
}

TEST(OptimizeCommand, MultiStartAndMlslRunFromTheCommandLine) {
  const std::string common = "optimize --plugin sharp_bevel --scene '" + kSkin +
                             "' --vary bevel_angle --bound bevel_angle=15deg:60deg"
                             " --model analytic --material silicon --json";
  const auto multi = run_mneedle(common + " --starts 3 --max-evals 30 --seed 5");
  ASSERT_EQ(multi.exit_code, 0) << multi.err;
  const auto m = nlohmann::json::parse(multi.out);
  EXPECT_EQ(m["starts"].get<int>(), 3);
  const auto again =
      nlohmann::json::parse(run_mneedle(common + " --starts 3 --max-evals 30 --seed 5").out);
  EXPECT_EQ(m["best"]["params"], again["best"]["params"]);
  EXPECT_EQ(m["evaluations"], again["evaluations"]);

  const auto mlsl = run_mneedle(common + " --algorithm mlsl --local cobyla --max-evals 30");
  ASSERT_EQ(mlsl.exit_code, 0) << mlsl.err;
  const auto g = nlohmann::json::parse(mlsl.out);
  EXPECT_EQ(g["algorithm"], "mlsl");
  EXPECT_EQ(g["local_algorithm"], "cobyla");
  EXPECT_LE(g["evaluations"].get<int>(), 30);
}

TEST(OptimizeCommand, TimeBudgetStopsTheSearchAndSaysSo) {
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSkin +
                               "' --vary bevel_angle,diameter --model analytic --material silicon"
                               " --algorithm isres --max-evals 100000 --max-time 1s --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["stop"], "max_time") << j["stop_reason"];
  EXPECT_LT(j["evaluations"].get<int>(), 100000);
}

TEST(OptimizeCommand, BadInputIsAClearError) {
  auto run = run_mneedle("optimize --plugin cone --scene '" + kSkin + "' --vary bevel_angle");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("has no parameter 'bevel_angle'"), std::string::npos) << run.err;
  run = run_mneedle("optimize --plugin cone --scene '" + kSkin +
                    "' --vary half_angle --min-feature -5um");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--min-feature"), std::string::npos) << run.err;
  run = run_mneedle("optimize --plugin cone --scene '" + kSkin +
                    "' --vary half_angle --algorithm isres --starts 3");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--starts"), std::string::npos) << run.err;
  run = run_mneedle("optimize --plugin cone --scene '" + kSkin +
                    "' --vary half_angle --max-time 5kg");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("5kg"), std::string::npos) << run.err;
}

}  // namespace

namespace {

TEST(OptimizeCommand, UnknownMaterialIsRefusedBeforeTheSearchStarts) {
  const auto run = run_mneedle("optimize --plugin cone --scene '" + kSkin +
                               "' --vary half_angle --material unobtainium --max-evals 2");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("unknown needle material 'unobtainium'"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("no design could be evaluated"), std::string::npos) << run.err;
}

TEST(OptimizeCommand, SummarySaysWhereTheOptimumIsAndHowManyEvaluationsFailed) {
  // The analytic puncture depth falls with the bevel angle over 15-60 deg (docs/model.md,
  // "Optimisation"), so the search ends on the lower bound and must say so.
  const fs::path dir = temp_dir("optimum");
  const std::string common = "optimize --plugin sharp_bevel --scene '" + kSilicone +
                             "' --vary bevel_angle --bound bevel_angle=15deg:60deg"
                             " --model analytic --max-evals 20";
  const auto run = run_mneedle(common + " --json --out '" + dir.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const auto& optimum = j["optimum"];
  EXPECT_FALSE(optimum["interior"].get<bool>()) << optimum.dump();
  EXPECT_EQ(optimum["on_lower_bound"], nlohmann::json::array({"bevel_angle"})) << optimum.dump();
  EXPECT_TRUE(optimum["on_upper_bound"].empty()) << optimum.dump();
  EXPECT_TRUE(optimum["violated_constraints"].empty()) << optimum.dump();
  EXPECT_EQ(optimum["failed_evaluations"], 0) << optimum.dump();
  EXPECT_EQ(optimum["impossible_designs"], 0) << optimum.dump();
  std::ifstream history(dir / "history.csv");
  int rows = -2;  // provenance and header
  for (std::string line; std::getline(history, line);) ++rows;
  EXPECT_EQ(rows, j["evaluations"].get<int>());
  const auto text = run_mneedle(common);
  EXPECT_NE(text.out.find("optimum on the lower bound of bevel_angle (widen --bound"),
            std::string::npos)
      << text.out;
  fs::remove_all(dir);
}

// A --bound beyond the shape's own range was narrowed to it in silence (-10 deg read as 5 deg); it
// is refused with the range. On the shape's own limit the summary does not advise widening
// --bound, which cannot go further: the sharp bevel's 85 deg maximum.
TEST(OptimizeCommand, ABoundBeyondTheShapesRangeIsRefusedAndItsOwnLimitIsNamedAsSuch) {
  const auto beyond = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                                  "' --vary bevel_angle --bound bevel_angle=-10deg:40deg"
                                  " --model analytic --max-evals 2");
  EXPECT_EQ(beyond.exit_code, 1);
  EXPECT_NE(beyond.err.find("--bound bevel_angle: low -10deg is below the shape's minimum (the "
                            "shape's range is 5 deg to 85 deg)"),
            std::string::npos)
      << beyond.err;
  const std::string common = "optimize --plugin sharp_bevel --scene '" + kSilicone +
                             "' --vary bevel_angle --bound bevel_angle=60deg:85deg"
                             " --model analytic --max-evals 20";
  const auto json = run_mneedle(common + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto optimum = nlohmann::json::parse(json.out)["optimum"];
  EXPECT_EQ(optimum["on_upper_bound"], nlohmann::json::array({"bevel_angle"})) << optimum.dump();
  EXPECT_EQ(optimum["on_shape_limit"], nlohmann::json::array({"bevel_angle"})) << optimum.dump();
  const auto text = run_mneedle(common);
  EXPECT_NE(text.out.find("optimum on the upper bound of bevel_angle (the shape's own limit)"),
            std::string::npos)
      << text.out;
  EXPECT_EQ(text.out.find("widen --bound"), std::string::npos) << text.out;
}

TEST(OptimizeCommand, BevelLongerThanTheNeedleIsAnImpossibleDesignNotAFailure) {
  // The plugin's whole ranges: thin bevels on wide needles are longer than the needle.
  const auto run = run_mneedle("optimize --plugin sharp_bevel --scene '" + kSilicone +
                               "' --vary bevel_angle,diameter --model analytic --max-evals 30"
                               " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const auto& optimum = j["optimum"];
  EXPECT_EQ(optimum["failed_evaluations"], 0) << optimum.dump(2);
  ASSERT_GT(optimum["impossible_designs"].get<int>(), 0) << optimum.dump(2);
  EXPECT_NE(optimum["impossible_causes"][0]["error"].get<std::string>().find("longer than"),
            std::string::npos)
      << optimum.dump(2);
}

// "Same needle, same answer": the optimiser evaluates a design through the code path of `screen`
// and `simulate` (evaluate_design). Its start design also sizes the run's one tissue mesh
// (tip_element_size_m, docs/cli.md "Smoothness"), so for that design the three paths must agree
// bit for bit, on the 3-D model and on the axisymmetric one. A later design runs on the start's
// mesh; that is the one place where the optimiser and simulate may differ, by the mesh error.
TEST(OptimizeCommand, ItsStartDesignPuncturesWhereSimulatePuncturesIt) {
  struct Case {
    std::string scene, plugin, vary, set;
  };
  const std::vector<Case> cases = {
      // 3-D half model, pressure criterion, silicone (the plugin-or-STL test's scene)
      {kRoot + "/tests/assets/scenes/bevel_silicone_3d.toml", "sharp_bevel", "bevel_angle",
       "--set diameter=230um --set length=1000um --set bevel_angle=30deg"},
      // axisymmetric model, stress criterion, layered skin (the README's cone)
      {kRoot + "/designs/scenes/human_skin.toml", "cone", "half_angle", ""}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.plugin);
    const auto opt = run_mneedle("optimize --plugin " + c.plugin + " --scene '" + c.scene +
                                 "' --vary " + c.vary + " " + c.set +
                                 " --material silicon --fidelity fast --max-evals 1 --json");
    ASSERT_EQ(opt.exit_code, 0) << opt.err;
    const auto summary = nlohmann::json::parse(opt.out);
    const auto& best = summary["best"];
    ASSERT_TRUE(best["puncture_depth_m"].is_number()) << best.dump(2);
    // The same design in a scene of its own: the scene's needle line replaced by the start's
    // parameters as the optimiser reports them (SI, full precision, each with its unit).
    std::string geometry = "geometry = { plugin = \"" + c.plugin + "\"";
    for (const auto& [name, value] : best["params"].items()) {
      const std::string unit = summary["parameter_units"][name].get<std::string>();
      geometry +=
          ", " + name + " = " +
          (unit.empty() || unit == "1" ? value.dump() : "\"" + value.dump() + " " + unit + "\"");
    }
    geometry += " }";
    std::string text = mneedle::test::file_text(c.scene);
    const auto line = text.find("geometry = {");
    ASSERT_NE(line, std::string::npos);
    text.replace(line, text.find('\n', line) - line, geometry);
    const fs::path dir = temp_dir("optimize_same_" + c.plugin);
    fs::create_directories(dir);
    std::ofstream(dir / "design.toml") << text;
    const auto sim =
        run_mneedle("simulate '" + (dir / "design.toml").string() + "' --fidelity fast --json");
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    const auto puncture = nlohmann::json::parse(sim.out)["needles"][0]["puncture"];
    ASSERT_TRUE(puncture.is_object()) << sim.out;
    EXPECT_EQ(puncture["depth_m"].get<double>(), best["puncture_depth_m"].get<double>());
    EXPECT_EQ(puncture["force_N"].get<double>(), best["puncture_force_N"].get<double>());
    // The small-strain warning where simulate gives it: the skin's linear stratum corneum, not
    // the silicone block (docs/validation.md, "Finite strain in a stiff top layer").
    bool simulate_warns = false;
    const auto simulated = nlohmann::json::parse(sim.out);
    for (const auto& w : simulated["warnings"])
      simulate_warns = simulate_warns || w.get<std::string>().find("membrane") != std::string::npos;
    ASSERT_EQ(summary["warnings"].size(), simulate_warns ? 1u : 0u) << summary["warnings"].dump();
    EXPECT_EQ(simulate_warns, c.plugin == "cone");
    if (simulate_warns) {
      EXPECT_NE(opt.err.find("the best design before it punctures"), std::string::npos) << opt.err;
    }
    fs::remove_all(dir);
  }
}

TEST(OptimizeCommand, KilledRunKeepsEveryEvaluatedDesignInItsHistory) {
  // SIGKILL once the first row is on disk: the rows written must be whole and full precision,
  // and no summary claims a result.
  const fs::path dir = temp_dir("killed");
  const std::string history = (dir / "history.csv").string();
  const std::string script =
      "'" + mneedle_binary() + "' optimize --plugin sharp_bevel --scene '" + kSilicone +
      "' --vary bevel_angle --max-evals 100 --out '" + dir.string() +
      "' >/dev/null 2>&1 & pid=$!; for i in $(seq 1200); do "
      "[ -f '" +
      history + "' ] && [ $(wc -l < '" + history +
      "') -ge 3 ] && break; sleep 0.1; done; kill -9 $pid; wait $pid 2>/dev/null; true";
  ASSERT_EQ(std::system(script.c_str()), 0);
  std::ifstream in(history);
  std::string header;
  ASSERT_TRUE(std::getline(in, header)) << "no history after the kill";
  EXPECT_EQ(header.rfind("# provenance: ", 0), 0u) << header;
  ASSERT_TRUE(std::getline(in, header)) << "no header after the kill";
  const auto fields = [](const std::string& line) {
    return std::count(line.begin(), line.end(), ',') + 1;
  };
  int rows = 0;
  for (std::string line; std::getline(in, line); ++rows) {
    EXPECT_EQ(fields(line), fields(header)) << line;
    // 17 significant digits: the first field is the bevel angle in radians (the start, 30 deg,
    // is pi/6, which no shorter decimal holds).
    EXPECT_GE(line.find(','), 17u) << line;
  }
  EXPECT_GE(rows, 1);
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  fs::remove_all(dir);
}

}  // namespace
