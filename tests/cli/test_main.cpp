// The command line's exit statuses and error lines (docs/cli.md, "Exit status").
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "mneedle/fe/blas_kernels.h"
#include "run_mneedle.h"

namespace {

using mneedle::test::run_mneedle;

const std::string kRoot = MNEEDLE_SOURCE_ROOT;

TEST(ExitStatus, SuccessAndHelpAreZero) {
  EXPECT_EQ(run_mneedle("--help").exit_code, 0);
  EXPECT_EQ(run_mneedle("simulate --help").exit_code, 0);
}

TEST(ExitStatus, BadInputIsOneWithTheErrorPrefix) {
  const auto run = run_mneedle("scene check '" + kRoot + "/no_such_scene.toml'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err.rfind("mneedle: error: ", 0), 0u) << run.err;
}

TEST(ExitStatus, BadCommandLineIsTwoWithTheErrorPrefix) {
  for (const char* args : {"simulate", "simulate x.toml --no-such-option", "no-such-command"}) {
    const auto run = run_mneedle(args);
    EXPECT_EQ(run.exit_code, 2) << args;
    EXPECT_EQ(run.err.rfind("mneedle: error: ", 0), 0u) << args << ": " << run.err;
    EXPECT_NE(run.err.find("(see mneedle --help)"), std::string::npos) << run.err;
  }
}

// A value error names the option it came from (it said only '"10" needs a unit'), and a zero that
// plane-strain used to replace silently by its default is refused.
TEST(ExitStatus, AValueErrorNamesItsOption) {
  const std::string silicone = kRoot + "/designs/scenes/silicone_phantom.toml";
  const std::string strip =
      "plane-strain --tissue 7kPa,0.475 --block 160mm,86mm --needle-width 8mm --tip-angle 50deg ";
  for (const auto& [args, expected] :
       {std::pair<std::string, std::string>{"force '" + silicone + "' --step 10",
                                            "--step: \"10\" needs a unit: a length"},
        std::pair<std::string, std::string>{strip + "--thickness 15mm --element-size 0mm",
                                            "--element-size 0mm: must be positive"},
        std::pair<std::string, std::string>{strip + "--thickness 15mm --step -1mm",
                                            "--step -1mm: must be positive"},
        std::pair<std::string, std::string>{strip + "--thickness 15",
                                            "--thickness: \"15\" needs a unit"}}) {
    const auto run = run_mneedle(args);
    EXPECT_EQ(run.exit_code, 1) << args;
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
}

// CLI11 said "A subcommand is required" for a misspelt command; the line names the word, the
// closest command and the known ones, at the top level and inside `scene` and `plugins`.
TEST(ExitStatus, AMisspeltCommandIsNamedWithTheClosestKnownOne) {
  for (const auto& [args, expected] :
       {std::pair<std::string, std::string>{
            "scren designs",
            "unknown command 'mneedle scren' (did you mean 'mneedle screen'?); "
            "known: scene, plugins,"},
        std::pair<std::string, std::string>{
            "scene chek x.toml",
            "unknown command 'mneedle scene chek' (did you mean 'mneedle scene check'?); known: "
            "check (see mneedle --help)"},
        std::pair<std::string, std::string>{
            "plugins lst", "(did you mean 'mneedle plugins list'?); known: list, describe"},
        std::pair<std::string, std::string>{"sim x.toml", "(did you mean 'mneedle simulate'?)"},
        std::pair<std::string, std::string>{"frobnicate",
                                            "unknown command 'mneedle frobnicate'; known: "}}) {
    const auto run = run_mneedle(args);
    EXPECT_EQ(run.exit_code, 2) << args;
    EXPECT_NE(run.err.find(expected), std::string::npos) << run.err;
  }
}

}  // namespace

namespace {

// docs/cli.md promises an example in every command's help.
TEST(Help, EveryCommandShowsAnExample) {
  for (const char* command :
       {"scene check", "plugins list", "plugins describe", "generate", "inspect", "force",
        "strength", "screen", "optimize", "fit", "predict", "stats", "simulate", "toughness",
        "calibrate", "energy", "export"}) {
    const auto run = mneedle::test::run_mneedle(std::string(command) + " --help");
    EXPECT_EQ(run.exit_code, 0) << command << ": " << run.err;
    EXPECT_NE(run.out.find("Example"), std::string::npos) << command << " --help:\n" << run.out;
  }
}

}  // namespace

namespace {

namespace fs = std::filesystem;

// Every error path the command line has, one bad input each: a malformed number or unit, an
// out-of-range value, an unknown name, a missing, empty, truncated or garbage file, a malformed
// key=value. docs/cli.md promises one line `mneedle: error: ...` and exit 1 (bad input), 2 (bad
// command line) or 3 (solver) for each; an exception message of the standard library, CLI11,
// nlohmann::json or toml++ reaching the user, or a NaN in a message, is a bug (exit 4 at best).
// No case may start a simulation: each fails in its checks, well under a second.
struct Case {
  const char* name;
  std::string args;  // {D}: the test's scratch folder, {R}: the repository root
  int exit_code;
};

// Text of the libraries' own exceptions (std::stoi, map::at, nlohmann::json, toml++, asserts).
constexpr const char* kInternalMarkers[] = {
    // the standard library: containers, number conversions, optional/variant/function, new
    "map::at", "vector::", "basic_string", "_M_", "stoi", "stod", "stoul", "stoll", "bad_alloc",
    "bad_optional", "bad_variant", "bad_function", "std::",
    // nlohmann::json and toml++
    "json.exception", "[json", "toml::",
    // assimp names its own structures in its validation messages
    "aiMesh", "aiScene", "mIndices",
    // main()'s catch-all, std::terminate and assert()
    "internal error", "what():", "terminate called", "Assertion"};

// The message without its quoted spans: an error may echo what the user typed ("nan", 'inf'),
// which is no NaN of mneedle's own. A quote opens only after a non-letter, so "shape's" does not.
std::string unquoted(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if ((c == '\'' || c == '"') &&
        (i == 0 || !std::isalnum(static_cast<unsigned char>(text[i - 1])))) {
      const std::size_t close = text.find(c, i + 1);
      if (close != std::string::npos) {
        i = close;
        continue;
      }
    }
    out += c;
  }
  return out;
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A valid scene, cut and changed below into each bad one.
const std::string kTissue = R"toml([tissue]
size = ["2 mm", "2 mm", "1 mm"]

[[tissue.layers]]
name = "gel"
material = { model = "linear", E = "7 kPa", nu = 0.45 }
)toml";
const std::string kNeedle = R"toml(
[[needles]]
geometry = { plugin = "cone", diameter = "200 um", length = "1 mm" }
)toml";
const std::string kInsertion = "\n[insertion]\ndepth = \"0.5 mm\"\n";

std::string scene_with_depth(const std::string& depth) {
  return kTissue + kNeedle + "\n[insertion]\ndepth = " + depth + "\n";
}

// The bad (and a few good) input files, written fresh in `dir` for every run.
void write_inputs(const fs::path& dir) {
  const std::string curves = kRoot + "/tests/assets/curves/";
  fs::create_directories(dir / "folder");
  fs::copy_file(curves + "loading_hold_retraction.csv", dir / "curve.csv");
  fs::copy_file(curves + "toughness_first.csv", dir / "first.csv");
  fs::copy_file(curves + "toughness_second.csv", dir / "second.csv");
  const std::pair<const char*, std::string> files[] = {
      // scenes
      {"good.toml", kTissue + kNeedle + kInsertion},
      {"empty.toml", ""},
      {"truncated.toml", "[tissue]\nsize = [\"2 mm\", \"2 mm\"\n"},
      {"binary.toml", std::string("\0\1\2garbage\xff\xfe", 12)},
      {"depth_text.toml", scene_with_depth("\"abc\"")},
      {"depth_kg.toml", scene_with_depth("\"5 kg\"")},
      {"depth_nan.toml", scene_with_depth("\"nan mm\"")},
      {"depth_huge.toml", scene_with_depth("\"1e400 m\"")},
      {"depth_array.toml", scene_with_depth("[\"0.5 mm\"]")},
      {"no_insertion.toml", kTissue + kNeedle},
      {"unknown_key.toml", kTissue + kNeedle + kInsertion + "colour = \"red\"\n"},
      {"negative_thickness.toml",
       replace_all(kTissue, "name = \"gel\"\n", "name = \"gel\"\nthickness = \"-0.1 mm\"\n") +
           "\n[[tissue.layers]]\nname = \"base\"\n"
           "material = { model = \"linear\", E = \"7 kPa\", nu = 0.45 }\n" +
           kNeedle + kInsertion},
      {"layers_string.toml", "[tissue]\nsize = [\"2 mm\", \"2 mm\", \"1 mm\"]\nlayers = \"gel\"\n" +
                                 kNeedle + kInsertion},
      {"unknown_model.toml",
       replace_all(kTissue, "\"linear\"", "\"rubber\"") + kNeedle + kInsertion},
      {"unknown_fidelity.toml",
       kTissue + kNeedle + kInsertion + "\n[model]\nfidelity = \"ultra\"\n"},
      {"missing_stl.toml",
       kTissue + "\n[[needles]]\ngeometry = { stl = \"missing.stl\" }\n" + kInsertion},
      {"unknown_plugin.toml",
       kTissue + "\n[[needles]]\ngeometry = { plugin = \"no_such_shape\" }\n" + kInsertion},
      {"two_needles.toml", kTissue + kNeedle + kNeedle + kInsertion},
      {"wide_needle.toml", kTissue + replace_all(kNeedle, "200 um", "3 mm") + kInsertion},
      {"no_friction.toml", kTissue + kNeedle + "\n[loads]\nfriction = \"none\"\n" + kInsertion},
      // meshes
      {"empty.stl", ""},
      {"short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"},
      {"text.stl", "hello, this is not a mesh\n"},
      {"bad_face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"},
      {"no_faces.obj", "v 0 0 0\n"},
      {"header_only.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"},
      {"mesh.xyz", "0 0 0\n"},
      // force-depth curves
      {"empty.csv", ""},
      {"header_only.csv", "time_s,travel_mm,fz_N\n"},
      {"text_cell.csv", "time_s,travel_mm,fz_N\n0,0,0\n0.1,0.1,abc\n0.2,0.2,0.1\n"},
      {"one_row.csv", "time_s,travel_mm,fz_N\n0,0,0\n"},
      {"ragged.csv", "time_s,travel_mm,fz_N\n0,0,0\n0.1,0.1\n0.2,0.2,0.1,7\n"},
      {"nan_cells.csv", "time_s,travel_mm,fz_N\n0,0,nan\n0.1,0.1,inf\n0.2,0.2,0.1\n"},
      {"unclosed.csv", "time_s,\"travel_mm\n0,0\n"},
      // grouped values for stats
      {"groups.csv", "group,value\na,1\na,2\na,3\nb,4\nb,5\nb,7\n"},
      {"groups_header_only.csv", "group,value\n"},
      {"groups_one_row.csv", "group,value\na,1\n"},
      {"groups_text.csv", "group,value\na,x\nb,2\n"},
      {"groups_one_group.csv", "group,value\na,1\na,2\na,3\n"},
      {"groups_ragged.csv", "group,value\na,1\nb\n"},
      {"groups_no_variance.csv", "group,value\na,1\na,1\nb,2\nb,2\n"},
      {"groups_nan.csv", "group,value\na,nan\na,1\nb,2\nb,3\n"},
      // tri-force parameters for predict
      // Every parameter (a missing one is refused: the built-in value would stand in for it).
      {"params.json",
       R"({"params": {"Fc_max_N": 1, "kc_per_m": 500, "K0_N": 1, "beta": 0.5, "c_per_m2": 4e4,
                      "mu": 0.2, "radius_m": 6e-4, "ref_length_m": 0.01, "eta_Ns": 0,
                      "lambda_s": 1}})"},
      {"partial_params.json", R"({"params": {"Fc_max_N": 1}})"},
      {"no_params.json", R"({"model": "triforce"})"},
      {"params_array.json", R"({"params": [1, 2]})"},
      {"params_text.json", R"({"params": {"mu": "x"}})"},
      {"params_unknown.json", R"({"params": {"no_such_param": 1}})"},
      {"params_negative.json", R"({"params": {"mu": -5}})"},
  };
  for (const auto& [name, text] : files) write_file(dir / name, text);
}

