// `mneedle screen` and `mneedle strength` end to end: the README's main job ranked by puncture
// depth, bad designs among good ones, results kept on disk, JSON with units in its keys.
#include <gtest/gtest.h>
#include <cstdio>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>
#include <thread>
#include <vector>

#include "fe/needle_meshes.h"
#include "mneedle/needle/mesh_io.h"
#include "run_mneedle.h"

namespace {

namespace fs = std::filesystem;
using mneedle::test::run_mneedle;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;
const std::string kSkin = kRoot + "/designs/scenes/human_skin.toml";
// The same with the pressure criterion, for the closed-form pre-puncture model (it has no stress
// field for the scene's own stress criterion).
const std::string kSkinPressure = mneedle::test::skin_scene_with_criterion("pressure");

TEST(ScreenCommand, ReadmeMainJobRanksEveryShippedDesignByPunctureDepth) {
  const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin + "' --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The scene's linear stratum corneum is pushed past its 20 um before every puncture: one
  // warning for the run, at the deepest design, the cylinder (docs/validation.md, "Finite strain
  // in a stiff top layer").
  EXPECT_NE(run.err.find("membrane tension"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("design 'cylinder"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("membrane tension"), run.err.rfind("membrane tension")) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["warnings"].size(), 1u) << j["warnings"].dump();
  EXPECT_NE(run.err.find(j["warnings"][0].get<std::string>()), std::string::npos) << run.err;
  ASSERT_EQ(j["designs"].size(), 4u);
  EXPECT_EQ(j["fidelity"], "fast");
  // What the README says of this table: with the scene's stress criterion every design punctures
  // at a resolved depth (none at first contact), cone < sharp bevel < blunt bevel < cylinder,
  // each at the depth the README quotes (fast; standard and fine within 6 %). Pinned to 0.1 %
  // (1 % until 2026-12-07, which let the sticking anchor's 0.34 % move of the blunt bevel pass
  // unseen for a session; the runs read the same to the printed digits on Intel and AMD VMs,
  // docs/speed-accuracy.md): the run is deterministic, so any move is a change of the model or
  // the mesh to explain
  // (docs/validation.md, "The stress criterion in skin"; the cone moved 62.3 -> 62.8 um with the
  // pointed-tip mesh rule of the axisymmetric model, docs/model.md "Mesh"; the blunt bevel
  // 100.0 -> 85.8 um with its flat meshed in cells of 2 L, docs/model.md "Tissue block and mesh";
  // both bevels by -0.2 to -0.4 % when the stress probe began cutting each element in an order its
  // mirror image keeps, docs/model.md "Tip stress and cracked meshes": 65.4 -> 65.16 and 85.81
  // -> 85.64 um; the blunt bevel 85.64 -> 85.68 um when fast graded the column under its flat,
  // docs/model.md "Tissue block and mesh"; 85.68 -> 85.39 um when a node entering the needle's
  // side was held where it entered, docs/model.md "Contact with the rigid needle (sticking)").
  std::map<std::string, nlohmann::json> by_name;
  for (const auto& d : j["designs"]) {
    EXPECT_TRUE(d["ok"].get<bool>()) << d.dump();
    EXPECT_GT(d["peak_force_N"].get<double>(), 0.0);
    EXPECT_GT(d["capacity_N"].get<double>(), 0.0);
    EXPECT_DOUBLE_EQ(d["target_depth_m"].get<double>(), 200e-6);
    by_name[d["design"].get<std::string>()] = d;
  }
  const std::vector<std::pair<std::string, double>> readme = {{"cone", 62.82e-6},
                                                              {"sharp_bevel", 65.16e-6},
                                                              {"blunt_bevel", 85.39e-6},
                                                              {"cylinder", 148.0e-6}};
  for (std::size_t i = 0; i < readme.size(); ++i) {
    const auto& [name, depth] = readme[i];
    const auto& d = by_name[name];
    ASSERT_TRUE(d["punctured"].get<bool>()) << name;
    EXPECT_FALSE(d["puncture_at_first_contact"].get<bool>()) << name;
    EXPECT_NEAR(d["puncture_depth_m"].get<double>(), depth, 1e-3 * depth) << name;
    EXPECT_TRUE(d["passes"].get<bool>()) << name;
    EXPECT_EQ(j["designs"][i]["design"], name) << "rank " << i + 1;
  }
  // The ranking's invariants: punctured rows first, each within the target depth and at a force
  // no larger than the peak its curve reaches.
  bool seen_unpunctured = false;
  for (const auto& d : j["designs"]) {
    if (!d["punctured"].get<bool>()) {
      seen_unpunctured = true;
      continue;
    }
    EXPECT_FALSE(seen_unpunctured) << "a punctured design ranked after one that is not";
    EXPECT_GT(d["puncture_depth_m"].get<double>(), 0.0);
    EXPECT_LE(d["puncture_depth_m"].get<double>(), 200e-6);
    EXPECT_GT(d["puncture_force_N"].get<double>(), 0.0);
    EXPECT_LE(d["puncture_force_N"].get<double>(), d["peak_force_N"].get<double>() * (1 + 1e-9));
  }
}

// The README's claim on the same table at the finer levels: "`standard` and `fine` read each
// within 6 % of these". Measured 2026-12-05 (standard / fine, um): cone 65.44 / 65.79, sharp
// bevel 65.76 / 62.75, blunt bevel 85.47 / 85.68 (2026-12-06, its flat meshed in cells of 2 L
// at every level: 101.79 / 104.51 before, against fast's 100.0), cylinder 141.43 / 140.52; the
// largest gap to fast is the cylinder's -5.1 % at fine (the sharp bevel's -4.1 %). Fine resolves
// the sharp bevel's tip since 2026-12-06 (it read 68.97 um, +5.5 %, before; docs/model.md,
// "Tissue block and mesh"). The stress probe's mirror-invariant cut (2026-12-06, docs/model.md
// "Tip stress and cracked meshes") moved the bevels: standard 65.80 / 85.40, fine 62.70 / 85.75
// um; the sharp bevel's gap to fast at fine is now -3.8 %. Fine's growth 1.35 -> 1.6
// (2026-12-07, docs/model.md "Tissue block and mesh") moved its bevels to 63.06 / 84.55 um
// (+0.6 % / -1.4 %), both inside their converged bands (63.4-63.8 um and 84.0-85.8 um,
// docs/validation.md, "The stress criterion in skin"); fine's sharp bevel 63.14 um since a node
// entering the needle's side is held where it entered. Fast's blunt bevel reads 85.68 um since
// its column under the flat was graded (2026-12-07; 85.64 um before), 85.39 um since a node
// entering the needle's side is held where it entered (docs/model.md, "Contact with the rigid
// needle (sticking)").
// Each level is also pinned to 0.1 % of its own reading (1 % until 2026-12-07, which hid the
// sticking anchor's moves for a session), so that a move inside the 6 % is seen and explained.
TEST(ScreenCommand, ReadmeMainJobReadsWithinSixPercentOfFastAtStandardAndFine) {
  const std::map<std::string, double> fast = {{"cone", 62.8e-6},
                                              {"sharp_bevel", 65.16e-6},
                                              {"blunt_bevel", 85.39e-6},
                                              {"cylinder", 148.0e-6}};
  const std::map<std::string, std::map<std::string, double>> level = {{"standard",
                                                                       {{"cone", 65.44e-6},
                                                                        {"sharp_bevel", 65.80e-6},
                                                                        {"blunt_bevel", 85.40e-6},
                                                                        {"cylinder", 141.43e-6}}},
                                                                      {"fine",
                                                                       {{"cone", 65.79e-6},
                                                                        {"sharp_bevel", 63.14e-6},
                                                                        {"blunt_bevel", 84.55e-6},
                                                                        {"cylinder", 140.52e-6}}}};
  for (const auto& [fidelity, depths] : level) {
    const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin +
                                 "' --fidelity " + fidelity + " --jobs 2 --json");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const auto j = nlohmann::json::parse(run.out);
    ASSERT_EQ(j["designs"].size(), 4u);
    std::vector<std::string> order;
    for (const auto& d : j["designs"]) {
      const std::string name = d["design"].get<std::string>();
      order.push_back(name);
      SCOPED_TRACE(fidelity + " " + name);
      ASSERT_TRUE(d["punctured"].get<bool>());
      EXPECT_FALSE(d["puncture_at_first_contact"].get<bool>());
      const double depth = d["puncture_depth_m"].get<double>();
      EXPECT_NEAR(depth, fast.at(name), 0.06 * fast.at(name));
      EXPECT_NEAR(depth, depths.at(name), 1e-3 * depths.at(name));
    }
    // Paper A's order at every level: sharp tips first, the flat end last.
    EXPECT_EQ(order.back(), "cylinder") << fidelity;
    EXPECT_EQ(order[2], "blunt_bevel") << fidelity;
  }
}

// The puncture depth is a continuous function of every design parameter (docs/model.md,
// "Contact with the rigid needle (sticking)"): blunt bevels of 32 and 33 deg in skin read
// 85.67 and 85.67 um at fast (2026-12-07, with fast's column under the flat graded; 85.64 and
// 85.63 um before it, 85.81 both before the probe's mirror-invariant cut), 45 deg 85.39 um; since
// a node entering the needle's side is held where it entered (docs/model.md, "Contact with the
// rigid needle (sticking)") 85.39, 85.39 and 85.13 um. Until
// captures were grouped over a fiftieth of the surface spacing instead of a quarter, the 33 deg
// bevel's first capture event took a row of nodes 0.4 um beside its flat, whose face was 0.62 um
// above them against the group's 0.625 um, pulled them onto the needle, and read 79.80 um: a 7 %
// step for one degree. The three are pinned to 1 % (deterministic runs) and 32/33 deg asked to
// agree to 0.1 %.
TEST(ScreenCommand, ABluntBevelsPunctureDepthDoesNotJumpWithItsBevelAngle) {
  const fs::path dir = fs::temp_directory_path() / ("angles_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream list(dir / "designs.toml");
  for (int angle : {32, 33, 45})
    list << "[[designs]]\nname = \"blunt_" << angle
         << "\"\nplugin = \"blunt_bevel\"\nbevel_angle = \"" << angle << " deg\"\n\n";
  list.close();
  const auto run = run_mneedle("screen '" + (dir / "designs.toml").string() + "' --scene '" +
                               kSkin + "' --jobs 2 --json");
  fs::remove_all(dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  std::map<std::string, double> depth;
  for (const auto& d : j["designs"]) {
    ASSERT_TRUE(d["punctured"].get<bool>()) << d.dump();
    depth[d["design"].get<std::string>()] = d["puncture_depth_m"].get<double>();
  }
  ASSERT_EQ(depth.size(), 3u);
  EXPECT_NEAR(depth["blunt_32"], 85.39e-6, 0.01 * 85.39e-6);
  EXPECT_NEAR(depth["blunt_33"], 85.39e-6, 0.01 * 85.39e-6);
  EXPECT_NEAR(depth["blunt_45"], 85.13e-6, 0.01 * 85.13e-6);
  EXPECT_NEAR(depth["blunt_33"], depth["blunt_32"], 1e-3 * depth["blunt_32"]);
}

// The analytic model in skin: the stratum corneum spreads a flat punch's load as in the FE (the
// cylinder's F / A_sec stays below 3 MPa to 200 um; docs/validation.md), so neither shipped STL
// punctures. (Until the round-off guard of the equivalent needle the flat STL cylinder carried
// 207 N at the first step and "punctured at first contact".)
TEST(ScreenCommand, AnalyticModelInSkinLetsNeitherFlatNorSharpStlPuncture) {
  const std::string designs =
      "'" + kRoot + "/designs/cylinder.stl' '" + kRoot + "/designs/sharp_bevel.stl'";
  const auto run =
      run_mneedle("screen " + designs + " --scene '" + kSkinPressure + "' --model analytic --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  ASSERT_EQ(j["designs"].size(), 2u);
  EXPECT_EQ(j["model"], "analytic");
  for (const auto& d : j["designs"]) {
    EXPECT_EQ(d["models_run"][0], "analytic") << d.dump();
    EXPECT_FALSE(d["punctured"].get<bool>()) << d.dump();
    // The FE gives 20-25 mN at 200 um for these needles (docs/validation.md, "Layered skin
    // after the puncture"); 50 mN catches a return of the newton-sized answers.
    EXPECT_LT(d["peak_force_N"].get<double>(), 0.05) << d.dump();
  }
  // Nothing punctures, and the closed form is small strain whatever the layer: no advice.
  EXPECT_EQ(run.err.find("membrane tension"), std::string::npos) << run.err;
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"].dump();
}

// With a threshold below the pressure of the first depth step the criterion fires "at first
// contact": the depth is the step's, marked * in the table and flagged in the JSON.
TEST(ScreenCommand, DepthAtFirstContactIsMarkedWithAStar) {
  std::ifstream in(kSkinPressure);
  std::stringstream text;
  text << in.rdbuf();
  std::string scene = text.str();
  scene.replace(scene.find("critical_pressure = \"3 MPa\""), 27, "critical_pressure = \"1 kPa\"");
  const auto file = std::filesystem::temp_directory_path() /
                    ("mneedle_first_contact_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << scene;
  const std::string args = "screen '" + kRoot + "/designs/cylinder.stl' --scene '" + file.string() +
                           "' --model analytic";
  const auto run = run_mneedle(args + " --json");
  const auto table = run_mneedle(args);
  std::filesystem::remove(file);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j["designs"][0]["puncture_at_first_contact"].get<bool>()) << j.dump(2);
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find(" um* "), std::string::npos) << table.out;
}

TEST(ScreenCommand, BrokenDesignGetsAnErrorRowAndTheOthersAreKept) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_screen_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  fs::copy_file(kRoot + "/designs/cone.stl", dir / "in" / "cone.stl");
  fs::copy_file(std::string(MNEEDLE_TEST_ASSETS) + "/meshes/open_box.stl",
                dir / "in" / "broken.stl");
  const auto run = run_mneedle("screen '" + (dir / "in").string() + "' --scene '" + kSkinPressure +
                               "' --model analytic --out '" + (dir / "out").string() + "'");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("1 of 2 designs failed"), std::string::npos) << run.err;
  EXPECT_NE(run.out.find("not closed"), std::string::npos) << run.out;
  std::ifstream jsonl(dir / "out" / "results.jsonl");
  int lines = 0;
  for (std::string line; std::getline(jsonl, line);) ++lines;
  EXPECT_EQ(lines, 2);
  fs::remove_all(dir);
}

// A CAD export: the needle standing on its holder, long axis along +y (tip up), in mm, moved off
// the origin. With the default --axis auto the needle is found, cut from its holder and placed;
// it must give the bare needle's row. Tolerances: the cut lies 1e-6 of the mesh's height below
// the holder's face, so the needle is 2 nm shorter (capacity ~ 1/L^2: 4e-6 relative); the
// puncture reads the tip, which only the rotation's round-off moves (1e-9 relative).
TEST(ScreenCommand, NeedleOnAHolderExportedYUpGivesTheBareNeedlesRow) {
  const double radius = 150e-6, length = 1e-3;
  const double cone = radius / std::tan(std::numbers::pi / 12.0);
  std::vector<std::array<double, 2>> rings{{0.0, 0.0}};
  for (int k = 1; k <= 8; ++k) rings.push_back({radius * k / 8.0, cone * k / 8.0});
  rings.push_back({radius, length});
  const mneedle::TriangleMesh bare = mneedle::test::revolved_needle(rings, 48);
  rings.push_back({2.5e-3, length});
  rings.push_back({2.5e-3, length + 1e-3});
  mneedle::TriangleMesh held = mneedle::test::revolved_needle(rings, 48);
  for (mneedle::Vec3& p : held.vertices) p = {p[0] + 1e-3, -p[2] + 2e-3, p[1] + 3e-3};  // y up
  const auto dir =
      std::filesystem::temp_directory_path() / ("mneedle_holder_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  mneedle::write_stl_binary(bare, dir / "bare.stl", 1e-3);
  mneedle::write_stl_binary(held, dir / "on_holder.stl", 1e-3);
  const auto run = run_mneedle("screen '" + dir.string() + "' --scene '" + kRoot +
                               "/designs/scenes/optimize_silicone.toml' --model analytic --unit mm "
                               "--json");
  std::filesystem::remove_all(dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::map<std::string, nlohmann::json> by_name;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  for (const auto& d : out["designs"]) by_name[d["design"].get<std::string>()] = d;
  const auto& a = by_name.at("bare");
  const auto& b = by_name.at("on_holder");
  ASSERT_TRUE(a["ok"].get<bool>() && b["ok"].get<bool>()) << run.out;
  EXPECT_NE(b["frame_note"].get<std::string>().find("holder"), std::string::npos);
  const double cap = a["capacity_N"].get<double>();
  EXPECT_NEAR(b["capacity_N"].get<double>(), cap, 1e-5 * cap);
  const double len = a["length_m"].get<double>();
  EXPECT_NEAR(b["length_m"].get<double>(), len, 1e-5 * len);
  const double depth = a["puncture_depth_m"].get<double>();
  EXPECT_NEAR(b["puncture_depth_m"].get<double>(), depth, 1e-9 * depth);
  const double peak = a["peak_force_N"].get<double>();
  EXPECT_NEAR(b["peak_force_N"].get<double>(), peak, 1e-6 * peak);
}

TEST(ScreenCommand, RepairLetsAnInwardMeshThroughAndSaysWhatChanged) {
  const std::string mesh = std::string(MNEEDLE_TEST_ASSETS) + "/meshes/all_flipped.stl";
  const std::string scene = kRoot + "/designs/scenes/silicone_phantom.toml";
  const auto plain =
      run_mneedle("screen '" + mesh + "' --scene '" + scene + "' --model analytic --json");
  EXPECT_EQ(plain.exit_code, 1);
  EXPECT_NE(plain.out.find("screen --repair"), std::string::npos) << plain.out;
  const auto repaired =
      run_mneedle("screen '" + mesh + "' --scene '" + scene + "' --model analytic --repair --json");
  ASSERT_EQ(repaired.exit_code, 0) << repaired.err;
  const auto row = nlohmann::json::parse(repaired.out)["designs"][0];
  EXPECT_TRUE(row["ok"].get<bool>());
  EXPECT_EQ(row["frame_note"], "repaired: reoriented 6 faces");
}

TEST(ScreenCommand, ResumeWithoutOutIsAnError) {
  const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin + "' --resume");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--resume needs --out"), std::string::npos) << run.err;
}

// A results file that cannot take a row (a full disk; here /dev/full behind results.csv): the
// finished design's row says it was not saved, no further design is evaluated, and the run exits
// 1 (rows were cut off with exit 0). A device in place of results.jsonl is refused (reading it
// for --resume never ended).
TEST(ScreenCommand, ResultsThatCannotBeWrittenStopTheBatchAndFailIt) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path out = fs::temp_directory_path() / "mneedle_screen_full";
  fs::remove_all(out);
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out / "results.csv");
  const std::string designs =
      "'" + kRoot + "/designs/cone.stl' '" + kRoot + "/designs/sharp_bevel.stl'";
  const auto run = run_mneedle("screen " + designs + " --scene '" + kSkin +
                               "' --model analytic --out '" + out.string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.out.find("evaluated, but the results in --out could not be written (No space"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("not evaluated: the results in --out could not be written"),
            std::string::npos)
      << run.out;
  fs::remove_all(out);
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out / "results.jsonl");
  const auto device = run_mneedle("screen " + designs + " --scene '" + kSkin +
                                  "' --model analytic --out '" + out.string() + "' --resume");
  EXPECT_EQ(device.exit_code, 1);
  EXPECT_NE(device.err.find("results.jsonl: not a regular file"), std::string::npos) << device.err;
  fs::remove_all(out);
}

