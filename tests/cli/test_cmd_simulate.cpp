// Runs the built `mneedle simulate` on small scenes and checks exit status and output: the FE
// keys of the pre-puncture model and the two-stage keys (stage, puncture, total curve, planner).

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include "../plot/svg_reader.h"
#include "run_mneedle.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;
using mneedle::test::CommandRun;
using mneedle::test::run_mneedle;

std::string scene(const std::string& name) {
  return std::string(MNEEDLE_TEST_ASSETS) + "/scenes/" + name;
}

TEST(CmdSimulate, FlatPunchJsonHasTheIssueKeysAndAPlausibleForce) {
  const CommandRun run = run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["mesh"]["axisymmetric"].get<bool>());
  EXPECT_EQ(j["mesh"]["order"].get<int>(), 2);
  EXPECT_GT(j["mesh"]["nodes"].get<int>(), 0);
  const auto& needle = j["needles"].at(0);
  EXPECT_EQ(needle["name"], "punch");
  const auto& last = needle["curve"].back();
  EXPECT_NEAR(last["depth_m"].get<double>(), 50e-6, 1e-12);
  for (const char* key : {"force_N", "contact_area_m2", "contact_pressure_Pa", "strain_energy_J"})
    EXPECT_TRUE(last.contains(key)) << key;
  EXPECT_EQ(last["lateral_force_N"].size(), 2u);
  // Boussinesq 2 a E* d with a = 115 um, E = 0.2 MPa, nu = 0.45, d = 50 um: 2.88 mN; the
  // 1.15 mm layer (a/h = 0.1) and the bonded contact add about 10 %.
  EXPECT_NEAR(last["force_N"].get<double>(), 3.2e-3, 0.3e-3);
  const double a = 115e-6;
  EXPECT_NEAR(last["contact_area_m2"].get<double>(), M_PI * a * a, 1e-3 * M_PI * a * a);
}

TEST(CmdSimulate, CsvHasOneRowPerDepth) {
  const CommandRun run = run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(run.out);
  std::string provenance, header, row;
  std::getline(lines, provenance);  // "# provenance: {...}" (docs/cli.md, "Provenance")
  EXPECT_EQ(provenance.rfind("# provenance: ", 0), 0u) << provenance;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("depth_m,force_N,", 0), 0u);
  int rows = 0;
  while (std::getline(lines, row)) rows += row.empty() ? 0 : 1;
  // fast: 10 steps of 10 um over the first pre-puncture horizon (100 um), 5 of them within the
  // 50 um asked for.
  EXPECT_EQ(rows, 5);
}

TEST(CmdSimulate, AxisymmetricModelRefusesABevelClearly) {
  const CommandRun run =
      run_mneedle("simulate '" + scene("bevel_needs_3d.toml") + "' --model axisymmetric");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("bevel_needs_3d.toml:"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("3-D model"), std::string::npos) << run.err;
}