TEST(ErrorPaths, EveryBadInputGivesOneClearLineAndNoInternalText) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_errors_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  write_inputs(dir);
  const Case cases[] = {
      {"scene check: missing file", "scene check {D}/missing.toml", 1},
      {"scene check: a directory", "scene check {D}/folder", 1},
      {"scene check: empty file", "scene check {D}/empty.toml", 1},
      {"scene check: truncated TOML", "scene check {D}/truncated.toml", 1},
      {"scene check: binary garbage", "scene check {D}/binary.toml", 1},
      {"scene check: depth is text", "scene check {D}/depth_text.toml", 1},
      {"scene check: depth in kg", "scene check {D}/depth_kg.toml", 1},
      {"scene check: depth NaN", "scene check {D}/depth_nan.toml", 1},
      {"scene check: depth 1e400 m", "scene check {D}/depth_huge.toml", 1},
      {"scene check: depth is an array", "scene check {D}/depth_array.toml", 1},
      {"scene check: no [insertion] table", "scene check {D}/no_insertion.toml", 1},
      {"scene check: unknown key", "scene check {D}/unknown_key.toml", 1},
      {"scene check: negative thickness", "scene check {D}/negative_thickness.toml", 1},
      {"scene check: layers is a string", "scene check {D}/layers_string.toml", 1},
      {"scene check: unknown material model", "scene check {D}/unknown_model.toml", 1},
      {"scene check: unknown fidelity", "scene check {D}/unknown_fidelity.toml", 1},
      {"scene check: missing STL", "scene check {D}/missing_stl.toml", 1},
      {"scene check: no FILE", "scene check", 2},
      {"scene check: two needles on one spot", "scene check {D}/two_needles.toml", 1},
      {"scene check: needle wider than the block", "scene check {D}/wide_needle.toml", 1},
      {"plugins: describe unknown shape", "plugins describe no_such_shape", 1},
      {"plugins: describe empty name", "plugins describe ''", 1},
      {"plugins: list missing plugin dir", "plugins list --plugin-dir {D}/missing_dir", 1},
      {"plugins: describe file as plugin dir", "plugins describe cone --plugin-dir {D}/good.toml",
       1},
      {"generate: unknown shape", "generate no_such_shape -o {D}/out.stl", 1},
      {"generate: --set without =", "generate cone --set x -o {D}/out.stl", 1},
      {"generate: --set =1", "generate cone --set =1 -o {D}/out.stl", 1},
      {"generate: --set empty value", "generate sharp_bevel --set bevel_angle= -o {D}/out.stl", 1},
      {"generate: --set text value", "generate sharp_bevel --set bevel_angle=abc -o {D}/out.stl",
       1},
      {"generate: --set angle without unit",
       "generate sharp_bevel --set bevel_angle=30 -o {D}/out.stl", 1},
      {"generate: --set length in kg", "generate cone --set diameter=5kg -o {D}/out.stl", 1},
      {"generate: --set 1e400m", "generate cone --set diameter=1e400m -o {D}/out.stl", 1},
      {"generate: --set nan", "generate cone --set diameter=nan -o {D}/out.stl", 1},
      {"generate: --set -inf", "generate cone --set diameter=-inf -o {D}/out.stl", 1},
      {"generate: --set above maximum", "generate cone --set diameter=20mm -o {D}/out.stl", 1},
      {"generate: --set negative", "generate cone --set diameter=-1mm -o {D}/out.stl", 1},
      {"generate: --set unknown parameter", "generate cone --set colour=1 -o {D}/out.stl", 1},
      {"generate: --set given twice",
       "generate cone --set diameter=200um --set diameter=300um -o {D}/out.stl", 1},
      {"generate: --set count with unit", "generate cone --set resolution=3mm -o {D}/out.stl", 1},
      {"generate: --unit unknown", "generate cone --unit furlong -o {D}/out.stl", 1},
      {"generate: --plugin-dir missing",
       "generate cone --plugin-dir {D}/missing_dir -o {D}/out.stl", 1},
      {"generate: -o is a directory", "generate cone -o {D}/folder", 1},
      {"generate: -o in a missing folder", "generate cone -o {D}/missing_dir/out.stl", 1},
      {"generate: no -o", "generate cone", 2},
      {"generate: -o not an STL name", "generate cone -o {D}/out.obj", 1},
      {"predict: params missing a parameter",
       "predict --params {D}/partial_params.json --depth 1mm", 1},
      {"inspect: missing file", "inspect {D}/missing.stl", 1},
      {"inspect: a directory", "inspect {D}/folder", 1},
      {"inspect: empty STL", "inspect {D}/empty.stl", 1},
      {"inspect: text that is not STL", "inspect {D}/text.stl", 1},
      {"inspect: OBJ face index out of range", "inspect {D}/bad_face.obj", 1},
      {"inspect: OBJ without faces", "inspect {D}/no_faces.obj", 1},
      {"inspect: PLY header only", "inspect {D}/header_only.ply", 1},
      {"inspect: unknown extension", "inspect {D}/mesh.xyz", 1},
      {"inspect: --unit unknown", "inspect {D}/empty.stl --unit parsec", 1},
      {"inspect: --axis unknown name", "inspect {R}/designs/cone.stl --axis w", 1},
      {"inspect: --axis zero vector", "inspect {R}/designs/cone.stl --axis 0,0,0", 1},
      {"inspect: --axis with nan", "inspect {R}/designs/cone.stl --axis nan,0,1", 1},
      {"inspect: --axis two numbers", "inspect {R}/designs/cone.stl --axis 1,2", 1},
      {"inspect: --axis 1e400", "inspect {R}/designs/cone.stl --axis 1e400,0,0", 1},
      {"inspect: -o is a directory", "inspect {R}/designs/cone.stl -o {D}/folder", 1},
      {"inspect: --json, missing file", "inspect {D}/missing.stl --json", 1},
      {"force: missing scene", "force {D}/missing.toml", 1},
      {"force: empty scene", "force {D}/empty.toml", 1},
      {"force: --step text", "force {D}/good.toml --step abc", 1},
      {"force: --step empty", "force {D}/good.toml --step ''", 1},
      {"force: --step 1e400m", "force {D}/good.toml --step 1e400m", 1},
      {"force: --step nan", "force {D}/good.toml --step nan", 1},
      {"force: --step -inf", "force {D}/good.toml --step=-inf", 1},
      {"force: --step in kg", "force {D}/good.toml --step 5kg", 1},
      {"force: --step without unit", "force {D}/good.toml --step 10", 1},
      {"force: --step zero", "force {D}/good.toml --step 0um", 1},
      {"force: --step too fine", "force {D}/good.toml --step 1e-15m", 1},
      {"force: --max-points text", "force {D}/good.toml --max-points abc", 2},
      {"force: --max-points zero", "force {D}/good.toml --max-points 0", 2},
      {"force: --max-points negative", "force {D}/good.toml --max-points=-5", 2},
      {"force: two needles on the same tissue", "force {D}/two_needles.toml", 1},
      {"inspect: OFF cut short", "inspect {D}/short.off --unit mm", 1},
      {"force: unknown plugin in scene", "force {D}/unknown_plugin.toml", 1},
      {"force: --plugin-dir missing", "force {D}/good.toml --plugin-dir {D}/missing_dir", 1},
      {"strength: no --material", "strength --plugin cone", 2},
      {"strength: neither file nor plugin", "strength --material pla", 1},
      {"strength: file and plugin", "strength {R}/designs/cone.stl --plugin cone --material pla",
       1},
      {"strength: unknown --material", "strength --plugin cone --material unobtainium", 1},
      {"strength: unknown --plugin", "strength --plugin nope --material pla", 1},
      {"strength: --set text value", "strength --plugin cone --set diameter=abc --material pla", 1},
      {"strength: unknown --end", "strength --plugin cone --material pla --end clamped", 1},
      {"strength: --depth text", "strength --plugin cone --material pla --depth abc", 1},
      {"strength: --depth without unit", "strength --plugin cone --material pla --depth 5", 1},
      {"strength: --depth negative", "strength --plugin cone --material pla --depth=-1mm", 1},
      {"strength: --lateral-ratio text",
       "strength --plugin cone --material pla --lateral-ratio abc", 2},
      {"strength: --lateral-ratio nan", "strength --plugin cone --material pla --lateral-ratio nan",
       1},
      {"strength: --lateral-ratio negative",
       "strength --plugin cone --material pla --lateral-ratio=-1", 1},
      {"strength: empty mesh file", "strength {D}/empty.stl --material pla", 1},
      {"strength: --unit unknown", "strength {R}/designs/cone.stl --unit ly --material pla", 1},
      {"strength: --axis unknown", "strength {R}/designs/cone.stl --axis q --material pla", 1},
      {"strength: --plugin-dir missing",
       "strength --plugin cone --material pla --plugin-dir {D}/missing_dir", 1},
      {"screen: missing scene", "screen {R}/designs/cone.stl --scene {D}/missing.toml", 1},
      {"screen: invalid scene", "screen {R}/designs/cone.stl --scene {D}/depth_text.toml", 1},
      {"screen: empty folder", "screen {D}/folder --scene {D}/good.toml", 1},
      {"screen: missing design", "screen {D}/missing.stl --scene {D}/good.toml", 1},
      {"screen: garbage design list", "screen {D}/depth_text.toml --scene {D}/good.toml", 1},
      {"screen: empty design list", "screen {D}/empty.toml --scene {D}/good.toml", 1},
      {"screen: empty STL design", "screen {D}/empty.stl --scene {D}/good.toml --json", 1},
      {"screen: unknown --material",
       "screen {D}/empty.stl --scene {D}/good.toml --material unobtainium --json", 1},
      {"screen: --unit unknown", "screen {R}/designs/cone.stl --scene {D}/good.toml --unit furlong",
       1},
      {"screen: --axis unknown", "screen {R}/designs/cone.stl --scene {D}/good.toml --axis w", 1},
      {"screen: --resume without --out",
       "screen {R}/designs/cone.stl --scene {D}/good.toml --resume", 1},
      {"screen: --jobs zero", "screen {R}/designs/cone.stl --scene {D}/good.toml --jobs 0", 2},
      {"screen: --fidelity unknown",
       "screen {R}/designs/cone.stl --scene {D}/good.toml --fidelity ultra", 2},
      {"screen: --model unknown", "screen {R}/designs/cone.stl --scene {D}/good.toml --model fem",
       2},
      {"screen: --plugin-dir missing",
       "screen {R}/designs/cone.stl --scene {D}/good.toml --plugin-dir {D}/missing_dir", 1},
      {"optimize: unknown --plugin", "optimize --plugin nope --scene {D}/good.toml --vary diameter",
       1},
      {"optimize: invalid scene",
       "optimize --plugin cone --scene {D}/negative_thickness.toml --vary diameter", 1},
      {"optimize: --vary unknown", "optimize --plugin cone --scene {D}/good.toml --vary colour", 1},
      {"optimize: --vary only a comma", "optimize --plugin cone --scene {D}/good.toml --vary ,", 1},
      {"optimize: --set without =",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --set x", 1},
      {"optimize: --bound without =",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter", 1},
      {"optimize: --bound without :",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter=1mm", 1},
      {"optimize: --bound text",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter=abc:1mm", 1},
      {"optimize: --bound empty high",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter=100um:", 1},
      {"optimize: --bound without unit",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter=1:2", 1},
      {"optimize: --bound reversed",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter=300um:100um",
       1},
      {"optimize: --min-feature text",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --min-feature abc", 1},
      {"optimize: --min-feature zero",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --min-feature 0um", 1},
      {"optimize: unknown --material",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --material unobtainium", 1},
      {"optimize: --objective unknown",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --objective speed", 2},
      {"optimize: --fidelity unknown",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --fidelity ultra", 2},
      {"optimize: --model unknown",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --model fem", 2},
      {"optimize: --algorithm unknown",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --algorithm newton", 2},
      {"optimize: --local unknown",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --local lbfgs", 2},
      {"optimize: --vary twice",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter,diameter", 1},
      {"optimize: --bound twice",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --bound diameter=150um:250um "
       "--bound diameter=160um:250um",
       1},
      {"optimize: --set twice",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --set length=1mm --set "
       "length=2mm",
       1},
      {"optimize: --starts zero",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --starts 0", 2},
      {"optimize: --max-evals text",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --max-evals abc", 2},
      {"optimize: --max-evals zero",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --max-evals 0", 1},
      {"optimize: --seed negative",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --seed=-1", 2},
      {"optimize: --max-time text",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --max-time abc", 1},
      {"optimize: --max-time a length",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --max-time 5mm", 1},
      {"optimize: --plugin-dir missing",
       "optimize --plugin cone --scene {D}/good.toml --vary diameter --plugin-dir {D}/missing_dir",
       1},
      {"fit: missing file", "fit {D}/missing.csv", 1},
      {"fit: empty CSV", "fit {D}/empty.csv", 1},
      {"fit: header only", "fit {D}/header_only.csv", 1},
      {"fit: text cell", "fit {D}/text_cell.csv", 1},
      {"fit: one row", "fit {D}/one_row.csv", 1},
      {"fit: ragged rows", "fit {D}/ragged.csv", 1},
      {"fit: nan and inf cells", "fit {D}/nan_cells.csv", 1},
      {"fit: unclosed quote", "fit {D}/unclosed.csv", 1},
      {"fit: unknown --model", "fit {D}/curve.csv --model linear", 1},
      {"fit: --speed text", "fit {D}/curve.csv --speed abc", 1},
      {"fit: --speed a length", "fit {D}/curve.csv --speed 5mm", 1},
      {"fit: --speed zero", "fit {D}/curve.csv --speed 0mm/s", 1},
      {"fit: --angle without unit", "fit {D}/curve.csv --angle 90", 1},
      {"fit: --depth-col missing", "fit {D}/curve.csv --depth-col nope", 1},
      {"fit: --force-col missing", "fit {D}/curve.csv --force-col nope", 1},
      {"fit: --depth-unit unknown", "fit {D}/curve.csv --depth-unit furlong", 1},
      {"fit: --force-unit unknown", "fit {D}/curve.csv --force-unit kg", 1},
      {"fit: --fix without =", "fit {D}/curve.csv --fix beta", 1},
      {"fit: --fix text value", "fit {D}/curve.csv --fix beta=abc", 1},
      {"fit: --fix unknown", "fit {D}/curve.csv --fix nope=1", 1},
      {"fit: --fix force without unit", "fit {D}/curve.csv --fix K0_N=1", 1},
      {"fit: --free unknown", "fit {D}/curve.csv --free nope", 1},
      {"fit: --layer-start text", "fit {D}/curve.csv --layer-start abc", 1},
      {"fit: --layer-start negative", "fit {D}/curve.csv --layer-start=-5mm", 1},
      {"fit: --detect-layers text", "fit {D}/curve.csv --detect-layers abc", 2},
      {"fit: --starts text", "fit {D}/curve.csv --starts abc", 2},
      {"predict: no --params", "predict --depth 1mm", 2},
      {"predict: missing --params", "predict --params {D}/missing.json --depth 1mm", 1},
      {"predict: no params object", "predict --params {D}/no_params.json --depth 1mm", 1},
      {"predict: params is an array", "predict --params {D}/params_array.json --depth 1mm", 1},
      {"predict: params value text", "predict --params {D}/params_text.json --depth 1mm", 1},
      {"predict: params unknown name", "predict --params {D}/params_unknown.json --depth 1mm", 1},
      {"predict: params negative", "predict --params {D}/params_negative.json --depth 1mm", 1},
      {"predict: unknown --model", "predict --model linear --params {D}/params.json --depth 1mm",
       1},
      {"predict: no --depth", "predict --params {D}/params.json", 1},
      {"predict: --depth text", "predict --params {D}/params.json --depth abc", 1},
      {"predict: --depth nan", "predict --params {D}/params.json --depth nanmm", 1},
      {"predict: --depth negative", "predict --params {D}/params.json --depth=-1mm", 1},
      {"predict: --depth 1e300 m", "predict --params {D}/params.json --depth 1e300m", 1},
      {"predict: --speed zero", "predict --params {D}/params.json --depth 1mm --speed 0mm/s", 1},
      {"predict: --speed a length", "predict --params {D}/params.json --depth 1mm --speed 1mm", 1},
      {"predict: --angle text", "predict --params {D}/params.json --depth 1mm --angle abc", 1},
      {"predict: --hold negative", "predict --params {D}/params.json --depth 1mm --hold=-1s", 1},
      {"predict: --retract-speed text",
       "predict --params {D}/params.json --depth 1mm --retract-speed abc", 1},
      {"predict: --step zero", "predict --params {D}/params.json --depth 1mm --step 0s", 1},
      {"predict: --step tiny", "predict --params {D}/params.json --depth 1mm --step 1e-12s", 1},
      {"predict: --perturb-amplitude text",
       "predict --params {D}/params.json --depth 1mm --perturb-amplitude abc", 1},
      {"predict: --perturb-frequency text",
       "predict --params {D}/params.json --depth 1mm --perturb-frequency abc", 2},
      {"predict: --perturb-frequency zero",
       "predict --params {D}/params.json --depth 1mm --perturb-frequency 0", 1},
      {"predict: --perturb-frequency nan",
       "predict --params {D}/params.json --depth 1mm --perturb-frequency nan", 1},
      {"predict: --max-samples text",
       "predict --params {D}/params.json --depth 1mm --max-samples abc", 2},
      {"predict: --max-samples zero",
       "predict --params {D}/params.json --depth 1mm --max-samples 0", 1},
      {"predict: 1000 m in the default steps", "predict --params {D}/params.json --depth 1000m", 1},
      {"predict: --compare missing", "predict --params {D}/params.json --compare {D}/missing.csv",
       1},
      {"predict: --compare empty", "predict --params {D}/params.json --compare {D}/empty.csv", 1},
      {"predict: --compare text cell",
       "predict --params {D}/params.json --compare {D}/text_cell.csv", 1},
      {"predict: --compare, --depth-col missing",
       "predict --params {D}/params.json --compare {D}/curve.csv --depth-col nope", 1},
      {"predict: --compare, --force-col missing",
       "predict --params {D}/params.json --compare {D}/curve.csv --force-col nope", 1},
      {"stats: missing file", "stats {D}/missing.csv", 1},
      {"stats: a directory", "stats {D}/folder", 1},
      {"stats: empty CSV", "stats {D}/empty.csv", 1},
      {"stats: header only", "stats {D}/groups_header_only.csv", 1},
      {"stats: one row", "stats {D}/groups_one_row.csv", 1},
      {"stats: text cell", "stats {D}/groups_text.csv", 1},
      {"stats: one group", "stats {D}/groups_one_group.csv", 1},
      {"stats: ragged rows", "stats {D}/groups_ragged.csv", 1},
      {"stats: no variance", "stats {D}/groups_no_variance.csv", 1},
      {"stats: nan cell", "stats {D}/groups_nan.csv", 1},
      {"stats: --value missing", "stats {D}/groups.csv --value nope", 1},
      {"stats: --group missing", "stats {D}/groups.csv --group nope", 1},
      {"stats: --alpha text", "stats {D}/groups.csv --alpha abc", 2},
      {"stats: --alpha zero", "stats {D}/groups.csv --alpha 0", 1},
      {"stats: --alpha two", "stats {D}/groups.csv --alpha 2", 1},
      {"stats: --alpha nan", "stats {D}/groups.csv --alpha nan", 1},
      {"simulate: missing scene", "simulate {D}/missing.toml", 1},
      {"simulate: empty scene", "simulate {D}/empty.toml", 1},
      {"simulate: truncated scene", "simulate {D}/truncated.toml", 1},
      {"simulate: --fidelity unknown", "simulate {D}/good.toml --fidelity ultra", 2},
      {"simulate: --contact unknown", "simulate {D}/good.toml --contact glue", 2},
      {"simulate: --criterion unknown", "simulate {D}/good.toml --criterion luck", 2},
      {"simulate: --criterion cohesive without its data",
       "simulate {D}/good.toml --criterion "
       "cohesive",
       1},
      {"simulate: --model unknown", "simulate {D}/good.toml --model fem", 2},
      {"simulate: --axis unknown", "simulate {D}/good.toml --axis w", 1},
      {"simulate: --max-needles text", "simulate {D}/good.toml --max-needles abc", 2},
      {"simulate: --max-needles negative", "simulate {D}/good.toml --max-needles=-1", 2},
      {"simulate: --vtu is a file", "simulate {D}/good.toml --vtu {D}/good.toml", 1},
      {"toughness: a folder as the first curve", "toughness {D}/folder {D}/second.csv --area 1mm^2",
       1},
      {"calibrate: a folder as the curve", "calibrate {D}/good.toml --curve {D}/folder --fit scale",
       1},
      {"optimize: --out is a file",
       "optimize --plugin cone --scene {D}/good.toml --vary half_angle --out {D}/good.toml", 1},
      {"optimize: --bound on a parameter not varied",
       "optimize --plugin cone --scene {D}/good.toml --vary half_angle --bound tip_radius=1um:2um",
       1},
      {"optimize: --bound without a name",
       "optimize --plugin cone --scene {D}/good.toml --vary half_angle --bound =1mm:2mm", 1},
      {"screen: --out is a file",
       "screen {R}/designs/cone.stl --scene {D}/good.toml --out {D}/good.toml --json", 1},
      {"simulate: unknown plugin in scene", "simulate {D}/unknown_plugin.toml", 1},
      {"simulate: missing STL in scene", "simulate {D}/missing_stl.toml", 1},
      {"simulate: --plugin-dir missing", "simulate {D}/good.toml --plugin-dir {D}/missing_dir", 1},
      {"toughness: missing first", "toughness {D}/missing.csv {D}/second.csv --area 1mm^2", 1},
      {"toughness: --area beyond a double",
       "toughness {D}/curve.csv {D}/second.csv --area 1e400mm^2", 1},
      {"toughness: --set without --plugin",
       "toughness {D}/curve.csv {D}/second.csv --area 1mm^2 --set diameter=1mm", 1},
      {"toughness: empty first", "toughness {D}/empty.csv {D}/second.csv --area 1mm^2", 1},
      {"toughness: header only", "toughness {D}/header_only.csv {D}/second.csv --area 1mm^2", 1},
      {"toughness: text cell", "toughness {D}/text_cell.csv {D}/second.csv --area 1mm^2", 1},
      {"toughness: one row", "toughness {D}/one_row.csv {D}/second.csv --area 1mm^2", 1},
      {"toughness: ragged rows", "toughness {D}/ragged.csv {D}/second.csv --area 1mm^2", 1},
      {"toughness: empty second", "toughness {D}/first.csv {D}/empty.csv --area 1mm^2", 1},
      {"toughness: no second pass", "toughness {D}/first.csv --area 1mm^2", 1},
      {"toughness: unknown --second-from",
       "toughness {D}/first.csv --second-from middle --area 1mm^2", 1},
      {"toughness: --second-from tail without a drop",
       "toughness {D}/second.csv --second-from tail --area 1mm^2", 1},
      {"toughness: no crack area", "toughness {D}/first.csv {D}/second.csv", 1},
      {"toughness: --area and --plugin",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --plugin cone", 1},
      {"toughness: --area text", "toughness {D}/first.csv {D}/second.csv --area abc", 1},
      {"toughness: --area a length", "toughness {D}/first.csv {D}/second.csv --area 5mm", 1},
      {"toughness: --area without its unit", "toughness {D}/first.csv {D}/second.csv --area 0.0415",
       1},
      {"toughness: --area zero", "toughness {D}/first.csv {D}/second.csv --area 0mm^2", 1},
      {"toughness: --area inf", "toughness {D}/first.csv {D}/second.csv --area inf", 1},
      {"toughness: --area 1e-400", "toughness {D}/first.csv {D}/second.csv --area 1e-400", 1},
      {"toughness: unknown --align",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --align sideways", 1},
      {"toughness: --max-depth text",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --max-depth abc", 1},
      {"toughness: --max-depth without unit",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --max-depth 2", 1},
      {"toughness: --needle missing",
       "toughness {D}/first.csv {D}/second.csv --needle {D}/missing.stl", 1},
      {"toughness: --needle text", "toughness {D}/first.csv {D}/second.csv --needle {D}/text.stl",
       1},
      {"toughness: --unit unknown",
       "toughness {D}/first.csv {D}/second.csv --needle {R}/designs/cone.stl --unit ft", 1},
      {"toughness: unknown --plugin", "toughness {D}/first.csv {D}/second.csv --plugin nope", 1},
      {"toughness: --set text value",
       "toughness {D}/first.csv {D}/second.csv --plugin cone --set diameter=abc", 1},
      {"toughness: --set unknown",
       "toughness {D}/first.csv {D}/second.csv --plugin cone --set colour=1", 1},
      {"toughness: --plugin-dir missing",
       "toughness {D}/first.csv {D}/second.csv --plugin cone --plugin-dir {D}/missing_dir", 1},
      {"toughness: --depth-col missing",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --depth-col nope", 1},
      {"toughness: --force-col missing",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --force-col nope", 1},
      {"toughness: --depth-unit a mass",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --depth-unit kg", 1},
      {"toughness: --force-unit a length",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --force-unit mm", 1},
      {"toughness: --integrand is a directory",
       "toughness {D}/first.csv {D}/second.csv --area 1mm^2 --integrand {D}/folder", 1},
      {"calibrate: missing scene", "calibrate {D}/missing.toml --curve {D}/curve.csv --fit scale",
       1},
      {"calibrate: invalid scene", "calibrate {D}/depth_kg.toml --curve {D}/curve.csv --fit scale",
       1},
      {"calibrate: two needles", "calibrate {D}/two_needles.toml --curve {D}/curve.csv --fit scale",
       1},
      {"calibrate: no --curve", "calibrate {D}/good.toml --fit scale", 2},
      {"calibrate: unknown --fit", "calibrate {D}/good.toml --curve {D}/curve.csv --fit stiffness",
       1},
      {"calibrate: empty --fit", "calibrate {D}/good.toml --curve {D}/curve.csv --fit ''", 1},
      {"calibrate: --fit repeated",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale,scale --puncture-at 3mm", 1},
      {"calibrate: --fit both criteria",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit critical_pressure,toughness", 1},
      {"calibrate: friction without Coulomb",
       "calibrate {D}/no_friction.toml --curve {D}/curve.csv --fit friction_coefficient "
       "--puncture-at 3mm",
       1},
      {"calibrate: --curve missing", "calibrate {D}/good.toml --curve {D}/missing.csv --fit scale",
       1},
      {"calibrate: --curve empty", "calibrate {D}/good.toml --curve {D}/empty.csv --fit scale", 1},
      {"calibrate: --curve header only",
       "calibrate {D}/good.toml --curve {D}/header_only.csv --fit scale", 1},
      {"calibrate: --curve text cell",
       "calibrate {D}/good.toml --curve {D}/text_cell.csv --fit scale", 1},
      {"calibrate: --curve ragged", "calibrate {D}/good.toml --curve {D}/ragged.csv --fit scale",
       1},
      {"calibrate: --curve one row",
       "calibrate {D}/good.toml --curve {D}/one_row.csv --fit scale --puncture-at detect", 1},
      {"calibrate: --contact-at text",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --contact-at abc", 1},
      {"calibrate: --contact-at nan",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --contact-at nanmm", 1},
      {"calibrate: --puncture-at in kg",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --puncture-at 5kg", 1},
      {"calibrate: --puncture-at detect, no drop",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --puncture-at detect", 1},
      {"calibrate: --puncture-at beyond the curve",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --puncture-at 100mm", 1},
      {"calibrate: --fit-range without :",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --fit-range 5mm", 1},
      {"calibrate: --fit-range without unit",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --fit-range 1:5", 1},
      {"calibrate: --fit-range reversed",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --puncture-at 3mm --fit-range "
       "5mm:1mm",
       1},
      {"calibrate: --fidelity unknown",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --fidelity ultra", 2},
      {"calibrate: --depth-col missing",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --depth-col nope", 1},
      {"calibrate: --force-col missing",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --force-col nope", 1},
      {"calibrate: --depth-unit a time",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --depth-unit s", 1},
      {"calibrate: --force-unit unknown",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --force-unit lbf", 1},
      {"calibrate: --plugin-dir missing",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --plugin-dir {D}/missing_dir", 1},
      {"calibrate: --out is a directory",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --puncture-at 3mm --out "
       "{D}/folder",
       1},
      {"calibrate: --plot is a directory",
       "calibrate {D}/good.toml --curve {D}/curve.csv --fit scale --puncture-at 3mm --plot "
       "{D}/folder",
       1},
  };
  const std::regex non_finite(R"(\b(nan|inf)\b)", std::regex::icase);
  for (const Case& c : cases) {
    const std::string args =
        replace_all(replace_all(c.args, "{D}", "'" + dir.string() + "'"), "{R}", "'" + kRoot + "'");
    SCOPED_TRACE(std::string(c.name) + ": mneedle " + args);
    const auto run = run_mneedle(args);
    EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
    // One line: a second one would be a stack of messages or a stray progress or warning line.
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_TRUE(run.err.ends_with('\n')) << run.err;
    EXPECT_TRUE(run.err.starts_with("mneedle: error: ")) << run.err;
    for (const char* marker : kInternalMarkers)
      EXPECT_EQ(run.err.find(marker), std::string::npos) << marker << " in: " << run.err;
    EXPECT_FALSE(std::regex_search(unquoted(run.err), non_finite)) << run.err;
  }
  fs::remove_all(dir);
}

}  // namespace

namespace {

TEST(WorkLimits, SceneWithMoreNeedlesThanTheLimitIsRefusedBeforeAnyNeedleIsBuilt) {
  // Every needle names a file that is not a mesh: had one been read before the count was
  // checked, the error would be "not a mesh" (after minutes of work, were the meshes good).
  const fs::path dir = fs::temp_directory_path() / ("mneedle_limits_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::string scene = kTissue;
  for (int i = 0; i < 1001; ++i)
    scene += "\n[[needles]]\ngeometry = { stl = \"junk.stl\", unit = \"um\" }\n";
  write_file(dir / "many.toml", scene + kInsertion);
  write_file(dir / "junk.stl", "hello, this is not a mesh\n");
  const std::string file = "'" + (dir / "many.toml").string() + "'";
  for (const std::string& command : {"force " + file, "simulate " + file + " --max-needles 1000"}) {
    SCOPED_TRACE(command);
    const auto run = run_mneedle(command);
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_NE(run.err.find("needles: 1001 needles, above the limit of 1000 (raise it with "
                           "--max-needles)"),
              std::string::npos)
        << run.err;
  }
  // Raised far enough, the same scene gets as far as its first needle.
  const auto raised = run_mneedle("force " + file + " --max-needles 1001");
  EXPECT_NE(raised.err.find("junk.stl: not a mesh"), std::string::npos) << raised.err;
  const auto fe = run_mneedle("simulate " + file);
  EXPECT_NE(fe.err.find("1001 needles, above the limit of 16"), std::string::npos) << fe.err;
  fs::remove_all(dir);
}

}  // namespace

namespace {

// MNEEDLE_MEMORY_LIMIT (docs/cli.md, "Environment"): a factorisation that does not fit in it is
// refused before it is allocated, in one line with status 3 (a solver that could not deliver,
// not a bug); a limit without a unit is bad input. The skin scene at fast factorises 29 079
// unknowns into about 110 MiB, far above 20 MiB.
TEST(WorkLimits, AFactorAboveTheMemoryLimitEndsTheRunInOneLineBeforeItIsAllocated) {
  const std::string scene = "'" + kRoot + "/designs/scenes/human_skin.toml'";
  const auto run = mneedle::test::run_command("MNEEDLE_MEMORY_LIMIT='20 MiB' '" +
                                              mneedle::test::mneedle_binary() + "' simulate " +
                                              scene + " --fidelity fast --quiet");
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_EQ(run.err.rfind("mneedle: error: ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find("unknowns needs"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("of memory left to this process"), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  const auto unitless = mneedle::test::run_command(
      "MNEEDLE_MEMORY_LIMIT=300 '" + mneedle::test::mneedle_binary() + "' simulate " + scene);
  EXPECT_EQ(unitless.exit_code, 1) << unitless.err;
  EXPECT_NE(unitless.err.find("MNEEDLE_MEMORY_LIMIT: '300': no unit"), std::string::npos)
      << unitless.err;
  // Help is still there with a bad limit in the environment (as with SOURCE_DATE_EPOCH).
  EXPECT_EQ(mneedle::test::run_command("MNEEDLE_MEMORY_LIMIT=300 '" +
                                       mneedle::test::mneedle_binary() + "' --help")
                .exit_code,
            0);
}

// MNEEDLE_HUGE_PAGES (docs/cli.md, "Environment"): "off" takes the factor from ordinary pages and
// changes no result (the skin scene at fast: the same puncture to the last bit); any other value
// than "on" or "off" is bad input, one line naming the variable; help still answers.
TEST(Environment, HugePagesOffChangesNoResultAndABadValueIsOneLine) {
  const std::string run = "' simulate '" + kRoot + "/designs/scenes/human_skin.toml' --fidelity " +
                          "fast --quiet --json";
  const auto on =
      mneedle::test::run_command("MNEEDLE_HUGE_PAGES=on '" + mneedle::test::mneedle_binary() + run);
  const auto off = mneedle::test::run_command("MNEEDLE_HUGE_PAGES=off '" +
                                              mneedle::test::mneedle_binary() + run);
  ASSERT_EQ(on.exit_code, 0) << on.err;
  ASSERT_EQ(off.exit_code, 0) << off.err;
  const auto a = nlohmann::json::parse(on.out)["needles"][0]["puncture"];
  const auto b = nlohmann::json::parse(off.out)["needles"][0]["puncture"];
  EXPECT_EQ(a["depth_m"].get<double>(), b["depth_m"].get<double>());
  EXPECT_EQ(a["force_N"].get<double>(), b["force_N"].get<double>());
  const auto bad = mneedle::test::run_command("MNEEDLE_HUGE_PAGES=maybe '" +
                                              mneedle::test::mneedle_binary() + run);
  EXPECT_EQ(bad.exit_code, 1) << bad.err;
  EXPECT_EQ(bad.err,
            "mneedle: error: MNEEDLE_HUGE_PAGES: must be \"on\" or \"off\", got 'maybe'\n");
  EXPECT_EQ(mneedle::test::run_command("MNEEDLE_HUGE_PAGES=maybe '" +
                                       mneedle::test::mneedle_binary() + "' --help")
                .exit_code,
            0);
}

// MNEEDLE_BLAS_KERNELS (docs/cli.md, "Environment"): "off" keeps OpenBLAS's own kernels, "auto"
// (the default) replaces its SSE3 fallback on a CPU it does not know. The kernels sum in other
// orders, so the puncture moves by round-off only: 9e-12 of the depth and 4e-11 of the force on
// this scene, at most 4e-10 of the depth over the 40 designs of bench/screen_designs.sh
// (docs/performance.md, "BLAS kernels and huge pages, a fresh VM"); 1e-9 is that with room, far
// below any physical change. The JSON says which kernels ran. Any other value is bad input, one
// line; help still answers.
TEST(Environment, BlasKernelsOffMovesNoResultBeyondRoundOffAndABadValueIsOneLine) {
  const std::string run = "' simulate '" + kRoot + "/designs/scenes/human_skin.toml' --fidelity " +
                          "fast --quiet --json";
  const auto chosen = mneedle::test::run_command("MNEEDLE_BLAS_KERNELS=auto '" +
                                                 mneedle::test::mneedle_binary() + run);
  const auto off = mneedle::test::run_command("MNEEDLE_BLAS_KERNELS=off '" +
                                              mneedle::test::mneedle_binary() + run);
  ASSERT_EQ(chosen.exit_code, 0) << chosen.err;
  ASSERT_EQ(off.exit_code, 0) << off.err;
  const auto a = nlohmann::json::parse(chosen.out);
  const auto b = nlohmann::json::parse(off.out);
  const double depth = b["needles"][0]["puncture"]["depth_m"].get<double>();
  const double force = b["needles"][0]["puncture"]["force_N"].get<double>();
  EXPECT_NEAR(a["needles"][0]["puncture"]["depth_m"].get<double>(), depth, 1e-9 * depth);
  EXPECT_NEAR(a["needles"][0]["puncture"]["force_N"].get<double>(), force, 1e-9 * force);
  if (!b["blas_kernels"].is_null()) {
    // off: OpenBLAS's own choice, detected and used alike; auto: the same detection, and the
    // table's core where it has one for this CPU (this test's environment names none).
    EXPECT_EQ(b["blas_kernels"]["used"], b["blas_kernels"]["detected"]);
    EXPECT_EQ(a["blas_kernels"]["detected"], b["blas_kernels"]["detected"]);
    const std::string better = mneedle::fe::better_openblas_core(
        b["blas_kernels"]["detected"].get<std::string>(), mneedle::fe::cpu_simd_level());
    if (std::getenv("OPENBLAS_CORETYPE") == nullptr && !better.empty()) {
      EXPECT_EQ(a["blas_kernels"]["used"], better);
    }
  }
  const auto bad = mneedle::test::run_command("MNEEDLE_BLAS_KERNELS=fastest '" +
                                              mneedle::test::mneedle_binary() + run);
  EXPECT_EQ(bad.exit_code, 1) << bad.err;
  EXPECT_EQ(bad.err,
            "mneedle: error: MNEEDLE_BLAS_KERNELS: must be \"auto\" or \"off\", got 'fastest'\n");
  EXPECT_EQ(mneedle::test::run_command("MNEEDLE_BLAS_KERNELS=fastest '" +
                                       mneedle::test::mneedle_binary() + "' --help")
                .exit_code,
            0);
}

// An address-space limit (`ulimit -v`, as batch systems set) counts as memory left: the run is
// refused in one line with status 3. Before, CHOLMOD's solve crashed (status 139) and OpenBLAS
// retried its work buffer's mmap for ever; 400 MB leaves no room for the fast skin run's
// 69 MiB factor beside the process's mappings and OpenBLAS's buffers, 1.5 GB does.
// AddressSanitizer's shadow memory cannot be mapped under such a limit at all.
TEST(WorkLimits, AnAddressSpaceLimitEndsTheRunInOneLineInsteadOfAHangOrACrash) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer cannot start under ulimit -v";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  GTEST_SKIP() << "AddressSanitizer cannot start under ulimit -v";
#endif
#endif
  // One OpenBLAS thread: a many-core machine's threads would not start under 400 MB at all.
  const auto under = [](const std::string& kilobytes) {
    return mneedle::test::run_command("ulimit -v " + kilobytes +
                                      " && OPENBLAS_NUM_THREADS=1 timeout 120 '" +
                                      mneedle::test::mneedle_binary() + "' simulate '" + kRoot +
                                      "/designs/scenes/human_skin.toml' --fidelity fast --quiet");
  };
  const auto run = under("400000");
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_EQ(run.err.rfind("mneedle: error: ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find("the factor of"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("of memory left to this process"), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  // 1.5 GB holds the run (about 0.3 GB mapped at the factorisation, a 69 MiB factor and the
  // kept-back 256 MiB of OpenBLAS buffers).
  const auto fits = under("1500000");
  EXPECT_EQ(fits.exit_code, 0) << fits.err;
}

}  // namespace

namespace {

TEST(SceneCheck, RefusesNeedlesThatDoNotFitOrShareTissueAsEveryRunDoes) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_place_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_file(dir / "two.toml", kTissue + kNeedle + kNeedle + kInsertion);
  // A mesh file in mm read as metres: only its mesh says how wide it is.
  write_file(dir / "wide.toml", kTissue + "\n[[needles]]\ngeometry = { stl = \"" + kRoot +
                                    "/designs/cone.stl\", unit = \"m\" }\n" + kInsertion);
  write_file(dir / "good.toml", kTissue + kNeedle + kInsertion);
  const auto two = run_mneedle("scene check '" + (dir / "two.toml").string() + "'");
  EXPECT_EQ(two.exit_code, 1);
  EXPECT_NE(two.err.find("overlaps needle"), std::string::npos) << two.err;
  const auto wide = run_mneedle("scene check '" + (dir / "wide.toml").string() + "'");
  EXPECT_EQ(wide.exit_code, 1);
  EXPECT_NE(wide.err.find("does not fit in the 2 mm x 2 mm block (is the mesh's unit right?)"),
            std::string::npos)
      << wide.err;
  EXPECT_EQ(run_mneedle("scene check '" + (dir / "good.toml").string() + "'").exit_code, 0);
  fs::remove_all(dir);
}

// The summary's layer depths: the top layer starts at zero, written in its bottom's unit (it read
// "0 m to 20 um", docs/cli.md shows "0 um to 20 um").
TEST(SceneCheck, ATopLayerStartsAtZeroInTheUnitOfItsBottom) {
  const auto run = run_mneedle("scene check '" + kRoot + "/designs/scenes/human_skin.toml'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("[0] stratum_corneum: 0 um to 20 um (20 um)"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("[1] epidermis: 20 um to 120 um (100 um)"), std::string::npos) << run.out;
}

// The convergence study's contact zone is a scene's [model] keys (docs/scene.md): lengths with
// their unit, shown back in SI; a tip size without its zone is one line naming file, line and key.
TEST(SceneCheck, AContactZoneIsReadWithItsUnitsAndATipSizeAloneIsRefused) {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_zone_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_file(dir / "zone.toml", kTissue + kNeedle + kInsertion +
                                    "\n[model]\ncontact_zone = \"6 um\"\n"
                                    "contact_zone_tip = \"0.3 um\"\n");
  write_file(dir / "tip.toml",
             kTissue + kNeedle + kInsertion + "\n[model]\ncontact_zone_tip = \"0.3 um\"\n");
  const auto zone = run_mneedle("scene check '" + (dir / "zone.toml").string() + "' --json");
  ASSERT_EQ(zone.exit_code, 0) << zone.err;
  const auto model = nlohmann::json::parse(zone.out)["model"];
  EXPECT_DOUBLE_EQ(model["contact_zone_m"].get<double>(), 6e-6);
  EXPECT_DOUBLE_EQ(model["contact_zone_tip_m"].get<double>(), 0.3e-6);
  const auto tip = run_mneedle("scene check '" + (dir / "tip.toml").string() + "'");
  EXPECT_NE(tip.exit_code, 0);
  EXPECT_NE(tip.err.find("tip.toml:"), std::string::npos) << tip.err;
  EXPECT_NE(tip.err.find("model.contact_zone_tip"), std::string::npos) << tip.err;
  fs::remove_all(dir);
}

}  // namespace