// A design that failed for want of memory (under MNEEDLE_MEMORY_LIMIT) is evaluated again on
// --resume, and the table keeps its new row only (such rows were resumed as they were, for
// ever).
TEST(ScreenCommand, ResumeEvaluatesAFailedDesignAgainAndTheTableKeepsItsNewRow) {
  const fs::path out = fs::temp_directory_path() / "mneedle_screen_retry";
  fs::remove_all(out);
  const std::string args = "screen '" + kRoot + "/designs/cone.stl' --scene '" + kSkin +
                           "' --out '" + out.string() + "'";
  const auto starved = mneedle::test::run_command("MNEEDLE_MEMORY_LIMIT='1 MB' '" +
                                                  mneedle::test::mneedle_binary() + "' " + args);
  EXPECT_EQ(starved.exit_code, 1) << starved.err;
  const auto resumed = run_mneedle(args + " --resume");
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  std::ifstream in(out / "results.csv");
  int rows = 0, failed = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("\"cone\",", 0) != 0) continue;
    ++rows;
    failed += line.rfind("\"cone\",false", 0) == 0 ? 1 : 0;
  }
  EXPECT_EQ(rows, 1);
  EXPECT_EQ(failed, 0);
  fs::remove_all(out);
}

// A file that declares its unit (mneedle's STL header: `generate --unit um`) is read in it, as a
// scene's STL needle is; it was read in --unit's mm, a needle 1000 times too large.
TEST(ScreenCommand, AMeshFileThatDeclaresItsUnitIsReadInIt) {
  const fs::path dir = fs::temp_directory_path() / "mneedle_screen_units";
  fs::create_directories(dir);
  for (const char* unit : {"um", "mm"}) {
    const auto gen = run_mneedle("generate cone --unit " + std::string(unit) + " -o '" +
                                 (dir / (std::string("cone_") + unit + ".stl")).string() + "'");
    ASSERT_EQ(gen.exit_code, 0) << gen.err;
  }
  const auto run = run_mneedle("screen '" + (dir / "cone_um.stl").string() + "' '" +
                               (dir / "cone_mm.stl").string() + "' --scene '" + kSkin +
                               "' --model analytic --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto rows = nlohmann::json::parse(run.out)["designs"];
  ASSERT_EQ(rows.size(), 2u);
  // The same cone: the same puncture to the files' single precision.
  const double a = rows[0]["puncture_depth_m"].get<double>();
  const double b = rows[1]["puncture_depth_m"].get<double>();
  EXPECT_NEAR(a / b, 1.0, 1e-5);
  fs::remove_all(dir);
}

// A --report path that cannot be a folder is refused before any design runs (it was refused
// after the whole batch, and the table was lost with it).
TEST(ScreenCommand, AReportPathThatIsAFileIsRefusedBeforeAnyDesign) {
  const fs::path file = fs::temp_directory_path() / "mneedle_screen_report_file";
  std::ofstream(file) << "x";
  const auto run = run_mneedle("screen '" + kRoot + "/designs/cone.stl' --scene '" + kSkin +
                               "' --report '" + file.string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("--report '" + file.string() + "': is a file, not a folder"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("done "), std::string::npos) << run.err;
  fs::remove(file);
}

// docs/scene.md: every command that takes a scene checks it as `scene check` does. screen
// replaces the scene's needles by the designs, but a scene whose own needle is wrong (a misspelled
// plugin parameter, one without its unit) is refused with its file and line before any design
// runs (it was accepted, exit 0); so is an unknown --material (every FE model ran first, then each
// row failed) and a folder with no designs (the message now names it).
TEST(ScreenCommand, ASceneWhoseNeedleSceneCheckRefusesAndAnUnknownMaterialStopItBeforeAnyDesign) {
  const fs::path dir = fs::temp_directory_path() / ("screen_refuses_" + std::to_string(::getpid()));
  fs::create_directories(dir / "empty");
  const std::string text = mneedle::test::file_text(kSkin);
  const std::string angle = "bevel_angle = \"30 deg\"";
  ASSERT_NE(text.find(angle), std::string::npos);
  int line = 1;
  for (std::size_t i = 0; i < text.rfind("[[needles]]", text.find(angle)); ++i)
    line += text[i] == '\n' ? 1 : 0;
  for (const auto& [with, problem] :
       {std::pair<std::string, std::string>{"bevel_angel = \"30 deg\"",
                                            "has no parameter 'bevel_angel'"},
        std::pair<std::string, std::string>{"bevel_angle = 30",
                                            "geometry.bevel_angle needs a unit"}}) {
    std::string scene = text;
    scene.replace(scene.find(angle), angle.size(), with);
    const fs::path file = dir / "scene.toml";
    std::ofstream(file) << scene;
    const auto check = run_mneedle("scene check '" + file.string() + "'");
    const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + file.string() + "'");
    const std::string where =
        file.string() + ":" + std::to_string(line) + ": needle 'sharp_bevel': ";
    for (const auto* r : {&check, &run}) {
      EXPECT_EQ(r->exit_code, 1) << with;
      EXPECT_NE(r->err.find(where), std::string::npos) << r->err;
      EXPECT_NE(r->err.find(problem), std::string::npos) << r->err;
    }
    EXPECT_EQ(run.err.find("done"), std::string::npos) << run.err;
  }
  const auto material =
      run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkin + "' --material plaa");
  EXPECT_EQ(material.exit_code, 1);
  EXPECT_NE(material.err.find("screen: needle material: unknown needle material 'plaa'"),
            std::string::npos)
      << material.err;
  EXPECT_EQ(material.err.find("done"), std::string::npos) << material.err;
  EXPECT_EQ(material.out, "");
  const auto empty =
      run_mneedle("screen '" + (dir / "empty").string() + "' --scene '" + kSkin + "'");
  EXPECT_EQ(empty.exit_code, 1);
  EXPECT_NE(empty.err.find("found in " + (dir / "empty").string()), std::string::npos) << empty.err;
  fs::remove_all(dir);
}