TEST(CmdSimulate, BevelRunsIn3dWithALateralForce) {
  const CommandRun run = run_mneedle("simulate '" + scene("bevel_3d_linear.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_FALSE(j["mesh"]["axisymmetric"].get<bool>());
  const auto& last = j["needles"][0]["curve"].back();
  EXPECT_NEAR(last["depth_m"].get<double>(), 50e-6, 1e-12);
  EXPECT_GT(last["force_N"].get<double>(), 0.0);
  // The bevel faces one side: the tissue pushes it sideways, along x in the plugin's frame.
  EXPECT_GT(std::abs(last["lateral_force_N"][0].get<double>()), 0.0);
  EXPECT_NEAR(last["lateral_force_N"][1].get<double>(), 0.0, 1e-9);
}

// The axisymmetric model's frictionless contact is linear-only: a neo-Hookean scene is refused
// with a message that names the limit and the way out.
TEST(CmdSimulate, FrictionlessOnANeoHookeanAxisymmetricSceneNamesTheLimit) {
  const CommandRun run =
      run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --contact frictionless");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("frictionless"), std::string::npos) << run.err;
}

TEST(CmdSimulate, PunctureJsonHasStagesPunctureAndPlannerKeys) {
  const CommandRun run = run_mneedle("simulate '" + scene("puncture_punch.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["fidelity"], "fast");
  EXPECT_EQ(j["models_run"], nlohmann::json({"axisymmetric_fe", "surface_loads"}));
  ASSERT_TRUE(j["reductions"].is_array());
  EXPECT_EQ(j["reductions"][0]["name"], "axisymmetric");
  const auto& needle = j["needles"].at(0);
  const auto& p = needle["puncture"];
  ASSERT_TRUE(p.is_object());
  EXPECT_EQ(p["criterion"], "pressure");
  for (const char* key : {"depth_m", "force_N", "post_force_N"})
    EXPECT_TRUE(p.contains(key)) << key;
  // Flat punch, P = F / (pi a^2) reaches 0.3 MPa near 200 um (see test_insertion_run).
  EXPECT_GT(p["depth_m"].get<double>(), 150e-6);
  EXPECT_LT(p["depth_m"].get<double>(), 260e-6);
  EXPECT_NEAR(p["force_N"].get<double>(), 0.3e6 * M_PI * 115e-6 * 115e-6, 2e-4);
  std::string previous = "pre";
  for (const auto& point : needle["curve"]) {
    const std::string stage = point["stage"];
    EXPECT_TRUE(stage == "pre" || stage == "post") << stage;
    if (stage == "post") {
      for (const char* key : {"alpha_N", "beta_N", "friction_N", "collar_N"})
        EXPECT_TRUE(point.contains(key)) << key;
      EXPECT_NEAR(point["force_N"].get<double>(),
                  point["alpha_N"].get<double>() + point["beta_N"].get<double>() +
                      point["friction_N"].get<double>() + point["collar_N"].get<double>(),
                  1e-12);
    }
    EXPECT_FALSE(previous == "post" && stage == "pre");
    previous = stage;
  }
  EXPECT_EQ(previous, "post");
  EXPECT_GE(needle["max_force_N"].get<double>(), p["force_N"].get<double>());
  EXPECT_EQ(j["total_curve"].size(), needle["curve"].size());
}

// The cohesive criterion from the command line (docs/model.md, "The cohesive criterion"): the
// puncture is the force's peak, and the curve carries the ring crack's state up to it.
TEST(CmdSimulate, CohesiveCriterionReportsThePeakAndTheRingCracksState) {
  const CommandRun run = run_mneedle("simulate '" + scene("cohesive_punch.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["criterion"]["name"], "cohesive");
  EXPECT_EQ(j["criterion"]["threshold"], 19.0);
  EXPECT_EQ(j["criterion"]["cohesive_strength_Pa"], 356e3);
  EXPECT_NEAR(j["criterion"]["crack_depth_m"].get<double>(), 200e-6, 1e-15);  // the diameter
  const auto& needle = j["needles"].at(0);
  const auto& p = needle["puncture"];
  ASSERT_TRUE(p.is_object());
  EXPECT_EQ(p["criterion"], "cohesive");
  // As tests/core/insertion/test_insertion_run.cpp's punch (the same gel and law).
  EXPECT_GT(p["depth_m"].get<double>(), 330e-6);
  EXPECT_LT(p["depth_m"].get<double>(), 410e-6);
  double fracture = 0.0;
  for (const auto& point : needle["curve"]) {
    if (point["stage"] != "pre") continue;
    for (const char* key :
         {"cohesive_crack_m", "cohesive_zone_m", "process_zone_cells", "fracture_energy_J"})
      ASSERT_TRUE(point.contains(key)) << key;
    fracture = point["fracture_energy_J"].get<double>();
  }
  EXPECT_GT(fracture, 0.0);
  EXPECT_TRUE(j["energy_check"]["passes"].get<bool>()) << j["energy_check"].dump();
}

TEST(CmdSimulate, SceneWithoutFractureDataHasNullPuncture) {
  const CommandRun run = run_mneedle("simulate '" + scene("axisymmetric_punch.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["needles"][0]["puncture"].is_null());
  EXPECT_TRUE(j["criterion"].is_null());
  for (const auto& point : j["needles"][0]["curve"]) EXPECT_EQ(point["stage"], "pre");
}

TEST(CmdSimulate, CriterionWithoutItsDataNamesTheLayerAndKey) {
  const CommandRun run =
      run_mneedle("simulate '" + scene("puncture_punch.toml") + "' --criterion stress");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("puncture_punch.toml:"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("strength: missing"), std::string::npos) << run.err;
}

// Paper A's four-needle array: symmetric about x = 0 and y = 0, so one needle is solved and
// reported four times; the total is their sum.
TEST(CmdSimulate, PaperAArrayRunsAsAQuarterModelAndReportsEveryNeedle) {
  const std::string file =
      std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/paper_a_skin_array.toml";
  const CommandRun run = run_mneedle("simulate '" + file + "' --fidelity fast --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["reductions"].size(), 1U) << j["reductions"].dump();
  EXPECT_EQ(j["reductions"][0]["name"], "quarter_model");
  ASSERT_EQ(j["needles"].size(), 4U);
  const double force = j["needles"][0]["max_force_N"].get<double>();
  EXPECT_GT(force, 1e-3);  // tens of mN for a 230 um punch 200 um into skin
  // The lateral force of the last pre-puncture point (post-puncture points carry none).
  const auto last_pre = [](const nlohmann::json& curve) {
    nlohmann::json point;
    for (const auto& p : curve)
      if (p["stage"] == "pre") point = p;
    return point;
  };
  const double lateral0 = last_pre(j["needles"][0]["curve"])["lateral_force_N"][0].get<double>();
  for (const auto& needle : j["needles"]) {
    EXPECT_EQ(needle["max_force_N"].get<double>(), force) << needle["name"];
    EXPECT_NEAR(std::abs(last_pre(needle["curve"])["lateral_force_N"][0].get<double>()),
                std::abs(lateral0), 1e-12);
  }
  // The total at the last depth is four times a needle's last force, to round-off. (It was
  // compared with the peak while the needles did not puncture; now they do, and their
  // post-puncture curve peaks before its end.)
  const double last = j["needles"][0]["curve"].back()["force_N"].get<double>();
  EXPECT_NEAR(j["total_curve"].back()["force_N"].get<double>(), 4.0 * last, 1e-9 * last);
}

// Paper A's three needles on its skin, each scene's own criterion (stress) at standard fidelity:
// resolved depths in paper A's order, sharp bevel < blunt bevel < cylinder (docs/validation.md,
// "The stress criterion in skin"). Pinned to 1 % of the depths measured on 2026-12-05 with the
// balls' volume-weighted sub-tetrahedra (the blunt bevel on 2026-12-06, with its flat meshed in
// cells of 2 L: 101.8 um before; 85.47 -> 85.40 um with the stress probe's mirror-invariant cut,
// docs/model.md "Tip stress and cracked meshes"): the runs are deterministic, so a move is a change
// to explain.
TEST(CmdSimulate, PaperASkinNeedlesPunctureInPaperAsOrderUnderTheStressCriterion) {
  const std::vector<std::pair<std::string, double>> needles = {
      {"sharp_bevel", 65.8e-6}, {"blunt_bevel", 85.40e-6}, {"cylinder", 140.9e-6}};
  for (const auto& [needle, depth] : needles) {
    const std::string file =
        std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/paper_a_skin_" + needle + ".toml";
    const CommandRun run = run_mneedle("simulate '" + file + "' --fidelity standard --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    const auto& p = j["needles"][0]["puncture"];
    ASSERT_TRUE(p.is_object()) << needle;
    EXPECT_EQ(p["criterion"], "stress") << needle;
    EXPECT_FALSE(p["at_first_contact"].get<bool>()) << needle;
    EXPECT_NEAR(p["depth_m"].get<double>(), depth, 0.01 * depth) << needle;
  }
}

// Force at depth d (m) on a run's curve, linear between its points.
double force_at(const nlohmann::json& curve, double d) {
  for (std::size_t i = 1; i < curve.size(); ++i) {
    const double d0 = curve[i - 1]["depth_m"].get<double>(), d1 = curve[i]["depth_m"].get<double>();
    if (d1 >= d) {
      const double f0 = curve[i - 1]["force_N"].get<double>(),
                   f1 = curve[i]["force_N"].get<double>();
      return f0 + (f1 - f0) * (d - d0) / (d1 - d0);
    }
  }
  return std::nan("");
}

// The skin scenes' post-puncture curves (docs/model.md, "The broken top layer"), the README's and
// paper A's three needles: each starts at the puncture force (paper A: the force after the
// puncture is at most slightly below it; the issue's band 0.5-1.0), never falls over the 800 um
// insertion and stays finite; the layer's grip shows as collar_N until the stratum corneum
// slides; and at 200 um it is within 0.3-3 times the intact FE force there (the issue's band),
// the intact curve taken from the penetration criterion, which never fires in skin. Measured
// 2026-12-05 at fast: 1.00 / 1.06 / 1.00 (human_skin's sharp bevel, blunt bevel, cylinder).
TEST(CmdSimulate, InSkinTheForceAfterThePunctureStartsAtThePunctureForceAndNeverFalls) {
  // paper_a_skin_sharp_bevel is left out: its hollow bevel reads what human_skin's solid one reads
  // to the last digit (the stiff layer holds the tip in point contact to 800 um, so the bore is
  // never touched before the puncture, and the grip continues the pre-puncture curve).
  for (const char* name : {"human_skin", "paper_a_skin_blunt_bevel", "paper_a_skin_cylinder"}) {
    SCOPED_TRACE(name);
    const std::string file = std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/" + name + ".toml";
    const CommandRun run = run_mneedle("simulate '" + file + "' --fidelity fast --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    const auto& needle = j["needles"][0];
    const auto& p = needle["puncture"];
    ASSERT_TRUE(p.is_object());
    const double ratio = p["post_force_N"].get<double>() / p["force_N"].get<double>();
    EXPECT_GE(ratio, 0.5);
    EXPECT_LE(ratio, 1.0 + 1e-12);
    double previous = 0.0, last_depth = 0.0;
    bool gripped = false;
    for (const auto& point : needle["curve"]) {
      if (point["stage"] != "post") continue;
      const double force = point["force_N"].get<double>();
      EXPECT_TRUE(std::isfinite(force));
      EXPECT_GE(force, previous * (1.0 - 1e-12)) << "falls at " << point["depth_m"];
      gripped = gripped || point["collar_N"].get<double>() > 0.0;
      previous = force;
      last_depth = point["depth_m"].get<double>();
    }
    EXPECT_TRUE(gripped);
    EXPECT_NEAR(last_depth, 800e-6, 1e-12);

    const CommandRun intact =
        run_mneedle("simulate '" + file + "' --fidelity fast --criterion penetration --json");
    ASSERT_EQ(intact.exit_code, 0) << intact.err;
    const auto k = nlohmann::json::parse(intact.out)["needles"][0];
    ASSERT_TRUE(k["puncture"].is_null()) << "the intact reference punctured";
    const double at_200 = force_at(needle["curve"], 200e-6) / force_at(k["curve"], 200e-6);
    EXPECT_GE(at_200, 0.3);
    EXPECT_LE(at_200, 3.0);
  }
}

// The README's figure (docs/simulate-silicone-sharp-bevel.svg) and its caption: paper A's sharp
// bevel in its silicone phantom, `--fidelity fast`, "the pressure criterion fires at 0.62 mm".
// Measured 2026-12-05: 616.8 um at 27.50 mN; 618.0 um since a node entering the needle's side is
// held where it entered (docs/model.md, "Contact with the rigid needle (sticking)"). The caption's
// 0.62 mm to 1 %, as every README number is; the run's own 618.05 um to 0.1 %, so that a move
// the caption's rounding hides is still seen.
TEST(CmdSimulate, ReadmeSiliconeFigurePuncturesWhereItsCaptionSays) {
  const std::string file =
      std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/paper_a_silicone_sharp_bevel.toml";
  const CommandRun run = run_mneedle("simulate '" + file + "' --fidelity fast --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto p = nlohmann::json::parse(run.out)["needles"][0]["puncture"];
  ASSERT_TRUE(p.is_object());
  EXPECT_EQ(p["criterion"], "pressure");
  EXPECT_FALSE(p["at_first_contact"].get<bool>());
  EXPECT_NEAR(p["depth_m"].get<double>(), 0.62e-3, 0.01 * 0.62e-3);
  EXPECT_NEAR(p["depth_m"].get<double>(), 618.05e-6, 1e-3 * 618.05e-6);
}

// `simulate --json` of a shipped skin scene with `zone_keys` added to its [model] table (after
// its fidelity); the whole output (null when the run failed).
nlohmann::json simulate_with_zone(const std::string& scene, const std::string& zone_keys,
                                  const std::string& arguments) {
  const std::string source = std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/" + scene;
  std::string text = mneedle::test::file_text(source);
  const std::string key = "fidelity = \"standard\"";
  EXPECT_NE(text.find(key), std::string::npos);
  if (text.find(key) == std::string::npos) return nullptr;
  text.replace(text.find(key), key.size(), key + "\n" + zone_keys);
  const fs::path file =
      fs::temp_directory_path() / ("zone_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << text;
  const CommandRun run = run_mneedle("simulate '" + file.string() + "' --json " + arguments);
  fs::remove(file);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  if (run.exit_code != 0) return nullptr;
  return nlohmann::json::parse(run.out);
}

// The same with the zone keys, and the scene as shipped: each run's first puncture.
std::pair<nlohmann::json, nlohmann::json> punctures_with_zone(const std::string& scene,
                                                              const std::string& zone_keys,
                                                              const std::string& arguments) {
  const nlohmann::json zoned = simulate_with_zone(scene, zone_keys, arguments);
  const CommandRun plain = run_mneedle("simulate '" + std::string(MNEEDLE_SOURCE_ROOT) +
                                       "/designs/scenes/" + scene + "' --json " + arguments);
  EXPECT_EQ(plain.exit_code, 0) << plain.err;
  if (zoned.is_null() || plain.exit_code != 0) return {};
  return {zoned["needles"][0]["puncture"],
          nlohmann::json::parse(plain.out)["needles"][0]["puncture"]};
}

// The README's resolved 3-D depth in skin (docs/validation.md, "The 3-D model under a point load,
// resolved"): paper A's sharp bevel with the scene's contact zone graded down to its tip punctures
// at 61.47 um at standard (2026-12-05; the study's converged 63.4-63.8 um at fine's growth,
// standard's 1.8 reads 3-4 % low), where standard alone reads 65.8 um, 7 % deeper. It read 61.09 um
// while a capture event took every node entering within 1.15 um of depth with it (110 nodes at the
// first contact; with groups of at most a quarter of the surface's finest spacing 85 nodes were
// captured over 74 events; with a fiftieth, since 2026-12-06, it read 61.470 um, and 61.44 um with
// the stress probe's mirror-invariant cut, docs/model.md "Tip stress and cracked meshes"; 61.47 um
// since a node entering the needle's side is held where it entered, docs/model.md "Contact with
// the rigid needle (sticking)"). Pinned
// to 0.1 % (61.473 um; 1 % until 2026-12-07, which hid the 61.44 -> 61.47 move: a move is a change
// to explain); the gap to the plain level is asked to stay at least 5 % (7 % measured). 8 s,
// release only.
TEST(CmdSimulate, ASharpBevelWithItsTipResolvedPuncturesSkinShallowerThanTheShippedLevelReadsIt) {
  const auto [r, q] =
      punctures_with_zone("paper_a_skin_sharp_bevel.toml",
                          "contact_zone = \"6 um\"\ncontact_zone_tip = \"0.3 um\"", "");
  ASSERT_TRUE(r.is_object() && q.is_object());
  EXPECT_FALSE(r["at_first_contact"].get<bool>());
  const double d = r["depth_m"].get<double>();
  EXPECT_NEAR(d, 61.473e-6, 1e-3 * 61.473e-6);
  EXPECT_GT(q["depth_m"].get<double>() / d, 1.05);
}

// The blunt bevel's flat meets the stratum corneum along an edge, where the stress criterion
// fires: every level meshes the flat with cells of 2 L (L = 10 um, the layer's strength_length;
// docs/model.md, "Tissue block and mesh"), so a scene's own zone of 20 um is the shipped mesh
// itself, to round-off. Measured 2026-12-07 at fast: 85.68 um shipped, 82.68 um with cells of L
// (which read what 5 um cells read, docs/validation.md "How fine the flat must be"; 85.64 and
// 82.64 um before fast graded the column under the flat, docs/model.md "Tissue block and mesh";
// 85.81 and 82.59 um before the stress probe's mirror-invariant cut, docs/model.md "Tip stress and
// cracked meshes"); before the zone the level read 100.03 um; 85.39 and 82.94 um since a node
// entering the needle's side is held where it entered (docs/model.md, "Contact with the rigid
// needle (sticking)"). Pinned to 1 % (deterministic runs: a move is a change to explain); the
// 2 L zone's remaining error against L asked to stay below 5 % (3.0 % measured at fast, 2.0 % at
// fine).
TEST(CmdSimulate, ABluntBevelsFlatIsMeshedWithCellsOfTwiceTheCriterionLength) {
  const auto [twice, shipped] = punctures_with_zone("paper_a_skin_blunt_bevel.toml",
                                                    "contact_zone = \"20 um\"", "--fidelity fast");
  ASSERT_TRUE(twice.is_object() && shipped.is_object());
  EXPECT_FALSE(shipped["at_first_contact"].get<bool>());
  const double d = shipped["depth_m"].get<double>();
  EXPECT_NEAR(d, 85.39e-6, 0.01 * 85.39e-6);
  EXPECT_NEAR(twice["depth_m"].get<double>(), d, 1e-12 * d);
  const nlohmann::json once = simulate_with_zone("paper_a_skin_blunt_bevel.toml",
                                                 "contact_zone = \"10 um\"", "--fidelity fast");
  ASSERT_TRUE(once.is_object());
  EXPECT_DOUBLE_EQ(once["mesh"]["contact_zone_m"].get<double>(), 10e-6);
  const double finer = once["needles"][0]["puncture"]["depth_m"].get<double>();
  EXPECT_NEAR(finer, 82.94e-6, 0.01 * 82.94e-6);
  EXPECT_LT(d / finer, 1.05);
  EXPECT_GT(d / finer, 1.0);
}

// A scene's `contact_zone = "none"` trades the flat's zone for speed: the blunt bevel then reads
// on the levels' coarse cells 100.237 / 102.064 / 103.580 um at fast / standard / fine (the
// README's numbers; 17-21 % deep), with no zone in the mesh and no warning about the zone (the
// scene asked for it; the linear stratum corneum pushed past its thickness is warned about, as on
// every run of these scenes).
TEST(CmdSimulate, ASceneCanTurnTheFlatsZoneOffAndReadsTheUnresolvedDepth) {
  // 100.03 / 101.79 um at fast / standard when first measured, 100.237 / 102.064 um since the
  // stress probe's mirror-invariant cut (docs/model.md, "Tip stress and cracked meshes"; the 1 %
  // pin of fast hid the move): 0.1 %.
  for (const auto& [fidelity, depth] : {std::pair<std::string, double>{"fast", 100.237e-6},
                                        {"standard", 102.064e-6},
                                        {"fine", 103.580e-6}}) {
    const nlohmann::json j = simulate_with_zone(
        "paper_a_skin_blunt_bevel.toml", "contact_zone = \"none\"", "--fidelity " + fidelity);
    ASSERT_TRUE(j.is_object()) << fidelity;
    EXPECT_DOUBLE_EQ(j["mesh"]["contact_zone_m"].get<double>(), 0.0);
    for (const auto& w : j["warnings"])
      EXPECT_EQ(w.get<std::string>().find("contact zone"), std::string::npos) << w;
    EXPECT_NEAR(j["needles"][0]["puncture"]["depth_m"].get<double>(), depth, 1e-3 * depth)
        << fidelity;
  }
}

// A flat end wider than 25 L (250 um in radius in skin) gets no zone of its own: the run says so
// in one warning naming the scene and the layer, and the mesh reports no zone. A 600 um cylinder
// on the 3-D model at fast.
TEST(CmdSimulate, AFlatEndTooWideForItsZoneIsReadOnCoarseCellsAndTheRunSaysSo) {
  const std::string source =
      std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/" + "paper_a_skin_cylinder.toml";
  std::string text = mneedle::test::file_text(source);
  const std::string key = "diameter = \"230 um\"";
  ASSERT_NE(text.find(key), std::string::npos);
  text.replace(text.find(key), key.size(), "diameter = \"600 um\"");
  const fs::path file =
      fs::temp_directory_path() / ("wide_flat_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << text;
  const CommandRun run =
      run_mneedle("simulate '" + file.string() + "' --fidelity fast --model 3d --json");
  fs::remove(file);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_DOUBLE_EQ(j["mesh"]["contact_zone_m"].get<double>(), 0.0);
  // The zone's warning; the other one is the small-strain stratum corneum's.
  std::vector<std::string> zone;
  for (const auto& w : j["warnings"])
    if (w.get<std::string>().find("contact zone") != std::string::npos) zone.push_back(w);
  ASSERT_EQ(zone.size(), 1u) << j["warnings"].dump();
  const std::string warning = zone[0];
  EXPECT_NE(warning.find("wide_flat_"), std::string::npos) << warning;
  EXPECT_NE(warning.find("stratum_corneum"), std::string::npos) << warning;
  EXPECT_NE(warning.find("no contact zone"), std::string::npos) << warning;
}

// The stress criterion on the analytic path (docs/model.md, "The stress criterion on the analytic
// path"): the stratum corneum as a plate on the epidermis, pressed at one point by a pointed tip,
// in series with the tip's own indentation of the layer. Every pointed tip punctures at the same
// force; the depth differs by that local indentation. Measured 2026-12-05: the cone 63.48 um and
// the sharp bevel 60.60 um, both at 5.207 mN, pinned to 1 % (closed form: a move is a change to
// explain); against the axisymmetric FE cone at standard (65.44 um, 5.522 mN) -3.0 % in depth and
// -5.7 % in force, within the 7 % this test allows. A flat end is refused in one line naming the
// scene and the layer, and so is a tip whose flank meets the bent layer before it breaks.
TEST(CmdSimulate, AnalyticStressCriterionInSkinPuncturesAPointedTipNearTheFeDepth) {
  const std::string skin = std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/human_skin.toml";
  std::string cone = mneedle::test::file_text(skin);
  const std::string bevel =
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length "
      "= \"1000 um\", bevel_angle = \"30 deg\" }";
  ASSERT_NE(cone.find(bevel), std::string::npos);
  cone.replace(cone.find(bevel), bevel.size(), "geometry = { plugin = \"cone\" }");
  const fs::path file =
      fs::temp_directory_path() / ("analytic_cone_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << cone;
  auto puncture_of = [](const std::string& scene, const std::string& model) {
    const CommandRun run =
        run_mneedle("simulate '" + scene + "' --model " + model + " --fidelity standard --json");
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return nlohmann::json::parse(run.out)["needles"][0]["puncture"];
  };
  const auto fe = puncture_of(file.string(), "axisymmetric");
  const auto closed = puncture_of(file.string(), "analytic");
  const auto bevel_closed = puncture_of(skin, "analytic");
  ASSERT_TRUE(fe.is_object() && closed.is_object() && bevel_closed.is_object());
  EXPECT_EQ(closed["criterion"], "stress");
  EXPECT_NEAR(closed["depth_m"].get<double>(), 63.48e-6, 0.01 * 63.48e-6);
  EXPECT_NEAR(closed["force_N"].get<double>(), 5.207e-3, 0.01 * 5.207e-3);
  const double d_fe = fe["depth_m"].get<double>();
  EXPECT_NEAR(closed["depth_m"].get<double>(), d_fe, 0.07 * d_fe);
  EXPECT_NEAR(closed["force_N"].get<double>(), fe["force_N"].get<double>(),
              0.07 * fe["force_N"].get<double>());
  EXPECT_NEAR(bevel_closed["depth_m"].get<double>(), 60.60e-6, 0.01 * 60.60e-6);
  // The same force, to the crossing's bisection (measured 1.3e-5 apart).
  EXPECT_NEAR(bevel_closed["force_N"].get<double>(), closed["force_N"].get<double>(),
              1e-4 * closed["force_N"].get<double>());
  // A cone of 88 deg half-angle meets the bent layer with its flank before the layer breaks.
  std::string blunt = cone;
  const std::string sharp_cone = "{ plugin = \"cone\" }";
  blunt.replace(blunt.find(sharp_cone), sharp_cone.size(),
                "{ plugin = \"cone\", half_angle = \"88 deg\" }");
  std::ofstream(file) << blunt;
  const CommandRun flank = run_mneedle("simulate '" + file.string() + "' --model analytic --json");
  EXPECT_EQ(flank.exit_code, 1);
  EXPECT_NE(flank.err.find("with its flank at"), std::string::npos) << flank.err;
  fs::remove(file);

  const CommandRun flat =
      run_mneedle("simulate '" + std::string(MNEEDLE_SOURCE_ROOT) +
                  "/designs/scenes/paper_a_skin_cylinder.toml' --model analytic --json");
  EXPECT_EQ(flat.exit_code, 1);
  EXPECT_NE(flat.err.find("paper_a_skin_cylinder.toml: "), std::string::npos) << flat.err;
  EXPECT_NE(flat.err.find("'stratum_corneum' with a flat end (as wide as a circle of 230 um"),
            std::string::npos)
      << flat.err;
  EXPECT_EQ(std::count(flat.err.begin(), flat.err.end(), '\n'), 1) << flat.err;
}

// The pressure criterion verified outside the FE (docs/validation.md, "Pressure over the
// section's outline"): paper A's cylinder in its silicone is a flat punch, F = 2 a E* d
// kappa_Hayes, which crosses P_c = F / (pi a^2) at d = pi a P_c / (2 E* kappa_Hayes) = 440.4 um on
// the scene's 5 mm layer (the analytic path is that closed form). The axisymmetric FE reads 433.8
// um at standard (-1.5 %); 2 % allowed, the FE's mesh error at standard against fine (440.0 um).
TEST(CmdSimulate, PressureCrossingOfAFlatPunchInSiliconeIsTheClosedFormsWithinTwoPercent) {
  const std::string file =
      std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/paper_a_silicone_cylinder.toml";
  auto depth = [&](const std::string& model) {
    const CommandRun run = run_mneedle("simulate '" + file + "' --model " + model + " --json");
    EXPECT_EQ(run.exit_code, 0) << run.err;
    const auto p = nlohmann::json::parse(run.out)["needles"][0]["puncture"];
    EXPECT_TRUE(p.is_object());
    return p.is_object() ? p["depth_m"].get<double>() : 0.0;
  };
  const double closed = depth("analytic");
  // d = pi a P_c / (2 E* kappa): a 115 um, P_c 0.663 MPa, E* = 0.2 MPa / (1 - 0.49^2).
  const double half_space = 3.14159265358979 * 115e-6 * 0.663e6 / (2.0 * 0.2e6 / (1 - 0.49 * 0.49));
  EXPECT_NEAR(half_space, 455.1e-6, 0.1e-6);
  EXPECT_NEAR(closed, 440.4e-6, 0.1e-6);  // Hayes' factor for a / H = 0.023: 1.033
  EXPECT_NEAR(depth("axisymmetric"), closed, 0.02 * closed);
}

// The README's "forces 3-30x below those measured in human skin": Roemgens et al. 2014 measured
// 20 mN at the drop for a 5 um tip and 167 mN for a 37 um tip (docs/validation.md, "Tip radius,
// against Roemgens"). Our cone with those tips on human_skin.toml (axisymmetric, standard):
// 61.8 um / 5.545 mN and 62.1 um / 5.646 mN, measured 2026-12-06 after captures in depth order
// (61.9 / 5.551 and 61.3 / 5.547 before: the 37 um cap was pinned whole at the first steps),
// pinned to 1 %; the misses are 3.6x and 30x, and the force does not rise with the tip.
TEST(CmdSimulate, RoundedConeTipsInSkinPunctureFarBelowTheForcesRoemgensMeasured) {
  std::string text = mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) +
                                              "/designs/scenes/human_skin.toml");
  const std::string bevel =
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length "
      "= \"1000 um\", bevel_angle = \"30 deg\" }";
  const auto at = text.find(bevel);
  ASSERT_NE(at, std::string::npos);
  const fs::path file =
      fs::temp_directory_path() / ("roemgens_" + std::to_string(::getpid()) + ".toml");
  struct Tip {
    std::string radius;
    double depth, force, measured;
  };
  for (const Tip& tip :
       {Tip{"2.5 um", 61.78e-6, 5.545e-3, 20e-3}, Tip{"18.5 um", 62.08e-6, 5.646e-3, 167e-3}}) {
    std::string scene = text;
    scene.replace(at, bevel.size(),
                  "geometry = { plugin = \"cone\", tip_radius = \"" + tip.radius + "\" }");
    std::ofstream(file) << scene;
    const CommandRun run = run_mneedle("simulate '" + file.string() + "' --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto p = nlohmann::json::parse(run.out)["needles"][0]["puncture"];
    ASSERT_TRUE(p.is_object()) << tip.radius;
    EXPECT_NEAR(p["depth_m"].get<double>(), tip.depth, 0.01 * tip.depth) << tip.radius;
    EXPECT_NEAR(p["force_N"].get<double>(), tip.force, 0.01 * tip.force) << tip.radius;
    const double miss = tip.measured / p["force_N"].get<double>();
    EXPECT_GE(miss, 3.0) << tip.radius;
    EXPECT_LE(miss, 31.0) << tip.radius;
  }
  fs::remove(file);
}

// A sharp bevel whose edges are rounded (tip_radius; docs/model.md, "Sharp bevel with a rounded
// edge") meets the skin with one rounded point: its lowest vertices, about 0.35 um apart within 1
// nm at 1 um, are one point to the planner, not a flat with a 2 L zone (which read 57.3 um on 11
// 387 nodes before the rule; docs/model.md, "Tissue block and mesh"). Paper A's skin sharp bevel at
// fast, measured 2026-12-07: 65.12 um at 1 um and 65.06 um at 5 um against the sharp bevel's 65.16
// um, pinned to 1 % (deterministic runs: a move is a change to explain). The stress criterion
// averages over L = 10 um, far wider than these roundings.
TEST(CmdSimulate, ARoundedBevelTipIsAPointContactAndPuncturesWhereTheSharpOneDoes) {
  std::string text = mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) +
                                              "/designs/scenes/paper_a_skin_sharp_bevel.toml");
  const std::string angle = "bevel_angle = \"30 deg\" }";
  const auto at = text.find(angle);
  ASSERT_NE(at, std::string::npos);
  const fs::path file =
      fs::temp_directory_path() / ("rounded_bevel_" + std::to_string(::getpid()) + ".toml");
  for (const auto& [radius, depth] : {std::pair{"1 um", 65.12e-6}, std::pair{"5 um", 65.06e-6}}) {
    std::string scene = text;
    scene.replace(at, angle.size(),
                  "bevel_angle = \"30 deg\", tip_radius = \"" + std::string(radius) + "\" }");
    std::ofstream(file) << scene;
    const CommandRun run = run_mneedle("simulate '" + file.string() + "' --fidelity fast --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j["mesh"]["contact_zone_m"].get<double>(), 0.0) << radius;
    const auto p = j["needles"][0]["puncture"];
    ASSERT_TRUE(p.is_object()) << radius;
    EXPECT_FALSE(p["at_first_contact"].get<bool>()) << radius;
    EXPECT_NEAR(p["depth_m"].get<double>(), depth, 0.01 * depth) << radius;
  }
  fs::remove(file);
}

// Three refinement levels built a coarse grid whose clearance dropped the bevel's tip line (R from
// the axis): no node lay under the tip, the force at 80 um read 0.41 mN against 0.94-1.00 mN at
// 0-2 levels and the puncture 712.2 um (docs/validation.md, "Refinement levels beyond two"). The
// clearance now stops at two levels' grid: 1.107 mN and 657.36 um, pinned to 0.1 % (deterministic
// runs); 4 levels, once 123 um in skin, are refused.
TEST(CmdSimulate, AThirdRefinementLevelKeepsTheBevelTipsGridLineAndAFourthIsRefused) {
  std::string text = mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) +
                                              "/designs/scenes/paper_a_silicone_sharp_bevel.toml");
  const std::string criterion = "criterion = \"pressure\"";
  ASSERT_NE(text.find(criterion), std::string::npos);
  const fs::path file =
      fs::temp_directory_path() / ("refinement_" + std::to_string(::getpid()) + ".toml");
  for (const int levels : {3, 4}) {
    std::string scene = text;
    scene.replace(scene.find(criterion), criterion.size(),
                  criterion + "\nmesh_refinement = " + std::to_string(levels));
    std::ofstream(file) << scene;
    const CommandRun run = run_mneedle("simulate '" + file.string() + "' --fidelity fast --json");
    if (levels == 4) {
      EXPECT_EQ(run.exit_code, 1);
      EXPECT_NE(run.err.find("model.mesh_refinement: must be 0 to 3, got 4"), std::string::npos)
          << run.err;
      continue;
    }
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto needle = nlohmann::json::parse(run.out)["needles"][0];
    EXPECT_NEAR(needle["curve"][0]["depth_m"].get<double>(), 80e-6, 1e-12);
    EXPECT_NEAR(needle["curve"][0]["force_N"].get<double>(), 1.107e-3, 1e-3 * 1.107e-3);
    EXPECT_NEAR(needle["puncture"]["depth_m"].get<double>(), 657.36e-6, 1e-3 * 657.36e-6);
  }
  fs::remove(file);
}

// Under the pressure criterion in skin a sharp tip fires at the first step: F/A_sec grows without
// bound toward the tip (docs/model.md, "Criteria", fires at first contact). A rounded one bounds
// it: paper A's skin sharp bevel with tip_radius 1 um at standard reads 2.814 MPa at its first
// step (5 um) and less at every step after, so P_c = 3 MPa is never reached, where the sharp
// bevel reads 5.205 MPa there (measured 2026-12-07; docs/validation.md, "A rounded tip resolved
// to rho/2", which shows cells of rho/2 moving that bound by 5 %, not the conclusion). Pinned to
// 0.1 % (deterministic runs: a move is a change to explain).
TEST(CmdSimulate,
     ARoundedBevelTipBoundsTheSectionPressureInSkinWhereTheSharpOneFiresAtFirstContact) {
  std::string text = mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) +
                                              "/designs/scenes/paper_a_skin_sharp_bevel.toml");
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"depth = \"800 um\"", "depth = \"100 um\""},
        std::pair<std::string, std::string>{"target_depth = \"200 um\"",
                                            "target_depth = \"100 um\""}}) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  const std::string angle = "bevel_angle = \"30 deg\" }";
  ASSERT_NE(text.find(angle), std::string::npos);
  const fs::path file =
      fs::temp_directory_path() / ("rounded_pressure_" + std::to_string(::getpid()) + ".toml");
  for (const auto& [radius, first_pressure] :
       {std::pair{"0 um", 5.20548e6}, std::pair{"1 um", 2.81386e6}}) {
    std::string scene = text;
    scene.replace(scene.find(angle), angle.size(),
                  "bevel_angle = \"30 deg\", tip_radius = \"" + std::string(radius) + "\" }");
    std::ofstream(file) << scene;
    const CommandRun run = run_mneedle("simulate '" + file.string() +
                                       "' --fidelity standard --criterion pressure --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto needle = nlohmann::json::parse(run.out)["needles"][0];
    const auto& curve = needle["curve"];
    ASSERT_FALSE(curve.empty()) << radius;
    EXPECT_NEAR(curve[0]["depth_m"].get<double>(), 5e-6, 1e-12) << radius;
    EXPECT_NEAR(curve[0]["section_pressure_Pa"].get<double>(), first_pressure,
                1e-3 * first_pressure)
        << radius;
    if (std::string(radius) == "0 um") {
      ASSERT_TRUE(needle["puncture"].is_object());
      EXPECT_TRUE(needle["puncture"]["at_first_contact"].get<bool>());
      continue;
    }
    EXPECT_TRUE(needle["puncture"].is_null());
    const double bound = curve[0]["section_pressure_Pa"].get<double>();
    EXPECT_LT(bound, 3e6);  // the scene's critical pressure
    for (std::size_t i = 1; i < curve.size(); ++i) {
      if (curve[i]["stage"] != "pre") continue;
      EXPECT_LE(curve[i]["section_pressure_Pa"].get<double>(), bound)
          << curve[i]["depth_m"].get<double>();
    }
  }
  fs::remove(file);
}

// The blunt bevel with every edge of its cut rounded (tip_radius; docs/model.md, "Blunt bevel with
// rounded edges"): its flat stays a flat at z = 0, narrower by 1.577 rho, so it keeps the level's
// 2 L zone over its outline. In that zone's 20 um cells the rim's move shows: 81.02 um at rho = 5
// um against 85.39 um sharp-edged (fast, 2026-12-07), as flat widths of 40-54 um scatter by 3-4 %
// at standard (docs/validation.md, "The blunt bevel with rounded edges"). With cells of L
// (contact_zone = "10 um") the rounding moves it by 0.3 % at most: 82.74 / 82.91 um at 5 / 10 um
// against 82.94 um (ABluntBevelsFlatIsMeshedWithCellsOfTwiceTheCriterionLength). Pinned to 1 %
// (deterministic runs).
TEST(CmdSimulate, ARoundedBluntBevelKeepsItsFlatZoneAndWithCellsOfLPuncturesAsTheSharpEdgedOne) {
  std::string text = mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) +
                                              "/designs/scenes/paper_a_skin_blunt_bevel.toml");
  const std::string flat = "flat_width = \"50 um\" }";
  const std::string contact = "contact = \"sticking\"";
  ASSERT_NE(text.find(flat), std::string::npos);
  ASSERT_NE(text.find(contact), std::string::npos);
  const fs::path file =
      fs::temp_directory_path() / ("rounded_blunt_" + std::to_string(::getpid()) + ".toml");
  struct Case {
    std::string radius;
    bool cells_of_l;
    double depth;
  };
  for (const Case& c : {Case{"5 um", false, 81.02e-6}, Case{"5 um", true, 82.74e-6},
                        Case{"10 um", true, 82.91e-6}}) {
    std::string scene = text;
    scene.replace(scene.find(flat), flat.size(),
                  "flat_width = \"50 um\", tip_radius = \"" + c.radius + "\" }");
    if (c.cells_of_l)
      scene.replace(scene.find(contact), contact.size(), contact + "\ncontact_zone = \"10 um\"");
    std::ofstream(file) << scene;
    const CommandRun run = run_mneedle("simulate '" + file.string() + "' --fidelity fast --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_EQ(j["mesh"]["contact_zone_m"].get<double>(), c.cells_of_l ? 10e-6 : 20e-6) << c.radius;
    const auto p = j["needles"][0]["puncture"];
    ASSERT_TRUE(p.is_object()) << c.radius;
    EXPECT_FALSE(p["at_first_contact"].get<bool>()) << c.radius;
    EXPECT_NEAR(p["depth_m"].get<double>(), c.depth, 0.01 * c.depth) << c.radius;
  }
  fs::remove(file);
}

// A finite-strain stratum corneum (docs/validation.md, "Finite strain in a stiff top layer"):
// paper A's skin cylinder and Roemgens' 37 um rounded cone with the layer's model "svk" puncture
// at fast where the measurement of 2026-12-06 put them, 91.1 um / 27.81 mN and 44.5 um /
// 5.770 mN (converged: standard and fine within 3 %), pinned to 1 %; against 148.8 um and
// 62.3 um on the shipped small-strain layer, which is what the run's warning is about. The
// README's cylinder at standard, 89.390 um (36.6 % above the linear layer's 140.918 um), to 0.1 %.
TEST(CmdSimulate, AFiniteStrainStratumCorneumPuncturesShallowerAndTheLinearOneIsWarnedAbout) {
  const std::string linear = "material = { model = \"linear\", E = \"1 GPa\", nu = 0.4 }";
  const std::string svk = "material = { model = \"svk\", E = \"1 GPa\", nu = 0.4 }";
  struct Case {
    std::string scene, replace, with;
    double depth, force;
  };
  const std::string bevel =
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length "
      "= \"1000 um\", bevel_angle = \"30 deg\" }";
  for (const Case& c :
       {Case{"paper_a_skin_cylinder.toml", "", "", 91.1e-6, 27.81e-3},
        Case{"human_skin.toml", bevel, "geometry = { plugin = \"cone\", tip_radius = \"18.5 um\" }",
             44.5e-6, 5.770e-3}}) {
    std::string text =
        mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/" + c.scene);
    if (!c.replace.empty()) {
      ASSERT_NE(text.find(c.replace), std::string::npos) << c.scene;
      text.replace(text.find(c.replace), c.replace.size(), c.with);
    }
    const fs::path file =
        fs::temp_directory_path() / ("finite_strain_" + std::to_string(::getpid()) + ".toml");
    std::ofstream(file) << text;
    const CommandRun small = run_mneedle("simulate '" + file.string() + "' --fidelity fast --json");
    ASSERT_EQ(small.exit_code, 0) << small.err;
    const auto j = nlohmann::json::parse(small.out);
    bool warned = false;
    for (const auto& w : j["warnings"])
      warned = warned || w.get<std::string>().find("membrane tension") != std::string::npos;
    EXPECT_TRUE(warned) << c.scene << ": " << j["warnings"].dump();
    const double small_depth = j["needles"][0]["puncture"]["depth_m"].get<double>();
    ASSERT_NE(text.find(linear), std::string::npos) << c.scene;
    text.replace(text.find(linear), linear.size(), svk);
    std::ofstream(file) << text;
    const CommandRun finite =
        run_mneedle("simulate '" + file.string() + "' --fidelity fast --json");
    fs::remove(file);
    ASSERT_EQ(finite.exit_code, 0) << finite.err;
    const auto f = nlohmann::json::parse(finite.out);
    EXPECT_TRUE(f["warnings"].empty()) << f["warnings"].dump();
    const auto& p = f["needles"][0]["puncture"];
    EXPECT_NEAR(p["depth_m"].get<double>(), c.depth, 0.01 * c.depth) << c.scene;
    EXPECT_NEAR(p["force_N"].get<double>(), c.force, 0.01 * c.force) << c.scene;
    EXPECT_LT(p["depth_m"].get<double>(), 0.8 * small_depth) << c.scene;
    if (c.scene != "paper_a_skin_cylinder.toml") continue;
    std::ofstream(file) << text;
    const CommandRun standard = run_mneedle("simulate '" + file.string() + "' --json");
    fs::remove(file);
    ASSERT_EQ(standard.exit_code, 0) << standard.err;
    const double d = nlohmann::json::parse(standard.out)["needles"][0]["puncture"]["depth_m"];
    EXPECT_NEAR(d, 89.390e-6, 1e-3 * 89.390e-6);
  }
}

// A run whose FE stops part-way (a sharp cone on a finite-strain stratum corneum inverts the
// element under its point between 40 and 50 um at fast) prints what it reached in every format,
// then the one-line error, and exits 3 (docs/cli.md, "simulate").
TEST(CmdSimulate, ARunWhoseSolverStopsPrintsWhatItReachedThenFails) {
  std::string text = mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) +
                                              "/designs/scenes/human_skin.toml");
  const std::string bevel =
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length = \"1000 um\", "
      "bevel_angle = \"30 deg\" }";
  const std::string linear = "material = { model = \"linear\", E = \"1 GPa\", nu = 0.4 }";
  ASSERT_NE(text.find(bevel), std::string::npos);
  text.replace(text.find(bevel), bevel.size(),
               "geometry = { plugin = \"cone\", diameter = \"230 um\", length = \"1000 um\" }");
  ASSERT_NE(text.find(linear), std::string::npos);
  text.replace(text.find(linear), linear.size(),
               "material = { model = \"svk\", E = \"1 GPa\", nu = 0.4 }");
  const fs::path file =
      fs::temp_directory_path() / ("stops_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << text;
  const CommandRun json = run_mneedle("simulate '" + file.string() + "' --fidelity fast --json");
  const CommandRun table = run_mneedle("simulate '" + file.string() + "' --fidelity fast --quiet");
  const fs::path svg = fs::temp_directory_path() / ("stops_" + std::to_string(::getpid()) + ".svg");
  const CommandRun plot = run_mneedle("simulate '" + file.string() +
                                      "' --fidelity fast --quiet --plot '" + svg.string() + "'");
  fs::remove(file);
  EXPECT_EQ(plot.exit_code, 3) << plot.err;
  const std::string drawn = mneedle::test::read_svg(svg);
  fs::remove(svg);
  EXPECT_TRUE(mneedle::test::has_text(mneedle::test::texts(drawn), "FE stopped")) << drawn.size();
  EXPECT_EQ(json.exit_code, 3) << json.err;
  EXPECT_EQ(std::count(json.err.begin(), json.err.end(), '\n'), 1) << json.err;
  EXPECT_EQ(json.err.rfind("mneedle: error: axisymmetric insertion stopped at depth ", 0), 0u)
      << json.err;
  EXPECT_NE(json.err.find("inverted element"), std::string::npos) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  EXPECT_NEAR(j["stopped"]["depth_m"].get<double>(), 40e-6, 1e-12);
  EXPECT_NE(j["stopped"]["reason"].get<std::string>().find("inverted element"), std::string::npos);
  EXPECT_GT(j["mesh"]["nodes"].get<int>(), 0);  // the mesh it stopped on
  const auto& needle = j["needles"].at(0);
  EXPECT_TRUE(needle["puncture"].is_null());
  ASSERT_EQ(needle["curve"].size(), 4u);  // 10, 20, 30, 40 um
  EXPECT_NEAR(needle["curve"].back()["depth_m"].get<double>(), 40e-6, 1e-12);
  EXPECT_GT(needle["curve"].back()["force_N"].get<double>(), 0.0);
  EXPECT_EQ(table.exit_code, 3) << table.err;
  EXPECT_NE(table.out.find("the finite element run stopped after its step at 40 um"),
            std::string::npos)
      << table.out;
  EXPECT_NE(table.out.find("no puncture before 40 um"), std::string::npos) << table.out;
}

TEST(CmdSimulate, SharpBevelFiresAtFirstContactOnAHalfModelAndSaysSo) {
  const CommandRun run = run_mneedle("simulate '" + scene("puncture_bevel.toml") + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  bool half = false;
  for (const auto& r : j["reductions"]) half = half || r["name"] == "half_model";
  EXPECT_TRUE(half) << j["reductions"].dump();
  const auto& p = j["needles"][0]["puncture"];
  ASSERT_TRUE(p.is_object());
  // A sharp bevel's F / A_sec is largest at the first step (0.49 MPa at 10 um here: the force is
  // carried by the node at the tip while the section's area starts from zero), above this
  // scene's 0.1 MPa: the criterion fires on contact, reported at the first step and flagged.
  EXPECT_TRUE(p["at_first_contact"].get<bool>());
  EXPECT_DOUBLE_EQ(p["depth_m"].get<double>(), j["pre_puncture_step_m"].get<double>());
  const auto& curve = j["needles"][0]["curve"];
  bool found = false;
  for (const auto& point : curve)
    if (point["stage"] == "pre" && point["depth_m"] == p["depth_m"]) {
      found = true;
      EXPECT_GE(point["section_pressure_Pa"].get<double>(), 0.1e6);
    }
  EXPECT_TRUE(found);
}

TEST(CmdSimulate, NoReductionsSolvesTheFullBevelModel) {
  const CommandRun half = run_mneedle("simulate '" + scene("puncture_bevel.toml") + "' --json");
  const CommandRun full =
      run_mneedle("simulate '" + scene("puncture_bevel.toml") + "' --no-reductions --json");
  ASSERT_EQ(half.exit_code, 0) << half.err;
  ASSERT_EQ(full.exit_code, 0) << full.err;
  const auto h = nlohmann::json::parse(half.out);
  const auto f = nlohmann::json::parse(full.out);
  EXPECT_TRUE(f["reductions"].empty()) << f["reductions"].dump();
  EXPECT_GT(f["mesh"]["nodes"].get<int>(), h["mesh"]["nodes"].get<int>());
  // The half model is exact for a mirror-symmetric bevel
  // (tests/core/insertion/test_insertion_run.cpp).
  EXPECT_NEAR(f["needles"][0]["puncture"]["depth_m"].get<double>(),
              h["needles"][0]["puncture"]["depth_m"].get<double>(), 1e-9);
}

TEST(CmdSimulate, CsvHasAStageColumn) {
  const CommandRun run = run_mneedle("simulate '" + scene("puncture_punch.toml") + "' --csv");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::istringstream lines(run.out);
  std::string provenance, header, row;
  std::getline(lines, provenance);  // "# provenance: {...}" (docs/cli.md, "Provenance")
  EXPECT_EQ(provenance.rfind("# provenance: ", 0), 0u) << provenance;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("depth_m,force_N,stage,", 0), 0u) << header;
  int post = 0;
  while (std::getline(lines, row)) post += row.find(",post,") != std::string::npos ? 1 : 0;
  EXPECT_GT(post, 0);
}

// The same needle and tissue give the same puncture through every path (docs/model.md,
// "Pre-puncture horizon"): the plugin or the STL `generate` wrote from the same parameters
// (within 2 %: the STL stores single-precision millimetres and the tissue grid follows the
// mesh's vertices), and `simulate` or `screen` on the STL (identical: one evaluation).
TEST(CmdSimulate, SameNeedleSamePunctureFromPluginStlSimulateAndScreen) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_paths_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const CommandRun gen = run_mneedle(
      "generate sharp_bevel --set diameter=230um --set length=1000um"
      " --set bevel_angle=30deg -o '" +
      (dir / "bevel.stl").string() + "'");
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  std::ifstream in(scene("bevel_silicone_3d.toml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string stl_scene = text.str();
  const std::string plugin_line =
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length = \"1000 um\", "
      "bevel_angle = \"30 deg\" }";
  const auto at = stl_scene.find(plugin_line);
  ASSERT_NE(at, std::string::npos);
  stl_scene.replace(at, plugin_line.size(), "geometry = { stl = \"bevel.stl\", unit = \"mm\" }");
  std::ofstream(dir / "stl.toml") << stl_scene;

  auto puncture_of = [](const CommandRun& run) {
    EXPECT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    EXPECT_TRUE(j["needles"][0]["puncture"].is_object()) << run.out;
    return j["needles"][0]["puncture"];
  };
  const auto plugin =
      puncture_of(run_mneedle("simulate '" + scene("bevel_silicone_3d.toml") + "' --json"));
  const auto stl =
      puncture_of(run_mneedle("simulate '" + (dir / "stl.toml").string() + "' --json"));
  ASSERT_TRUE(plugin.is_object() && stl.is_object());
  EXPECT_FALSE(plugin["at_first_contact"].get<bool>());
  const double d_plugin = plugin["depth_m"].get<double>();
  EXPECT_NEAR(stl["depth_m"].get<double>(), d_plugin, 0.02 * d_plugin);

  const CommandRun screened = run_mneedle("screen '" + (dir / "bevel.stl").string() +
                                          "' --scene '" + (dir / "stl.toml").string() + "' --json");
  ASSERT_EQ(screened.exit_code, 0) << screened.err;
  const auto row = nlohmann::json::parse(screened.out)["designs"][0];
  ASSERT_TRUE(row["punctured"].get<bool>()) << row.dump(2);
  EXPECT_EQ(row["puncture_depth_m"].get<double>(), stl["depth_m"].get<double>());
  EXPECT_EQ(row["puncture_force_N"].get<double>(), stl["force_N"].get<double>());
  fs::remove_all(dir);
}

// The first model a scene ran at fast and its needle's puncture depth (NaN and a test failure
// when the run fails or nothing punctures).
struct FastPuncture {
  std::string model;
  double depth_m = std::numeric_limits<double>::quiet_NaN();
};
FastPuncture fast_puncture(const fs::path& scene_file) {
  const CommandRun run =
      run_mneedle("simulate '" + scene_file.string() + "' --fidelity fast --json");
  EXPECT_EQ(run.exit_code, 0) << scene_file << ": " << run.err;
  if (run.exit_code != 0) return {};
  const auto j = nlohmann::json::parse(run.out);
  FastPuncture result;
  result.model = j["models_run"][0].get<std::string>();
  const auto& puncture = j["needles"][0]["puncture"];
  EXPECT_TRUE(puncture.is_object()) << scene_file;
  if (puncture.is_object()) result.depth_m = puncture["depth_m"].get<double>();
  return result;
}

// A round STL takes the axisymmetric model as its plugin does (design_source.h,
// revolution_profile): before, the cylinder's STL ran in 3-D and punctured human skin at 153.3 um
// against the plugin's 148.1 um (fast; 148.7 against 141.5 at standard). Now the two differ by
// the facets alone: 64 facets give an equal-area radius 0.08 % below the plugin's, which moved
// the depth by 0.04 % (measured); 0.5 % allowed.
TEST(CmdSimulate, ACylinderStlPuncturesSkinWhereItsPluginDoes) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_round_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const CommandRun gen =
      run_mneedle("generate cylinder --set diameter=230um --set length=1000um -o '" +
                  (dir / "cylinder.stl").string() + "'");
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  std::ifstream in(std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/human_skin.toml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string bevel_line =
      "geometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", length = \"1000 um\", "
      "bevel_angle = \"30 deg\" }";
  std::string plugin_scene = text.str(), stl_scene = text.str();
  ASSERT_NE(plugin_scene.find(bevel_line), std::string::npos);
  plugin_scene.replace(plugin_scene.find(bevel_line), bevel_line.size(),
                       "geometry = { plugin = \"cylinder\", diameter = \"230 um\", "
                       "length = \"1000 um\" }");
  stl_scene.replace(stl_scene.find(bevel_line), bevel_line.size(),
                    "geometry = { stl = \"cylinder.stl\", unit = \"mm\" }");
  std::ofstream(dir / "plugin.toml") << plugin_scene;
  std::ofstream(dir / "stl.toml") << stl_scene;
  const auto plugin = fast_puncture(dir / "plugin.toml"), stl = fast_puncture(dir / "stl.toml");
  EXPECT_EQ(plugin.model, "axisymmetric_fe");
  EXPECT_EQ(stl.model, "axisymmetric_fe");
  EXPECT_NEAR(stl.depth_m, plugin.depth_m, 0.005 * plugin.depth_m);
  fs::remove_all(dir);
}

// The rounded blunt bevel (tip_radius 5 um) and the STL `generate` writes of it give one
// puncture: before the needle frame's second pass over the shaft's faces the pipes' last steps
// tilted the STL's axis by 4.6e-5 rad, which lifted part of its flat 2 nm out of the first
// contact and took its base out of the base's level, and it read 85.32 um against the plugin's
// 81.02 um (+5.3 %; docs/validation.md, "Needle meshes"). Now the two meshes match node for node
// at fast (measured: the same 19 388 nodes and depth); 0.5 % allowed for the STL's
// single-precision vertices.
TEST(CmdSimulate, ARoundedBluntBevelStlPuncturesSkinWhereItsPluginDoes) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_rblunt_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const CommandRun gen = run_mneedle(
      "generate blunt_bevel --set diameter=230um --set bore=90um --set length=2.5mm"
      " --set bevel_angle=30deg --set flat_width=50um --set tip_radius=5um --unit um -o '" +
      (dir / "blunt.stl").string() + "'");
  ASSERT_EQ(gen.exit_code, 0) << gen.err;
  const std::string text = mneedle::test::file_text(
      std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/paper_a_skin_blunt_bevel.toml");
  const std::string flat = "flat_width = \"50 um\" }";
  const auto line = text.find("geometry = { plugin = \"blunt_bevel\"");
  ASSERT_NE(line, std::string::npos);
  const auto end = text.find('\n', line);
  std::string plugin_scene = text, stl_scene = text;
  ASSERT_NE(plugin_scene.find(flat), std::string::npos);
  plugin_scene.replace(plugin_scene.find(flat), flat.size(),
                       "flat_width = \"50 um\", tip_radius = \"5 um\" }");
  stl_scene.replace(line, end - line, "geometry = { stl = \"blunt.stl\", unit = \"um\" }");
  std::ofstream(dir / "plugin.toml") << plugin_scene;
  std::ofstream(dir / "stl.toml") << stl_scene;
  const double plugin = fast_puncture(dir / "plugin.toml").depth_m;
  EXPECT_NEAR(fast_puncture(dir / "stl.toml").depth_m, plugin, 0.005 * plugin);
  fs::remove_all(dir);
}

// `simulate --json` on a shipped scene with each `edits` text (found in it, or a test failure)
// replaced; an empty run when one is missing.
CommandRun simulate_edited_scene(const std::string& scene,
                                 const std::vector<std::pair<std::string, std::string>>& edits,
                                 const std::string& name) {
  std::string text =
      mneedle::test::file_text(std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/" + scene);
  for (const auto& [from, to] : edits) {
    if (text.find(from) == std::string::npos) {
      ADD_FAILURE() << scene << ": no " << from;
      return {};
    }
    text.replace(text.find(from), from.size(), to);
  }
  const fs::path file =
      fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << text;
  CommandRun run = run_mneedle("simulate '" + file.string() + "' --json");
  fs::remove(file);
  return run;
}

// Paper A's hollow cylinder (10 um rim) in its silicone as a neo-Hookean solid, intact (P_c so
// high that nothing fires): its tangent turns indefinite from 400 um, where the silicone under
// the wall is compressed to a stretch of 0.3-0.4, and Newton stalled there, at 415.3 um
// (docs/validation.md, "Why Newton stalls there"). Past such a bifurcation the solver shifts
// the tangent and steps down the potential energy (docs/model.md, "Solver"): the run now reaches
// 500 um, its force rising all the way and its strain energy equal to the work within 0.14 %
// (the run's own energy check, 5 %). F(480 um) = 28.61 mN measured 2026-12-07 (fast); pinned to
// 1 % (deterministic runs).
TEST(CmdSimulate, ANeoHookeanCylinderInSiliconeRunsPastTheBifurcationWhereNewtonStalled) {
  const CommandRun run = simulate_edited_scene(
      "paper_a_silicone_cylinder.toml",
      {{"model = \"linear\", E = \"0.2 MPa\"", "model = \"neo_hookean\", E = \"0.2 MPa\""},
       {"critical_pressure = \"0.663 MPa\"", "critical_pressure = \"10 GPa\""},
       {"length = \"2.5 mm\" }", "length = \"2.5 mm\", edge_radius = \"10 um\" }"},
       {"depth = \"2 mm\"", "depth = \"500 um\""},
       {"fidelity = \"standard\"", "fidelity = \"fast\""}},
      "neo_hookean_cylinder");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const auto& curve = j["needles"][0]["curve"];
  ASSERT_GE(curve.size(), 2u);
  EXPECT_NEAR(curve.back()["depth_m"].get<double>(), 500e-6, 1e-12);
  double previous = 0.0;
  bool found = false;
  for (const auto& point : curve) {
    const double force = point["force_N"].get<double>();
    EXPECT_GT(force, previous) << point["depth_m"].get<double>();
    previous = force;
    if (std::abs(point["depth_m"].get<double>() - 480e-6) < 1e-12) {
      EXPECT_NEAR(force, 28.61e-3, 0.01 * 28.61e-3);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(j["energy_check"]["passes"].get<bool>());
}

// Paper A's two measured puncture forces in its silicone, 14 mN (sharp bevel at 0.23 mm) and
// 217 mN (blunt bevel at 1.226 mm), against our intact pre-puncture force with its stated
// E = 0.2 MPa (P_c so high that nothing fires): both are 2.4-3.2 times ours. The force scales
// with E exactly (docs/model.md, "Calibration"), so one factor k fitted on the sharp bevel's
// point predicts the blunt bevel's: at fast k = 2.384 (E = 0.48 MPa) and 164 mN, 24 % below
// 217 mN; at standard 188 mN, 13 % below (docs/validation.md, "One modulus for both of paper A's
// forces"). The forces are pinned to 1 % (deterministic runs, as the neighbouring tests).
TEST(CmdSimulate, PaperAsSharpAndBluntBevelForcesAreOneModulusFactorApartWithinTheDocumentedMiss) {
  const auto intact = [](const std::string& scene, const std::string& depth) {
    const CommandRun run = simulate_edited_scene(
        scene,
        {{"critical_pressure = \"0.663 MPa\"", "critical_pressure = \"10 GPa\""},
         {"depth = \"2 mm\"", "depth = \"" + depth + "\""},
         {"fidelity = \"standard\"", "fidelity = \"fast\""}},
        "paper_a_modulus");
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.exit_code == 0 ? nlohmann::json::parse(run.out) : nlohmann::json{};
  };
  const double sharp = force_at(
      intact("paper_a_silicone_sharp_bevel.toml", "400 um")["needles"][0]["curve"], 230e-6);
  const double blunt = force_at(
      intact("paper_a_silicone_blunt_bevel.toml", "1.3 mm")["needles"][0]["curve"], 1.226e-3);
  EXPECT_NEAR(sharp, 5.872e-3, 0.01 * 5.872e-3);
  EXPECT_NEAR(blunt, 68.85e-3, 0.01 * 68.85e-3);
  const double k = 14e-3 / sharp;
  EXPECT_NEAR(k * blunt / 217e-3 - 1.0, -0.244, 0.01);
}

// Paper A's own two-stage model punctured its sharp bevel in silicone at "less than 20 um" with
// P_c = 0.663 MPa (docs/validation.md, "Paper A's own simulated punctures"). Ours at 20 um
// (standard, P_c raised so that nothing fires): 0.0882 mN over an FE contact area of
// 0.688e-9 m^2 and a section of 0.772e-9 m^2, a fifth of P_c whichever area divides it. Pinned to
// 0.1 % (deterministic runs; a move is a change to explain).
TEST(CmdSimulate, PaperAsSharpBevelAtTwentyMicronsPressesAFifthOfItsCriticalPressure) {
  const CommandRun run = simulate_edited_scene(
      "paper_a_silicone_sharp_bevel.toml",
      {{"critical_pressure = \"0.663 MPa\"", "critical_pressure = \"10 GPa\""},
       {"depth = \"2 mm\"", "depth = \"100 um\""},
       {"target_depth = \"300 um\"", "target_depth = \"100 um\""}},
      "paper_a_twenty_microns");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  bool found = false;
  for (const auto& point : j["needles"][0]["curve"]) {
    if (std::abs(point["depth_m"].get<double>() - 20e-6) > 1e-12) continue;
    found = true;
    const double force = point["force_N"].get<double>();
    const double contact = point["contact_area_m2"].get<double>();
    const double section = point["section_area_m2"].get<double>();
    EXPECT_NEAR(force, 0.08817e-3, 1e-3 * 0.08817e-3);
    EXPECT_NEAR(contact, 0.6875e-9, 1e-3 * 0.6875e-9);
    EXPECT_NEAR(section, 0.7717e-9, 1e-3 * 0.7717e-9);
    EXPECT_LT(force / contact, 0.663e6 / 4.0);
    EXPECT_LT(force / section, 0.663e6 / 4.0);
  }
  EXPECT_TRUE(found);
}

// The same rule in 3-D (docs/model.md, the 3-D "Solver" paragraph): paper A's sharp bevel in
// neo-Hookean silicone, a 1.2 x 1.2 x 0.8 mm block at fast, whose tangent fails Cholesky past
// 200 um (three shifted factorisations to 300 um, measured; none at standard on this block).
// The run reaches 300 um, its force rises, its energy check passes, and F(300 um) = 12.10 mN,
// measured 2026-12-07 (fast; 11.08 mN at standard), pinned to 1 % as the cylinder's above
// (deterministic runs).
TEST(CmdSimulate, ANeoHookeanSharpBevelRunsPastWhereItsTangentStopsBeingPositiveDefinite) {
  const CommandRun run = simulate_edited_scene(
      "paper_a_silicone_sharp_bevel.toml",
      {{"size = [\"10 mm\", \"10 mm\", \"5 mm\"]", "size = [\"1.2 mm\", \"1.2 mm\", \"0.8 mm\"]"},
       {"model = \"linear\", E = \"0.2 MPa\"", "model = \"neo_hookean\", E = \"0.2 MPa\""},
       {"critical_pressure = \"0.663 MPa\"", "critical_pressure = \"10 GPa\""},
       {"depth = \"2 mm\"", "depth = \"300 um\""},
       {"fidelity = \"standard\"", "fidelity = \"fast\""}},
      "neo_hookean_bevel");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_GE(j["seconds_by_stage"]["shifted_factorizations"].get<int>(), 1);
  const auto& curve = j["needles"][0]["curve"];
  ASSERT_GE(curve.size(), 2u);
  double previous = 0.0;
  for (const auto& point : curve) {
    if (point["stage"] != "pre") continue;
    EXPECT_GT(point["force_N"].get<double>(), previous) << point["depth_m"].get<double>();
    previous = point["force_N"].get<double>();
  }
  const auto& last = curve.back();
  EXPECT_NEAR(last["depth_m"].get<double>(), 300e-6, 1e-12);
  EXPECT_NEAR(last["force_N"].get<double>(), 12.10e-3, 0.01 * 12.10e-3);
  EXPECT_TRUE(j["energy_check"]["passes"].get<bool>());
}
}  // namespace

namespace {

// One gel, 0.2 MPa, with paper A's silicone fracture data, under a 200 um cone (axisymmetric,
// fast); `layers` is the [[tissue.layers]] part.
std::string gel_scene(const std::string& layers) {
  return "[tissue]\nsize = [\"4 mm\", \"4 mm\", \"2 mm\"]\nboundary = \"fixed\"\n" + layers +
         "\n[tissue.fracture]\ntoughness = \"19 J/m^2\"\ncritical_pressure = \"0.663 MPa\"\n"
         "\n[[needles]]\nname = \"cone\"\ngeometry = { plugin = \"cone\", diameter = \"200 um\", "
         "length = \"2 mm\" }\n\n[insertion]\ndepth = \"1 mm\"\n\n[model]\nfidelity = \"fast\"\n"
         "criterion = \"pressure\"\ncontact = \"sticking\"\n";
}

std::string gel_layer(const std::string& name, const std::string& thickness,
                      const std::string& modulus) {
  return "\n[[tissue.layers]]\nname = \"" + name + "\"\n" +
         (thickness.empty() ? "" : "thickness = \"" + thickness + "\"\n") +
         "material = { model = \"linear\", E = \"" + modulus + "\", nu = 0.49 }\n";
}

// The gel scene's cone without its length: the plugin's default (1 mm) is known only from its
// mesh, and 1 mm of insertion reaches it. The scene refuses a written length that short; this
// ran on past the base with the force of the last section (exit 0).
TEST(CmdSimulate, ANeedleWhoseMeshIsShorterThanTheDepthIsRefusedLikeAWrittenLength) {
  std::string text = gel_scene(gel_layer("gel", "", "0.2 MPa"));
  text.replace(text.find(", length = \"2 mm\""), 17, "");
  const fs::path file = fs::temp_directory_path() / "mneedle_short_cone.toml";
  std::ofstream(file) << text;
  for (const char* model : {"", " --model analytic"}) {
    const CommandRun run = run_mneedle("simulate '" + file.string() + "'" + model);
    EXPECT_EQ(run.exit_code, 1) << model;
    EXPECT_NE(run.err.find(":13: needle 'cone': the needle is 1 mm long (its mesh) and "
                           "insertion.depth = 1 mm would put its base into the tissue"),
              std::string::npos)
        << run.err;
  }
  fs::remove(file);
}

double gel_puncture_depth(const fs::path& file, const std::string& layers) {
  std::ofstream(file) << gel_scene(layers);
  const CommandRun run = run_mneedle("simulate '" + file.string() + "' --json");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const auto& puncture = j["needles"][0]["puncture"];
  EXPECT_FALSE(puncture.is_null()) << file;
  return puncture.is_null() ? 0.0 : puncture["depth_m"].get<double>();
}

TEST(CmdSimulate, OneMaterialSplitIntoLayersPuncturesWhereTheUnsplitOneDoes) {
  // Splitting one gel at 50, 150 or 300 um once gave "punctures at 25.6 um" or "no puncture".
  // Split into identical layers (which the planner may merge) and into layers whose moduli
  // differ by 1e-6 (which it may not), the same physics must give the same depth.
  const fs::path dir = fs::temp_directory_path() / ("mneedle_split_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const double whole = gel_puncture_depth(dir / "one.toml", gel_layer("gel", "", "0.2 MPa"));
  {
    // The run's energy ledger up to the puncture: the axisymmetric cone stores 0.7 % less than
    // the trapezoid work (docs/model.md, "Energy check"); a sign error or a lost step is 100 %.
    const CommandRun run = run_mneedle("simulate '" + (dir / "one.toml").string() + "' --json");
    const auto j = nlohmann::json::parse(run.out);
    ASSERT_TRUE(j["energy_check"].is_object()) << run.out;
    EXPECT_TRUE(j["energy_check"]["passes"].get<bool>());
    EXPECT_NEAR(j["energy_check"]["depth_m"].get<double>(), whole, 1e-12);
    EXPECT_GT(j["peak_memory_bytes"].get<double>(), 1e6);
    // No energy warning (a run slower than 2 s also prints progress lines there, so look for
    // the warning, not for an empty stderr: under load this run once took 21 s).
    EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;
  }
  ASSERT_GT(whole, 100e-6);  // 639 um: well below every split
  for (const std::string thickness : {"50 um", "150 um", "300 um"}) {
    SCOPED_TRACE(thickness);
    const double identical =
        gel_puncture_depth(dir / "identical.toml", gel_layer("top", thickness, "0.2 MPa") +
                                                       gel_layer("bottom", "", "0.2 MPa"));
    const double near =
        gel_puncture_depth(dir / "near.toml", gel_layer("top", thickness, "0.2 MPa") +
                                                  gel_layer("bottom", "", "0.2000002 MPa"));
    // An interface is a plane of the mesh, so a split may move the grid under the tip: 0.48 %
    // at 300 um, nothing at 50 and 150 um. 1 % keeps that well inside the fast mesh's own
    // puncture-depth error (about 10 % against fine, docs/validation.md, "Pressure criterion
    // under a sharp tip") while a wrong answer (a puncture at the interface, none at all) is off
    // by tens of per cent.
    EXPECT_NEAR(identical / whole, 1.0, 0.01);
    EXPECT_NEAR(near / whole, 1.0, 0.01);
    // A modulus 1e-6 away may change the planner's merge decision but not the answer: the force
    // moves by at most 1e-6 relative, the depth by that over the slope of the pressure's
    // logarithm in depth's (order one here); measured 3.6e-7, and 1e-5 leaves a factor 10.
    EXPECT_NEAR(near / identical, 1.0, 1e-5);
  }
  fs::remove_all(dir);
}

TEST(CmdSimulate, PlotDrawsTheCurveWithItsAxesAndUnits) {
  const auto svg = std::filesystem::temp_directory_path() /
                   ("mneedle_simulate_plot_" + std::to_string(::getpid()) + ".svg");
  const CommandRun run = run_mneedle("simulate '" + scene("axisymmetric_punch.toml") +
                                     "' --plot '" + svg.string() + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string text = mneedle::test::read_svg(svg);
  std::filesystem::remove(svg);
  const auto t = mneedle::test::texts(text);
  EXPECT_TRUE(mneedle::test::has_text(t, "simulate: axisymmetric_punch.toml"));
  bool depth_axis = false;
  for (const auto& x : t) depth_axis |= x.text.rfind("depth below the surface [", 0) == 0;
  EXPECT_TRUE(depth_axis);
  EXPECT_FALSE(mneedle::test::polyline(text, "#1F77B4").empty());
}

}  // namespace

namespace {

TEST(CmdSimulate, PenetrationCriterionReportsItsForceAtEveryStepAndFiresWhereTheForceReachesIt) {
  // A 200 um cone in one gel (axisymmetric, fast): the criterion is F / F_p, threshold 1, and at
  // the bisected crossing F equals F_p of the section there to the bisection's 1e-6 of a step.
  const fs::path dir =
      fs::temp_directory_path() / ("mneedle_penetration_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "gel.toml";
  std::ofstream(file) << gel_scene(gel_layer("gel", "", "0.2 MPa"));
  const CommandRun run =
      run_mneedle("simulate '" + file.string() + "' --criterion penetration --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("warning"), std::string::npos) << run.err;  // one thick layer
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j["criterion"]["name"], "penetration");
  EXPECT_EQ(j["criterion"]["threshold"].get<double>(), 1.0);
  const auto& needle = j["needles"][0];
  ASSERT_FALSE(needle["puncture"].is_null()) << run.out;
  const auto& puncture = needle["puncture"];
  EXPECT_FALSE(puncture["at_first_contact"].get<bool>());
  EXPECT_FALSE(puncture["flat_tip"].get<bool>());  // a cone ends in a point
  double previous_fp = 0.0;
  const nlohmann::json* at_puncture = nullptr;
  for (const auto& p : needle["curve"]) {
    if (p["stage"] != "pre") continue;
    ASSERT_TRUE(p.contains("penetration_force_N")) << p.dump();
    // The cone's section widens with depth up to its shaft, so F_p never falls.
    EXPECT_GE(p["penetration_force_N"].get<double>(), previous_fp);
    previous_fp = p["penetration_force_N"].get<double>();
    at_puncture = &p;
  }
  ASSERT_NE(at_puncture, nullptr);
  EXPECT_EQ((*at_puncture)["depth_m"].get<double>(), puncture["depth_m"].get<double>());
  const double force = puncture["force_N"].get<double>();
  EXPECT_NEAR(force, (*at_puncture)["penetration_force_N"].get<double>(), 1e-5 * force);

  // A top layer thinner than the needle is no half-space: the run says so on stderr.
  std::ofstream(file) << gel_scene(gel_layer("film", "50 um", "0.2 MPa") +
                                   gel_layer("gel", "", "0.2 MPa"));
  const CommandRun thin = run_mneedle("simulate '" + file.string() + "' --criterion penetration");
  ASSERT_EQ(thin.exit_code, 0) << thin.err;
  EXPECT_NE(thin.err.find("warning"), std::string::npos) << thin.err;
  EXPECT_NE(thin.err.find("'film' is 50 um thick"), std::string::npos) << thin.err;
  EXPECT_NE(thin.err.find("takes it for a half-space"), std::string::npos) << thin.err;
  EXPECT_NE(thin.out.find("F_p [mN]"), std::string::npos) << thin.out;

  // A brittle gel (toughness / (E r) = 5e-5): the crack would run wider than the table, F_p is
  // an upper bound, and the run says so.
  std::string brittle = gel_scene(gel_layer("gel", "", "0.2 MPa"));
  brittle.replace(brittle.find("19 J/m^2"), 8, "0.001 J/m^2");
  std::ofstream(file) << brittle;
  const CommandRun weak = run_mneedle("simulate '" + file.string() + "' --criterion penetration");
  ASSERT_EQ(weak.exit_code, 0) << weak.err;
  EXPECT_NE(weak.err.find("F_p is an upper bound"), std::string::npos) << weak.err;
  fs::remove_all(dir);
}

}  // namespace