TEST(ScreenCommand, TablePrintsTheMarginToFourSignificantDigitsWhateverItsSize) {
  // A 1 Pa gel: the cone's margin is about 7e10; the table printed its first six characters,
  // "732099", as if it were 7e5.
  const fs::path dir = fs::temp_directory_path() / ("mneedle_margin_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "scene.toml") << R"([tissue]
size = ["10 mm", "10 mm", "5 mm"]
[[tissue.layers]]
name = "gel"
material = { model = "linear", E = "1 Pa", nu = 0.49 }
[tissue.fracture]
toughness = "0.019 N/mm"
critical_pressure = "0.663 MPa"
[[needles]]
name = "n"
geometry = { plugin = "cylinder", diameter = "230 um", length = "2.5 mm" }
material = "silicon"
[insertion]
depth = "50 um"
speed = "1 mm/s"
)";
  std::ofstream(dir / "designs.toml") << "[[designs]]\nname = \"cone\"\nplugin = \"cone\"\n";
  const std::string args = "screen '" + (dir / "designs.toml").string() + "' --scene '" +
                           (dir / "scene.toml").string() + "' --model analytic";
  const auto json = run_mneedle(args + " --json");
  ASSERT_LE(json.exit_code, 1) << json.err;  // a design that fails its target still has a row
  const double margin = nlohmann::json::parse(json.out)["designs"][0]["margin"].get<double>();
  ASSERT_GT(margin, 1e9);
  char expected[32];
  std::snprintf(expected, sizeof expected, " %.4g ", margin);
  const auto table = run_mneedle(args);
  EXPECT_NE(table.out.find(expected), std::string::npos) << expected << "\n" << table.out;
  fs::remove_all(dir);
}

TEST(StrengthCommand, CylinderPluginBucklesAtEulersLoadOverTheWholeLength) {
  // Silicon cylinder 230 µm × 1 mm, flat tip (load from the tip), fixed-free: π²EI/(2L)².
  const auto run = run_mneedle(
      "strength --plugin cylinder --set diameter=230um --set length=1mm --material silicon "
      "--end fixed-free --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto j = nlohmann::json::parse(run.out);
  const double pi = 3.14159265358979323846, r = 115e-6, length = 1e-3, e = 169e9;
  const double euler = pi * pi * e * (pi * r * r * r * r / 4.0) / (4.0 * length * length);
  EXPECT_NEAR(j["elastic_buckling_N"].get<double>() / euler, 1.0, 1e-3);
  EXPECT_EQ(j["governing"], "buckling");
  EXPECT_DOUBLE_EQ(j["effective_length_factor"].get<double>(), 2.0);
  for (const char* key :
       {"material", "E_Pa", "I_min_m4", "length_m", "buckling_N", "strength_N", "capacity_N"})
    EXPECT_TRUE(j.contains(key)) << key;
}

// A 230 um cylinder exported in mm and read as um is 230 nm wide: a unit mistake, said so.
TEST(StrengthCommand, ANeedleOfImplausibleWidthWarnsOfTheUnit) {
  const auto run =
      run_mneedle("strength '" + kRoot + "/designs/cylinder.stl' --unit um --material silicon");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("warning: the needle is 230 nm wide"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("unit"), std::string::npos) << run.err;
}

TEST(StrengthCommand, MeshFileAndPluginAgree) {
  const auto plugin = run_mneedle("strength --plugin sharp_bevel --material silicon --json");
  const auto mesh =
      run_mneedle("strength '" + kRoot + "/designs/sharp_bevel.stl' --material silicon --json");
  ASSERT_EQ(plugin.exit_code, 0) << plugin.err;
  ASSERT_EQ(mesh.exit_code, 0) << mesh.err;
  const auto a = nlohmann::json::parse(plugin.out), b = nlohmann::json::parse(mesh.out);
  EXPECT_NEAR(b["capacity_N"].get<double>() / a["capacity_N"].get<double>(), 1.0, 0.02);
}

TEST(StrengthCommand, UnknownMaterialAndMissingNeedleAreClearErrors) {
  auto run = run_mneedle("strength --plugin cone --material unobtainium");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("unknown needle material 'unobtainium'"), std::string::npos) << run.err;
  run = run_mneedle("strength --material silicon");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("either a mesh FILE or --plugin"), std::string::npos) << run.err;
}

}  // namespace

namespace {

// Starts `program` (default mneedle) with `arguments` (output discarded) and sends it `signal`
// after `delay` unless it has finished by then; true when it finished on its own.
bool finished_before_kill(const std::vector<std::string>& arguments,
                          std::chrono::microseconds delay, int signal = SIGKILL,
                          const std::string& program = mneedle::test::mneedle_binary()) {
  const std::string binary = program;
  std::vector<char*> argv{const_cast<char*>(binary.c_str())};
  for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  const auto end = std::chrono::steady_clock::now() + delay;
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ::kill(pid, signal);
  ::waitpid(pid, &status, 0);
  return false;
}

std::vector<nlohmann::json> jsonl_rows(const fs::path& file) {
  std::vector<nlohmann::json> rows;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    nlohmann::json row = nlohmann::json::parse(line);
    row.erase("seconds");  // the timings are the only fields that may differ between runs
    row.erase("insertion_seconds");
    rows.push_back(std::move(row));
  }
  return rows;
}

TEST(ScreenCommand, KilledAndResumedAgainAndAgainListsEveryDesignOnceWithUninterruptedNumbers) {
  // SIGKILL at seeded moments (at most 20 kills), each time resumed: a kill can land inside a
  // JSON line, between a row's JSON and CSV lines, or during the resume's own rewrite of the CSV.
  const fs::path dir = fs::temp_directory_path() / ("mneedle_kill_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream list(dir / "designs.toml");
  for (int i = 0; i < 48; ++i)
    list << "[[designs]]\nname = \"cone_" << i << "\"\nplugin = \"cone\"\ndiameter = \""
         << 150 + 5 * i << " um\"\n\n";
  list.close();
  const std::string scene = kRoot + "/designs/scenes/paper_a_silicone_blunt_bevel.toml";
  const auto arguments = [&](const std::string& out) {
    return std::vector<std::string>{"screen",  (dir / "designs.toml").string(),
                                    "--scene", scene,
                                    "--model", "analytic",
                                    "--jobs",  "2",
                                    "--out",   (dir / out).string(),
                                    "--resume"};
  };
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(finished_before_kill(arguments("whole"), std::chrono::seconds(120)));
  const auto whole_run = std::chrono::duration_cast<std::chrono::microseconds>(
      std::chrono::steady_clock::now() - start);

  // Each run lives a twentieth to a quarter of a whole one (start-up is about a twentieth), so
  // it finishes a few designs before its kill; sooner or later one outlives its kill. The whole
  // run's time is one sample on a machine whose load varies: when a run outlives its kill before
  // five kills, the series starts again in a fresh folder with delays half as long, so the test
  // checks five or more kills whatever the load (it is the kills that test something, not their
  // timing).
  std::mt19937 random(2026);
  int kills = 0;
  for (long scale = 1; kills < 5 && scale <= 8; scale *= 2) {
    fs::remove_all(dir / "killed");
    std::uniform_int_distribution<long> delay_us(whole_run.count() / (20 * scale),
                                                 whole_run.count() / (4 * scale));
    kills = 0;
    while (kills < 20 &&
           !finished_before_kill(arguments("killed"), std::chrono::microseconds(delay_us(random))))
      ++kills;
  }
  ASSERT_GE(kills, 5) << "too few kills to test anything, even with delays an eighth as long";
  ASSERT_TRUE(finished_before_kill(arguments("killed"), std::chrono::seconds(120)));

  std::map<std::string, nlohmann::json> whole;
  for (const auto& row : jsonl_rows(dir / "whole" / "results.jsonl"))
    whole[row["design"].get<std::string>()] = row;
  ASSERT_EQ(whole.size(), 48u);
  std::map<std::string, int> seen;
  for (const auto& row : jsonl_rows(dir / "killed" / "results.jsonl")) {
    const std::string design = row["design"].get<std::string>();
    ++seen[design];
    EXPECT_EQ(row, whole[design]) << design;
  }
  EXPECT_EQ(seen.size(), 48u);
  for (const auto& [design, count] : seen) EXPECT_EQ(count, 1) << design;

  std::ifstream csv(dir / "killed" / "results.csv");
  std::string header;
  // One provenance line per run that wrote into the folder (the killed one and the resume), as
  // in provenance.jsonl, then the header.
  std::ifstream runs(dir / "killed" / "provenance.jsonl");
  for (std::string run; std::getline(runs, run);) {
    ASSERT_TRUE(std::getline(csv, header));
    EXPECT_EQ(header, "# provenance: " + run);
  }
  ASSERT_TRUE(std::getline(csv, header));
  EXPECT_EQ(header.rfind("design,", 0), 0u) << header;
  const auto fields = [](const std::string& line) {
    return std::count(line.begin(), line.end(), ',') + 1;
  };
  std::map<std::string, int> csv_seen;
  for (std::string line; std::getline(csv, line);) {
    EXPECT_EQ(fields(line), fields(header)) << line;
    ++csv_seen[line.substr(0, line.find(','))];
  }
  EXPECT_EQ(csv_seen.size(), 48u);
  for (const auto& [design, count] : csv_seen) EXPECT_EQ(count, 1) << design;
  fs::remove_all(dir);
}

// Under each row of a screen with --uncertainty: P(pass) with its binomial standard error over
// the samples that ran (docs/model.md, "Uncertainty from tissue variability"). The exit status is
// not asked for: on the closed form the flat-ended designs are error rows (exit 1), the others
// are screened.
TEST(ScreenCommand, UncertaintyLineGivesThePassProbabilityWithItsStandardError) {
  const auto run = run_mneedle("screen '" + kRoot + "/designs' --scene '" + kSkinPressure +
                               "' --model analytic --uncertainty 6 --seed 3 --vary "
                               "'fracture.critical_pressure=uniform(0.5MPa,6MPa)'");
  std::istringstream lines(run.out);
  int seen = 0, between = 0;
  for (std::string line; std::getline(lines, line);) {
    double p = 0.0, error = 0.0;
    int samples = 0;
    if (std::sscanf(line.c_str(), " P(pass) %lf %% (standard error %lf %%) of %d samples", &p,
                    &error, &samples) != 3)
      continue;
    ++seen;
    between += p > 0.0 && p < 100.0;
    EXPECT_EQ(samples, 6) << line;
    // P is k of the 6 samples that ran (none fails here); the error from k exactly, against the
    // printed one within half its last digit (0.05 %).
    const double k = std::round(p / 100.0 * 6.0);
    EXPECT_NEAR(error, 100.0 * std::sqrt(k / 6.0 * (1.0 - k / 6.0) / 6.0), 0.05) << line;
  }
  EXPECT_GE(seen, 1) << run.out << run.err;
  EXPECT_GE(between, 1) << run.out;  // a share strictly between 0 and 1, whose error is not 0
}

TEST(ScreenCommand, UncertaintyAndVaryNeedEachOtherAndABadPathFailsBeforeAnyDesign) {
  const std::string designs =
      "'" + kRoot + "/designs' --scene '" + kSkinPressure + "' --model analytic";
  const auto no_vary = run_mneedle("screen " + designs + " --uncertainty 5");
  EXPECT_EQ(no_vary.exit_code, 1);
  EXPECT_NE(no_vary.err.find("--vary"), std::string::npos) << no_vary.err;
  const auto no_samples =
      run_mneedle("screen " + designs + " --vary 'dermis.E=uniform(1kPa,2kPa)'");
  EXPECT_EQ(no_samples.exit_code, 1);
  EXPECT_NE(no_samples.err.find("--uncertainty"), std::string::npos) << no_samples.err;
  const auto bad = run_mneedle("screen " + designs +
                               " --uncertainty 5 --vary 'dermis.Young=uniform(1kPa,2kPa)'");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("dermis.Young"), std::string::npos) << bad.err;
  EXPECT_EQ(bad.err.find("done"), std::string::npos) << "no design ran: " << bad.err;
}

#ifdef MNEEDLE_MPIEXEC
// screen --mpi under the MPI launcher CMake found (docs/performance.md, "Screening on a cluster").
using mneedle::test::mpirun;
using mneedle::test::shell_words;

// The rows of a --json screen by design, without what may differ between runs (timings) or
// says how the row was reached (resumed).
std::map<std::string, nlohmann::json> rows_by_design(const std::string& json_text) {
  std::map<std::string, nlohmann::json> rows;
  const auto result = nlohmann::json::parse(json_text);  // outlives the loop over its rows
  for (auto row : result["designs"]) {
    for (const char* key : {"seconds", "insertion_seconds", "resumed"}) row.erase(key);
    rows[row["design"].get<std::string>()] = row;
  }
  return rows;
}

std::vector<std::string> ranked_names(const std::string& json_text) {
  std::vector<std::string> names;
  const auto result = nlohmann::json::parse(json_text);
  for (const auto& row : result["designs"]) names.push_back(row["design"].get<std::string>());
  return names;
}

// Whether any process still has `text` on its command line (/proc): a rank that outlived its
// mpirun would be a second writer in the folder the next run resumes.
bool process_mentions(const std::string& text) {
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string pid = entry.path().filename().string();
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(entry.path() / "cmdline", std::ios::binary);
    std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (cmdline.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(ScreenCommand, TwoMpiRanksGiveTheSerialRowsBitForBitAndTheSameRanking) {
  // FE designs (the three shipped bevels and cylinder as STL, two cones through the plugin) so
  // that CHOLMOD, OpenBLAS and METIS all run. Serial --jobs 2 and the MPI ranks both evaluate
  // each design on one OpenBLAS thread: the same arithmetic, so equal to the last bit.
  const fs::path dir = fs::temp_directory_path() / ("mneedle_mpi_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "cones.toml")
      << "[[designs]]\nname = \"cone_a\"\nplugin = \"cone\"\ndiameter = \"150 um\"\n\n"
         "[[designs]]\nname = \"cone_b\"\nplugin = \"cone\"\ndiameter = \"200 um\"\n";
  const std::vector<std::string> inputs{
      "screen", kRoot + "/designs", (dir / "cones.toml").string(), "--scene", kSkin, "--json"};
  std::string serial_args;
  for (const auto& w : inputs) serial_args += " '" + w + "'";
  const auto serial =
      run_mneedle(serial_args + " --jobs 2 --out '" + (dir / "serial").string() + "'");
  ASSERT_EQ(serial.exit_code, 0) << serial.err;

  for (const std::string jobs : {"1", "2"}) {
    auto words = mpirun(2, inputs);
    for (const std::string w : {"--jobs", jobs.c_str(), "--out"}) words.push_back(w);
    words.push_back((dir / ("mpi" + jobs)).string());
    const auto mpi = mneedle::test::run_command(shell_words(words));
    ASSERT_EQ(mpi.exit_code, 0) << mpi.err;
    EXPECT_EQ(ranked_names(mpi.out), ranked_names(serial.out)) << "--jobs " << jobs;
    const auto expected = rows_by_design(serial.out);
    const auto got = rows_by_design(mpi.out);
    ASSERT_EQ(got.size(), 6u);
    for (const auto& [design, row] : expected) EXPECT_EQ(got.at(design), row) << design;
    // One writer: every design once in the files rank 0 wrote.
    EXPECT_EQ(jsonl_rows(dir / ("mpi" + jobs) / "results.jsonl").size(), 6u);
  }
  fs::remove_all(dir);
}

TEST(ScreenCommand, MpiJobTerminatedAgainAndAgainAndResumedListsEveryDesignOnceAsTheSerialRun) {
  // SIGTERM to mpirun (what a batch scheduler sends) ends both ranks wherever they are; each
  // time the job is resumed under MPI, as on one machine.
  const fs::path dir =
      fs::temp_directory_path() / ("mneedle_mpikill_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream list(dir / "designs.toml");
  for (int i = 0; i < 32; ++i)
    list << "[[designs]]\nname = \"cone_" << i << "\"\nplugin = \"cone\"\ndiameter = \""
         << 150 + 5 * i << " um\"\n\n";
  list.close();
  const std::string scene = kRoot + "/designs/scenes/paper_a_silicone_blunt_bevel.toml";
  const auto arguments = [&](const std::string& out) {
    return std::vector<std::string>{
        "screen",  (dir / "designs.toml").string(), "--scene", scene, "--out", (dir / out).string(),
        "--resume"};
  };
  // The serial reference at one OpenBLAS thread per design, as every rank evaluates: --jobs 2.
  auto serial_arguments = arguments("serial");
  serial_arguments.insert(serial_arguments.end(), {"--jobs", "2"});
  ASSERT_TRUE(finished_before_kill(serial_arguments, std::chrono::seconds(300)));
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(finished_before_kill(mpirun(2, arguments("whole")), std::chrono::seconds(300),
                                   SIGTERM, MNEEDLE_MPIEXEC));
  const auto whole_run = std::chrono::duration_cast<std::chrono::microseconds>(
      std::chrono::steady_clock::now() - start);
  // As in the single-machine test above: restart the series with shorter delays when a job
  // outlives its signal before three kills.
  std::mt19937 random(2026);
  int kills = 0;
  for (long scale = 1; kills < 3 && scale <= 8; scale *= 2) {
    fs::remove_all(dir / "killed");
    std::uniform_int_distribution<long> delay_us(whole_run.count() / (10 * scale),
                                                 whole_run.count() / (3 * scale));
    kills = 0;
    while (kills < 10 && !finished_before_kill(mpirun(2, arguments("killed")),
                                               std::chrono::microseconds(delay_us(random)), SIGTERM,
                                               MNEEDLE_MPIEXEC)) {
      ++kills;
      // mpirun ends its ranks before it exits; give them a moment, then insist.
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (process_mentions((dir / "killed").string()) &&
             std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      ASSERT_FALSE(process_mentions((dir / "killed").string())) << "a rank outlived mpirun";
    }
  }
  ASSERT_GE(kills, 3) << "too few kills to test anything, even with delays an eighth as long";
  ASSERT_TRUE(finished_before_kill(mpirun(2, arguments("killed")), std::chrono::seconds(300),
                                   SIGTERM, MNEEDLE_MPIEXEC));

  std::map<std::string, nlohmann::json> serial;
  for (const auto& row : jsonl_rows(dir / "serial" / "results.jsonl"))
    serial[row["design"].get<std::string>()] = row;
  ASSERT_EQ(serial.size(), 32u);
  std::map<std::string, int> seen;
  for (const auto& row : jsonl_rows(dir / "killed" / "results.jsonl")) {
    const std::string design = row["design"].get<std::string>();
    ++seen[design];
    EXPECT_EQ(row, serial[design]) << design;
  }
  EXPECT_EQ(seen.size(), 32u);
  for (const auto& [design, count] : seen) EXPECT_EQ(count, 1) << design;
  std::ifstream csv(dir / "killed" / "results.csv");
  std::map<std::string, int> csv_seen;
  for (std::string line; std::getline(csv, line);)
    if (line.rfind("\"cone_", 0) == 0) ++csv_seen[line.substr(0, line.find(','))];  // quoted
  EXPECT_EQ(csv_seen.size(), 32u);
  for (const auto& [design, count] : csv_seen) EXPECT_EQ(count, 1) << design;
  fs::remove_all(dir);
}

TEST(ScreenCommand, UnderMpirunWithoutMpiFlagEveryRankRefusesAndOneLineSaysWhy) {
  // Without --mpi every rank would screen every design into the same files.
  auto words = mpirun(2, {"screen", kRoot + "/designs", "--scene", kSkin});
  words.pop_back();  // no --mpi
  const auto run = mneedle::test::run_command(shell_words(words));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("add --mpi"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("add --mpi"), run.err.rfind("add --mpi"))
      << "one rank says it: " << run.err;
}

TEST(ScreenCommand, MpiJobWithAMissingInputSaysItOnceAndEveryRankStops) {
  const auto run = mneedle::test::run_command(
      shell_words(mpirun(2, {"screen", "/nonexistent/designs", "--scene", kSkin})));
  EXPECT_NE(run.exit_code, 0);
  const std::string line = "/nonexistent/designs: no such file or folder";
  EXPECT_NE(run.err.find(line), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find(line), run.err.rfind(line)) << "said once: " << run.err;
}
#endif

}  // namespace
