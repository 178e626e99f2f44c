#include "mneedle/scene/scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <numbers>
#include <sstream>
#include <string>
#include <string_view>
#include <variant>

#include "mneedle/base/error.h"

namespace {

using mneedle::InputError;
using mneedle::Scene;

const std::filesystem::path kAssets = std::filesystem::path(MNEEDLE_TEST_ASSETS) / "scenes";
const std::filesystem::path kDesigns =
    std::filesystem::path(MNEEDLE_SOURCE_ROOT) / "designs" / "scenes";

// Line numbers matter: the error tests below name them.
constexpr std::string_view kBase = R"([tissue]
size = ["3000 um", "3000 um", "1150 um"]
boundary = "fixed"

[[tissue.layers]]
name = "stratum_corneum"
thickness = "20 um"
material = { model = "linear", E = "1 GPa", nu = 0.4 }

[[tissue.layers]]
name = "dermis"
thickness = "1130 um"
material = { model = "linear", E = "0.08 MPa", nu = 0.4 }

[tissue.fracture]
toughness = "0.019 N/mm"
critical_pressure = "0.663 MPa"

[[needles]]
geometry = { plugin = "sharp_bevel", diameter = "230 um", length = "1000 um", bevel_angle = "30 deg" }
at = ["0 um", "0 um"]
material = "silicon"

[insertion]
depth = "800 um"
speed = "1 mm/s"
angle = "90 deg"

[model]
fidelity = "standard"
outputs = ["puncture", "force_curve"]
)";

// kBase with one exact piece of text replaced (the piece must occur once).
std::string with(std::string_view from, std::string_view to,
                 std::string text = std::string(kBase)) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "fixture text not found: " << from;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "fixture text not unique: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

Scene parse(const std::string& toml) {
  return mneedle::parse_scene(toml, "test.toml");
}

// Parses `toml`, expects an InputError and checks that its message holds every piece.
void expect_error(const std::string& toml, std::initializer_list<std::string_view> pieces) {
  try {
    parse(toml);
    ADD_FAILURE() << "expected an InputError for:\n" << toml;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto piece : pieces) {
      EXPECT_NE(msg.find(piece), std::string::npos) << "'" << piece << "' missing in: " << msg;
    }
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message is not one line: " << msg;
  }
}

// ---- valid scenes ---------------------------------------------------------------------------

TEST(Scene, BaseSceneParsesIntoSi) {
  const Scene s = parse(std::string(kBase));
  EXPECT_EQ(s.source_name, "test.toml");
  EXPECT_DOUBLE_EQ(s.tissue.size[0], 3e-3);
  EXPECT_DOUBLE_EQ(s.tissue.depth(), 1.15e-3);
  ASSERT_EQ(s.tissue.layers.size(), 2u);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].material.youngs_modulus, 1e9);
  EXPECT_DOUBLE_EQ(s.tissue.layers[1].top, 20e-6);
  ASSERT_TRUE(s.tissue.layers[1].fracture);
  EXPECT_DOUBLE_EQ(s.tissue.layers[1].fracture->toughness, 19.0);
  EXPECT_FALSE(s.tissue.layers[1].fracture_is_own);
  ASSERT_EQ(s.needles.size(), 1u);
  EXPECT_EQ(s.needles[0].name, "sharp_bevel");
  const auto& geometry = std::get<mneedle::PluginGeometry>(s.needles[0].geometry);
  EXPECT_EQ(geometry.plugin, "sharp_bevel");
  EXPECT_DOUBLE_EQ(geometry.parameters.at("diameter").value_si, 230e-6);
  EXPECT_EQ(geometry.parameters.at("bevel_angle").dimension, mneedle::Dimension::Angle);
  EXPECT_DOUBLE_EQ(s.insertion.depth, 800e-6);
  EXPECT_DOUBLE_EQ(s.insertion.speed, 1e-3);
  EXPECT_DOUBLE_EQ(s.insertion.angle, std::numbers::pi / 2.0);
}

TEST(Scene, OptionalTablesTakeTheirDefaults) {
  const Scene s =
      parse(with("[model]\nfidelity = \"standard\"\noutputs = [\"puncture\", "
                 "\"force_curve\"]\n",
                 ""));
  EXPECT_EQ(s.model.fidelity, mneedle::Fidelity::Standard);
  EXPECT_TRUE(s.model.wants(mneedle::Output::Puncture));
  EXPECT_TRUE(s.model.wants(mneedle::Output::ForceCurve));
  EXPECT_FALSE(s.model.wants(mneedle::Output::Fields));
  EXPECT_EQ(s.model.criterion, mneedle::PunctureCriterion::Pressure);
  EXPECT_EQ(s.model.contact, mneedle::Contact::Sticking);
  EXPECT_DOUBLE_EQ(s.loads.scale, 0.168);
  EXPECT_FALSE(s.loads.stiffness);
  EXPECT_EQ(s.loads.friction, mneedle::FrictionLaw::Coulomb);
  EXPECT_DOUBLE_EQ(s.loads.friction_coefficient, 0.2);
  EXPECT_FALSE(s.requirements.target_depth);
  EXPECT_DOUBLE_EQ(s.requirements.safety_factor, 1.5);
  EXPECT_TRUE(s.materials.empty());
  EXPECT_FALSE(s.model.mesh_refinement);  // the fidelity's default
  EXPECT_EQ(s.model.crack_faces, mneedle::CrackFaces::Contact);
}

TEST(Scene, CrackFacesMayBeLeftFree) {
  const Scene s =
      parse(with("fidelity = \"standard\"", "fidelity = \"standard\"\ncrack_faces = \"free\""));
  EXPECT_EQ(s.model.crack_faces, mneedle::CrackFaces::Free);
  EXPECT_EQ(mneedle::to_string(s.model.crack_faces), "free");
}

TEST(Scene, MeshRefinementIsAWholeNumberOfHalvings) {
  const Scene s =
      parse(with("fidelity = \"standard\"", "fidelity = \"standard\"\nmesh_refinement = 3"));
  EXPECT_EQ(s.model.mesh_refinement, 3);
}

TEST(Scene, AContactZoneAndItsTipSizeAreLengths) {
  const Scene s = parse(with("fidelity = \"standard\"",
                             "fidelity = \"standard\"\ncontact_zone = \"6 um\"\n"
                             "contact_zone_tip = \"0.3 um\""));
  EXPECT_DOUBLE_EQ(*s.model.contact_zone, 6e-6);
  EXPECT_DOUBLE_EQ(*s.model.contact_zone_tip, 0.3e-6);
  const Scene plain = parse(with("fidelity = \"standard\"", "fidelity = \"standard\""));
  EXPECT_FALSE(plain.model.contact_zone || plain.model.contact_zone_tip);
  // "none": no zone at all, not even the level's own (0 inside), with or without refinement.
  const Scene none = parse(with("fidelity = \"standard\"",
                                "fidelity = \"standard\"\nmesh_refinement = 0\n"
                                "contact_zone = \"none\""));
  ASSERT_TRUE(none.model.contact_zone.has_value());
  EXPECT_DOUBLE_EQ(*none.model.contact_zone, 0.0);
}

// A dimensional value needs its unit (docs/scene.md, "General rules"): `thickness = 20` was read
// as 20 m and failed only when the layers overfilled the block; 2e-5 passed as 20 um. A plain
// number is taken where no unit can be forgotten (a dimensionless key) and as 0.
TEST(Scene, APlainNumberForADimensionalKeyIsAnErrorThatListsItsUnits) {
  const std::string sized = R"(size = ["3000 um", "3000 um", "1150 um"])";
  for (const std::string& plain :
       {std::string("size = [0.003, 0.003, 1.15e-3]"), std::string("size = [3000, 3000, 1150]")}) {
    try {
      parse(with(sized, plain));
      FAIL() << plain;
    } catch (const mneedle::InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("tissue.size[0]: a number needs its unit here: a length such as "
                          "\"230 um\" (nm, um, mm, cm, m)"),
                std::string::npos)
          << what;
    }
  }
  const Scene s = parse(with(R"(at = ["0 um", "0 um"])", "at = [0, 0]"));
  EXPECT_DOUBLE_EQ(s.needles[0].at[0], 0.0);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].material.poisson_ratio, 0.4);
}

TEST(Scene, LastLayerWithoutThicknessFillsTheBlock) {
  const Scene s = parse(with("thickness = \"1130 um\"\n", ""));
  EXPECT_NEAR(s.tissue.layers[1].thickness, 1.13e-3, 1e-15);
  EXPECT_NEAR(s.tissue.layers[1].top + s.tissue.layers[1].thickness, 1.15e-3, 1e-15);
}

TEST(Scene, LayerFractureOverridesTheTissueDefault) {
  const Scene s = parse(with("name = \"dermis\"\n",
                             "name = \"dermis\"\nfracture = { toughness = \"100 J/m^2\", "
                             "critical_pressure = \"2 MPa\" }\n"));
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].fracture->toughness, 19.0);
  EXPECT_DOUBLE_EQ(s.tissue.layers[1].fracture->toughness, 100.0);
  EXPECT_DOUBLE_EQ(s.tissue.layers[1].fracture->critical_pressure, 2e6);
  EXPECT_TRUE(s.tissue.layers[1].fracture_is_own);
}

TEST(Scene, ACohesiveLawIsReadWithItsStrengthAndShape) {
  const std::string pc = "critical_pressure = \"0.663 MPa\"\n";
  const Scene plain = parse(std::string(kBase));
  EXPECT_FALSE(plain.tissue.layers[0].fracture->cohesive_strength);
  const Scene s =
      parse(with(pc, pc + "cohesive_strength = \"356 kPa\"\ncohesive_peak_ratio = 0.1\n"));
  EXPECT_DOUBLE_EQ(*s.tissue.layers[0].fracture->cohesive_strength, 356e3);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].fracture->cohesive_peak_ratio, 0.1);
  // Copied to every layer from [tissue.fracture], as the rest of it.
  EXPECT_DOUBLE_EQ(*s.tissue.layers[1].fracture->cohesive_strength, 356e3);
  const Scene defaulted = parse(with(pc, pc + "cohesive_strength = \"356 kPa\"\n"));
  EXPECT_DOUBLE_EQ(defaulted.tissue.layers[0].fracture->cohesive_peak_ratio, 0.01);
}

TEST(SceneErrors, ACohesiveLawNeedsItsStrengthAUnitAndARatioBelowOne) {
  const std::string pc = "critical_pressure = \"0.663 MPa\"\n";
  expect_error(with(pc, pc + "cohesive_strength = 356000\n"),
               {"tissue.fracture.cohesive_strength", "unit"});
  expect_error(with(pc, pc + "cohesive_peak_ratio = 0.1\n"),
               {"tissue.fracture.cohesive_peak_ratio", "give cohesive_strength too"});
  expect_error(with(pc, pc + "cohesive_strength = \"356 kPa\"\ncohesive_peak_ratio = 1\n"),
               {"tissue.fracture.cohesive_peak_ratio", "[1e-4, 0.9]"});
  expect_error(with("fidelity = \"standard\"", "criterion = \"cohesive\""),
               {"test.toml:30:", "model.criterion", "cohesive_strength"});
}

TEST(Scene, WithoutAnyFractureDataLayersHaveNone) {
  const Scene s = parse(with(
      "[tissue.fracture]\ntoughness = \"0.019 N/mm\"\ncritical_pressure = \"0.663 MPa\"\n", ""));
  EXPECT_FALSE(s.tissue.layers[0].fracture);
  EXPECT_FALSE(s.tissue.fracture);
}

TEST(Scene, LayerIndexAtDepthPutsInterfacesInTheDeeperLayer) {
  const Scene s = parse(std::string(kBase));
  EXPECT_EQ(mneedle::layer_index_at_depth(s.tissue, 0.0), 0u);
  EXPECT_EQ(mneedle::layer_index_at_depth(s.tissue, 19e-6), 0u);
  EXPECT_EQ(mneedle::layer_index_at_depth(s.tissue, 20e-6), 1u);
  EXPECT_EQ(mneedle::layer_index_at_depth(s.tissue, 5e-3), 1u);
}

TEST(Scene, MooneyRivlinTakesPoissonRatio) {
  const Scene s = parse(
      with(R"(material = { model = "linear", E = "0.08 MPa", nu = 0.4 })",
           R"(material = { model = "mooney_rivlin", C10 = "10 kPa", C01 = "5 kPa", nu = 0.45 })"));
  const auto& m = s.tissue.layers[1].material;
  EXPECT_EQ(m.model, mneedle::MaterialModel::MooneyRivlin);
  EXPECT_DOUBLE_EQ(m.shear_modulus(), 2.0 * (10e3 + 5e3));
  EXPECT_DOUBLE_EQ(m.youngs_modulus, 2.0 * 30e3 * 1.45);
}

TEST(Scene, MooneyRivlinTakesBulkModulus) {
  const Scene s = parse(with(
      R"(material = { model = "linear", E = "0.08 MPa", nu = 0.4 })",
      R"(material = { model = "mooney_rivlin", C10 = "10 kPa", C01 = "5 kPa", K = "1 MPa" })"));
  const auto& m = s.tissue.layers[1].material;
  EXPECT_NEAR(m.bulk_modulus(), 1e6, 1e-6);
  EXPECT_NEAR(m.shear_modulus(), 30e3, 1e-9);
  EXPECT_GT(m.poisson_ratio, 0.48);
  EXPECT_LT(m.poisson_ratio, 0.5);
}

TEST(Scene, UnnamedNeedlesGetUniqueNames) {
  const std::string needle =
      "[[needles]]\ngeometry = { plugin = \"cone\", half_angle = \"20 deg\" }\nat = [\"%X\", "
      "\"0 um\"]\n";
  std::string toml = std::string(kBase);
  for (const char* x : {"-1 mm", "1 mm"}) toml += with("%X", x, needle);
  toml +=
      "[[needles]]\nname = \"cone_2\"\ngeometry = { plugin = \"cone\" }\nat = [\"0 um\", "
      "\"1 mm\"]\n";
  const Scene s = parse(toml);
  ASSERT_EQ(s.needles.size(), 4u);
  EXPECT_EQ(s.needles[1].name, "cone");
  EXPECT_EQ(s.needles[2].name, "cone_3");  // cone_2 is taken by the explicit name
  EXPECT_EQ(s.needles[3].name, "cone_2");
  EXPECT_DOUBLE_EQ(s.needles[1].at[0], -1e-3);
}

TEST(Scene, PluginParametersKeepTheirQuantities) {
  const Scene s = parse(with(R"(bevel_angle = "30 deg" })",
                             R"(bevel_angle = "30 deg", resolution = 64, bore = 9e-5 })"));
  const auto& p = std::get<mneedle::PluginGeometry>(s.needles[0].geometry).parameters;
  EXPECT_EQ(p.at("resolution").dimension, mneedle::Dimension::Dimensionless);
  EXPECT_DOUBLE_EQ(p.at("resolution").value_si, 64.0);
  EXPECT_DOUBLE_EQ(p.at("bore").value_si, 9e-5);
}

// The scene file is read from the assets folder so its STL path resolves.
Scene parse_in_assets(const std::string& text) {
  return mneedle::parse_scene(text, (kAssets / "axis_test.toml").string());
}

TEST(Scene, StlAxisIsReadAsANameOrATipDirection) {
  std::ifstream in(kAssets / "stl_needle.toml");
  std::stringstream whole;
  whole << in.rdbuf();
  std::string text = whole.str();
  const std::string from = "geometry = { stl = \"tiny_needle.stl\", unit = \"mm\" }";
  ASSERT_NE(text.find(from), std::string::npos);
  std::string named = text;
  named.replace(named.find(from), from.size(),
                "geometry = { stl = \"tiny_needle.stl\", unit = \"mm\", axis = \"y\" }");
  EXPECT_EQ(std::get<mneedle::StlGeometry>(parse_in_assets(named).needles[0].geometry).axis, "y");
  std::string vector = text;
  vector.replace(vector.find(from), from.size(),
                 "geometry = { stl = \"tiny_needle.stl\", unit = \"mm\", axis = [0, -1, 0] }");
  EXPECT_EQ(std::get<mneedle::StlGeometry>(parse_in_assets(vector).needles[0].geometry).axis,
            "0,-1,0");
  std::string bad = text;
  bad.replace(bad.find(from), from.size(),
              "geometry = { stl = \"tiny_needle.stl\", unit = \"mm\", axis = \"up\" }");
  try {
    parse_in_assets(bad);
    FAIL() << "expected an InputError";
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("geometry.axis"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("auto, x, y, z"), std::string::npos) << e.what();
  }
}

TEST(Scene, StlNeedleResolvesRelativeToTheSceneFile) {
  const Scene s = mneedle::load_scene(kAssets / "stl_needle.toml");
  ASSERT_EQ(s.needles.size(), 2u);
  const auto& stl = std::get<mneedle::StlGeometry>(s.needles[0].geometry);
  EXPECT_TRUE(std::filesystem::equivalent(stl.path, kAssets / "tiny_needle.stl"));
  EXPECT_EQ(stl.unit, "mm");
  EXPECT_DOUBLE_EQ(stl.unit_scale, 1e-3);
  EXPECT_EQ(s.needles[0].name, "tiny_needle");
  EXPECT_EQ(s.needles[1].name, "tiny_needle_2");
  EXPECT_EQ(s.tissue.layers[0].material.model, mneedle::MaterialModel::NeoHookean);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].thickness, 1e-3);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "my_pla");
  EXPECT_DOUBLE_EQ(s.materials[0].youngs_modulus, 3.5e9);
  EXPECT_DOUBLE_EQ(*s.materials[0].density, 1240.0);
  EXPECT_EQ(*s.needles[0].material, "my_pla");
}

TEST(Scene, LoadsAndRequirementsAreRead) {
  const Scene s = parse(std::string(kBase) + R"(
[loads]
scale = 0.2
stiffness = "50 kPa"
friction = "linear_growth"
friction_max_force = "0.919 N"
friction_saturation_depth = "86 mm"

[requirements]
target_depth = "300 um"
safety_factor = 2
)");
  EXPECT_DOUBLE_EQ(s.loads.scale, 0.2);
  EXPECT_DOUBLE_EQ(*s.loads.stiffness, 5e4);
  EXPECT_EQ(s.loads.friction, mneedle::FrictionLaw::LinearGrowth);
  EXPECT_DOUBLE_EQ(s.loads.friction_max_force, 0.919);
  EXPECT_DOUBLE_EQ(s.loads.friction_saturation_depth, 0.086);
  EXPECT_DOUBLE_EQ(*s.requirements.target_depth, 3e-4);
  EXPECT_DOUBLE_EQ(s.requirements.safety_factor, 2.0);
}

// ---- shipped scenes -------------------------------------------------------------------------

TEST(Scene, ShippedHumanSkinRoundTrips) {
  const Scene s = mneedle::load_scene(kDesigns / "human_skin.toml");
  EXPECT_DOUBLE_EQ(s.tissue.size[0], 3e-3);
  EXPECT_DOUBLE_EQ(s.tissue.size[2], 1.15e-3);
  ASSERT_EQ(s.tissue.layers.size(), 3u);
  EXPECT_EQ(s.tissue.layers[0].name, "stratum_corneum");
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].thickness, 20e-6);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].material.youngs_modulus, 1e9);
  EXPECT_DOUBLE_EQ(s.tissue.layers[1].thickness, 100e-6);
  EXPECT_DOUBLE_EQ(s.tissue.layers[1].material.youngs_modulus, 0.134e6);
  EXPECT_NEAR(s.tissue.layers[2].thickness, 1030e-6, 1e-15);
  EXPECT_DOUBLE_EQ(s.tissue.layers[2].material.youngs_modulus, 0.08e6);
  for (const auto& layer : s.tissue.layers) {
    EXPECT_DOUBLE_EQ(layer.material.poisson_ratio, 0.4);
    ASSERT_TRUE(layer.fracture);
  }
  ASSERT_EQ(s.needles.size(), 1u);
  const auto& g = std::get<mneedle::PluginGeometry>(s.needles[0].geometry);
  EXPECT_EQ(g.plugin, "sharp_bevel");
  EXPECT_DOUBLE_EQ(g.parameters.at("diameter").value_si, 230e-6);
  EXPECT_DOUBLE_EQ(g.parameters.at("length").value_si, 1000e-6);
  EXPECT_NEAR(g.parameters.at("bevel_angle").value_si, std::numbers::pi / 6.0, 1e-15);
  EXPECT_EQ(*s.needles[0].material, "silicon");
  EXPECT_DOUBLE_EQ(s.insertion.depth, 800e-6);
  EXPECT_LT(s.insertion.depth, g.parameters.at("length").value_si);
}

TEST(Scene, ShippedSiliconePhantomRoundTrips) {
  const Scene s = mneedle::load_scene(kDesigns / "silicone_phantom.toml");
  EXPECT_DOUBLE_EQ(s.tissue.size[0], 10e-3);
  EXPECT_DOUBLE_EQ(s.tissue.size[2], 5e-3);
  ASSERT_EQ(s.tissue.layers.size(), 1u);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].thickness, 5e-3);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].material.youngs_modulus, 0.2e6);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].material.poisson_ratio, 0.49);
  ASSERT_TRUE(s.tissue.layers[0].fracture);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].fracture->toughness, 19.0);
  EXPECT_DOUBLE_EQ(s.tissue.layers[0].fracture->critical_pressure, 0.663e6);
  EXPECT_DOUBLE_EQ(s.insertion.depth, 2e-3);
  const auto& g = std::get<mneedle::PluginGeometry>(s.needles[0].geometry);
  EXPECT_GT(g.parameters.at("length").value_si, s.insertion.depth);
}

// ---- errors: each names file:line, the key path and the problem -----------------------------

TEST(SceneErrors, UnknownUnit) {
  expect_error(with("\"20 um\"", "\"20 uf\""),
               {"test.toml:7:", "tissue.layers[0].thickness", "unknown unit 'uf'"});
}

TEST(SceneErrors, AContactZoneTipNeedsItsZoneAndFitsInIt) {
  expect_error(
      with("fidelity = \"standard\"", "fidelity = \"standard\"\ncontact_zone_tip = \"0.3 um\""),
      {"test.toml:31:", "model.contact_zone_tip", "give contact_zone too"});
  expect_error(with("fidelity = \"standard\"",
                    "fidelity = \"standard\"\ncontact_zone = \"6 um\"\n"
                    "contact_zone_tip = \"8 um\""),
               {"model.contact_zone_tip", "must not exceed contact_zone"});
  expect_error(with("fidelity = \"standard\"", "fidelity = \"standard\"\ncontact_zone = \"0 um\""),
               {"test.toml:31:", "model.contact_zone", "must be positive"});
  expect_error(with("fidelity = \"standard\"",
                    "fidelity = \"standard\"\ncontact_zone = \"none\"\n"
                    "contact_zone_tip = \"0.3 um\""),
               {"model.contact_zone_tip", "give contact_zone too"});
  expect_error(
      with("fidelity = \"standard\"", "fidelity = \"standard\"\ncontact_zone = \"nothing\""),
      {"test.toml:31:", "model.contact_zone", "or \"none\"", "\"nothing\""});
  expect_error(with("fidelity = \"standard\"", "fidelity = \"standard\"\ncontact_zone = \"6 s\""),
               {"test.toml:31:", "model.contact_zone"});
  expect_error(with("fidelity = \"standard\"",
                    "fidelity = \"standard\"\nmesh_refinement = 0\ncontact_zone = \"6 um\""),
               {"model.contact_zone", "needs mesh_refinement >= 1"});
}

TEST(SceneErrors, MeshRefinementOutsideZeroToThreeOrNotAWholeNumber) {
  expect_error(with("fidelity = \"standard\"", "fidelity = \"standard\"\nmesh_refinement = 4"),
               {"test.toml:31:", "model.mesh_refinement", "must be 0 to 3, got 4"});
  expect_error(with("fidelity = \"standard\"", "fidelity = \"standard\"\nmesh_refinement = 1.5"),
               {"test.toml:31:", "model.mesh_refinement", "expected a whole number"});
  expect_error(with("fidelity = \"standard\"", "fidelity = \"standard\"\nmesh_refinement = \"2\""),
               {"test.toml:31:", "model.mesh_refinement", "expected a whole number"});
}

TEST(SceneErrors, CrackFacesOtherThanContactOrFree) {
  expect_error(with("fidelity = \"standard\"", "fidelity = \"standard\"\ncrack_faces = \"open\""),
               {"test.toml:31:", "model.crack_faces", "unknown value 'open'",
                "expected one of: contact, free"});
}

TEST(SceneErrors, WrongDimension) {
  expect_error(with("depth = \"800 um\"", "depth = \"800 kPa\""),
               {"test.toml:25:", "insertion.depth", "is a pressure; expected a length"});
}

TEST(SceneErrors, NegativeBlockSize) {
  expect_error(with(R"("3000 um", "3000 um", "1150 um")", R"("3000 um", "-3000 um", "1150 um")"),
               {"test.toml:2:", "tissue.size[1]", "must be positive"});
}

TEST(SceneErrors, ZeroThickness) {
  expect_error(with("\"20 um\"", "\"0 um\""),
               {"test.toml:7:", "tissue.layers[0].thickness", "must be positive"});
}

TEST(SceneErrors, SizeNeedsThreeLengths) {
  expect_error(with(R"("3000 um", "3000 um", "1150 um")", R"("3000 um", "3000 um")"),
               {"test.toml:2:", "tissue.size", "array of 3 lengths"});
}

TEST(SceneErrors, IncompressiblePoissonRatioSuggests049) {
  expect_error(with("E = \"1 GPa\", nu = 0.4", "E = \"1 GPa\", nu = 0.5"),
               {"test.toml:8:", "tissue.layers[0].material.nu", "incompressible", "0.49"});
}

TEST(SceneErrors, PoissonRatioOutsideRange) {
  expect_error(with("E = \"1 GPa\", nu = 0.4", "E = \"1 GPa\", nu = -1.2"),
               {"test.toml:8:", "tissue.layers[0].material.nu", "(-1, 0.5)"});
  expect_error(with("E = \"1 GPa\", nu = 0.4", "E = \"1 GPa\", nu = 0.7"),
               {"tissue.layers[0].material.nu", "(-1, 0.5)"});
}

TEST(SceneErrors, NonPositiveModulus) {
  expect_error(with("E = \"0.08 MPa\"", "E = \"-0.08 MPa\""),
               {"test.toml:13:", "tissue.layers[1].material.E", "must be positive"});
  expect_error(with("E = \"0.08 MPa\"", "E = 0"), {"tissue.layers[1].material.E", "positive"});
}

TEST(SceneErrors, MissingRequiredKey) {
  expect_error(with("depth = \"800 um\"\n", ""),
               {"test.toml:24:", "insertion.depth", "required key is missing", "length"});
  expect_error(with("name = \"dermis\"\n", ""),
               {"test.toml:10:", "tissue.layers[1].name", "missing"});
  expect_error(with("model = \"linear\", E = \"1 GPa\"", "E = \"1 GPa\""),
               {"tissue.layers[0].material.model", "missing"});
  // `nu` is two letters from `E` but no misspelling of it (it was reported as "unknown key (did
  // you mean 'E'?)").
  expect_error(with("E = \"1 GPa\", nu = 0.4", "nu = 0.4"),
               {"test.toml:8:", "tissue.layers[0].material.E", "required key is missing"});
}

TEST(SceneErrors, MissingTopLevelTable) {
  expect_error(
      with("[insertion]\ndepth = \"800 um\"\nspeed = \"1 mm/s\"\nangle = \"90 deg\"\n", ""),
      {"test.toml:1:", "insertion", "missing"});
}

TEST(SceneErrors, UnknownKeyWithSuggestion) {
  expect_error(with("thickness = \"20 um\"", "thicknes = \"20 um\""),
               {"test.toml:7:", "tissue.layers[0].thicknes", "unknown key",
                "did you mean "
                "'thickness'"});
}

TEST(SceneErrors, UnknownKeyAnywhere) {
  expect_error(with("[model]", "[modle]"), {"test.toml:29:", "modle", "unknown key"});
  expect_error(with("nu = 0.4 }\n\n[[tissue.layers]]\nname = \"dermis\"",
                    "nu = 0.4, G = 3 }\n\n[[tissue.layers]]\nname = \"dermis\""),
               {"test.toml:8:", "tissue.layers[0].material.G", "unknown key"});
  expect_error(with("toughness = \"0.019 N/mm\"", "toughness = \"0.019 N/mm\"\nPc = 1"),
               {"test.toml:17:", "tissue.fracture.Pc", "unknown key"});
  expect_error(with("angle = \"90 deg\"", "angle = \"90 deg\"\ndepht = 1"),
               {"test.toml:28:", "insertion.depht", "unknown key"});
}

TEST(SceneErrors, LayersThickerThanTheBlock) {
  expect_error(with("\"1130 um\"", "\"1200 um\""),
               {"test.toml:5:", "tissue.layers", "add up to 1.22 mm", "block depth"});
}

TEST(SceneErrors, LayersThinnerThanTheBlockSuggestLeavingOutTheLastThickness) {
  expect_error(with("\"1130 um\"", "\"1000 um\""),
               {"test.toml:10:", "tissue.layers[1]", "1.15 mm", "leave out the last layer"});
}

TEST(SceneErrors, LastLayerLeftWithNothing) {
  expect_error(with("\"20 um\"", "\"1150 um\"", with("thickness = \"1130 um\"\n", "")),
               {"tissue.layers[1]", "leaving nothing"});
}

TEST(SceneErrors, OnlyTheLastLayerMayOmitItsThickness) {
  expect_error(with("thickness = \"20 um\"\n", ""),
               {"test.toml:5:", "tissue.layers[0].thickness", "only the last layer"});
}

TEST(SceneErrors, DepthReachesTheBlockBottom) {
  expect_error(with("\"800 um\"", "\"1150 um\""),
               {"test.toml:25:", "insertion.depth", "bottom of the block"});
}

TEST(SceneErrors, DepthReachesTheNeedleLength) {
  expect_error(with("\"800 um\"", "\"1000 um\""),
               {"test.toml:25:", "insertion.depth", "needle 'sharp_bevel'",
                "needles[0].geometry.length", "base would enter"});
}

TEST(SceneErrors, ObliqueAngle) {
  expect_error(with("\"90 deg\"", "\"45 deg\""),
               {"test.toml:27:", "insertion.angle", "oblique insertion is not modelled yet"});
}

TEST(SceneErrors, NoNeedles) {
  expect_error(with("[[needles]]\ngeometry = { plugin = \"sharp_bevel\", diameter = \"230 um\", "
                    "length = \"1000 um\", bevel_angle = \"30 deg\" }\nat = [\"0 um\", \"0 um\"]\n"
                    "material = \"silicon\"\n",
                    ""),
               {"test.toml:1:", "needles", "at least one"});
}

TEST(SceneErrors, DuplicateNeedleNames) {
  const std::string needle =
      "[[needles]]\nname = \"a\"\ngeometry = { plugin = \"cone\" }\nat = [\"%X\", \"0 um\"]\n";
  std::string toml = with("material = \"silicon\"\n", "material = \"silicon\"\nname = \"a\"\n");
  toml += with("%X", "1 mm", needle);
  expect_error(toml, {"test.toml:33:", "needles[1].name", "duplicate needle name 'a'"});
}

TEST(SceneErrors, TomlSyntaxErrorGivesLineAndColumn) {
  try {
    mneedle::load_scene(kAssets / "syntax_error.toml");
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("syntax_error.toml:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("TOML syntax error"), std::string::npos) << msg;
  }
  expect_error(with("depth = \"800 um\"", "depth = \"800 um"), {"test.toml:25:", "TOML syntax"});
}

TEST(SceneErrors, MissingSceneFile) {
  EXPECT_THROW(mneedle::load_scene(kAssets / "no_such_scene.toml"), InputError);
}

TEST(SceneErrors, GeometryNeedsPluginOrStlButNotBoth) {
  expect_error(with("plugin = \"sharp_bevel\",", "plugin = \"sharp_bevel\", stl = \"x.stl\","),
               {"test.toml:20:", "needles[0].geometry.stl", "not both"});
  expect_error(with("plugin = \"sharp_bevel\",", ""),
               {"test.toml:20:", "needles[0].geometry.plugin", "missing"});
}

TEST(SceneErrors, MissingStlFile) {
  expect_error(with("plugin = \"sharp_bevel\", diameter = \"230 um\", length = \"1000 um\", "
                    "bevel_angle = \"30 deg\"",
                    "stl = \"absent.stl\", unit = \"um\""),
               {"test.toml:20:", "needles[0].geometry.stl", "no such file"});
}

TEST(SceneErrors, StlWithoutUnitThatDoesNotDeclareOneIsRefused) {
  // A 180 um needle exported in um and read as mm ran as a 180 mm needle: no more guessing.
  const auto dir =
      std::filesystem::temp_directory_path() / ("mneedle_unit_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kAssets.parent_path() / "meshes" / "pyramid_ascii.stl", dir / "n.stl",
                             std::filesystem::copy_options::overwrite_existing);
  const std::string toml =
      "[tissue]\nsize = [\"2 mm\", \"2 mm\", \"1 mm\"]\n"
      "[[tissue.layers]]\nname = \"gel\"\n"
      "material = { model = \"linear\", E = \"7 kPa\", nu = 0.45 }\n"
      "[[needles]]\ngeometry = { stl = \"n.stl\" }\n"
      "[insertion]\ndepth = \"0.5 mm\"\n";
  try {
    mneedle::parse_scene(toml, (dir / "s.toml").string());
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("needles[0].geometry.unit"), std::string::npos) << msg;
    EXPECT_NE(msg.find("n.stl does not say its length unit"), std::string::npos) << msg;
  }
  // An empty file is named as such, not as a missing unit.
  std::ofstream(dir / "n.stl", std::ios::trunc).close();
  try {
    mneedle::parse_scene(toml, (dir / "s.toml").string());
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("needles[0].geometry.stl"), std::string::npos) << msg;
    EXPECT_NE(msg.find("n.stl: empty file"), std::string::npos) << msg;
  }
  std::filesystem::remove_all(dir);
}

TEST(SceneErrors, UnknownStlUnit) {
  const std::string toml =
      with("stl = \"tiny_needle.stl\" }", "stl = \"tiny_needle.stl\", unit = \"in\" }", [] {
        std::ifstream in(kAssets / "stl_needle.toml");
        return std::string(std::istreambuf_iterator<char>(in), {});
      }());
  try {
    mneedle::parse_scene(toml, (kAssets / "stl_needle.toml").string());
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("stl_needle.toml:15:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("needles[1].geometry.unit"), std::string::npos) << msg;
  }
}

TEST(SceneErrors, PluginLengthMustBeALength) {
  expect_error(with("length = \"1000 um\"", "length = \"1000 deg\""),
               {"test.toml:20:", "needles[0].geometry.length", "expected a length"});
}

TEST(SceneErrors, NeedleOutsideTheBlock) {
  expect_error(with("at = [\"0 um\", \"0 um\"]", "at = [\"1450 um\", \"0 um\"]"),
               {"test.toml:21:", "needles[0].at", "not inside the block"});
}

TEST(SceneErrors, MooneyRivlinConstantsAreChecked) {
  const std::string_view linear = R"(model = "linear", E = "0.08 MPa", nu = 0.4)";
  expect_error(with(linear, R"(model = "mooney_rivlin", C10 = "1 kPa", C01 = "1 kPa")"),
               {"test.toml:13:", "tissue.layers[1].material", "exactly one of nu"});
  expect_error(with(linear, R"(model = "mooney_rivlin", E = "1 kPa", C10 = "1 kPa", C01 = "0")"),
               {"tissue.layers[1].material.E", "derived from C10 and C01"});
  expect_error(with(linear, R"(model = "linear", E = "0.08 MPa", nu = 0.4, C10 = "1 kPa")"),
               {"tissue.layers[1].material.C10", "mooney_rivlin"});
  expect_error(with(linear, R"(model = "mooney_rivlin", C10 = "0", C01 = "0", nu = 0.4)"),
               {"tissue.layers[1].material.C10", "C10 + C01 must be positive"});
  // Each term, as the material model requires (scene check once passed this one, simulate not).
  expect_error(
      with(linear, R"(model = "mooney_rivlin", C10 = "-30 kPa", C01 = "30.000001 kPa", nu = 0.45)"),
      {"tissue.layers[1].material.C10", "must not be negative"});
  expect_error(with(linear, R"(model = "mooney_rivlin", C10 = "30 kPa", C01 = "-1 Pa", nu = 0.45)"),
               {"tissue.layers[1].material.C01", "must not be negative"});
  // A bulk modulus that makes nu 0.5 or -1 is named as K (it was "[loads] layer 1: Poisson ratio").
  for (const char* k : {"1e300 Pa", "1e-300 Pa"})
    expect_error(
        with(linear,
             std::string(R"(model = "mooney_rivlin", C10 = "30 kPa", C01 = "3 kPa", K = ")") + k +
                 "\""),
        {"tissue.layers[1].material.K", "gives Poisson's ratio"});
}

// E far outside any tissue failed late (1e300 Pa: "puncture: step 0 is not finite"; 5e-324 Pa: a
// singular stiffness), naming no key.
TEST(SceneErrors, AModulusOutsideTheTissuesRangeIsNamed) {
  const std::string_view linear = R"(model = "linear", E = "0.08 MPa", nu = 0.4)";
  for (const char* e : {"1e300 Pa", "5e-324 Pa", "0.5 Pa", "2e12 Pa"})
    expect_error(with(linear, std::string(R"(model = "linear", nu = 0.4, E = ")") + e + "\""),
                 {"tissue.layers[1].material.E", "outside the tissues' range, 1 Pa to 1e12 Pa"});
  parse(with(linear, R"(model = "linear", E = "1 Pa", nu = 0.4)"));
  parse(with(linear, R"(model = "linear", E = "1e12 Pa", nu = 0.4)"));
}

TEST(SceneErrors, UnknownMaterialModel) {
  expect_error(with("model = \"linear\", E = \"1 GPa\"", "model = \"ogden\", E = \"1 GPa\""),
               {"test.toml:8:", "tissue.layers[0].material.model", "'ogden'", "mooney_rivlin"});
}

TEST(SceneErrors, StrengthNeedsItsLength) {
  expect_error(with("thickness = \"20 um\"", "thickness = \"20 um\"\nstrength = \"20 MPa\""),
               {"test.toml:8:", "tissue.layers[0].strength", "strength_length"});
}

// A 1 m averaging length in a 3 mm block averaged the whole block: "no puncture", no word.
TEST(SceneErrors, AStrengthLengthAsLargeAsTheBlockIsRefused) {
  expect_error(with("thickness = \"20 um\"",
                    "thickness = \"20 um\"\nstrength = \"20 MPa\"\nstrength_length = \"1 m\""),
               {"test.toml:5:", "tissue.layers[0].strength_length",
                "must be below half the block's smallest side"});  // the layer's line
}

TEST(SceneErrors, ExplicitCriterionNeedsItsData) {
  expect_error(with("fidelity = \"standard\"", "criterion = \"stress\""),
               {"test.toml:30:", "model.criterion", "strength"});
  const std::string no_fracture = with(
      "[tissue.fracture]\ntoughness = \"0.019 N/mm\"\ncritical_pressure = \"0.663 MPa\"\n", "");
  expect_error(with("fidelity = \"standard\"", "criterion = \"energy\"", no_fracture),
               {"model.criterion", "fracture"});
}

TEST(SceneErrors, BadModelChoices) {
  expect_error(with("\"standard\"", "\"ultra\""), {"test.toml:30:", "model.fidelity", "fast"});
  expect_error(with("\"force_curve\"]", "\"stress_map\"]"),
               {"test.toml:31:", "model.outputs[1]", "'stress_map'"});
  expect_error(with("\"force_curve\"]", "\"puncture\"]"), {"model.outputs[1]", "listed twice"});
}

TEST(SceneErrors, LinearGrowthFrictionNeedsBothConstants) {
  expect_error(std::string(kBase) +
                   "\n[loads]\nfriction = \"linear_growth\"\n"
                   "friction_max_force = \"1 N\"\n",
               {"test.toml:33:", "loads.friction_saturation_depth", "missing"});
  expect_error(std::string(kBase) + "\n[loads]\nfriction = \"none\"\nfriction_coefficient = 0.3\n",
               {"test.toml:35:", "loads.friction_coefficient", "coulomb"});
  // 1e300 overflowed the force curve to +Inf, named as an output, not as this key.
  expect_error(std::string(kBase) + "\n[loads]\nfriction_coefficient = 1e300\n",
               {"test.toml:34:", "loads.friction_coefficient", "must be at most 10"});
  expect_error(std::string(kBase) + "\n[loads]\nfriction_max_force = \"1 N\"\n",
               {"loads.friction_max_force", "linear_growth"});
  expect_error(std::string(kBase) + "\n[loads]\nscale = -0.1\n", {"loads.scale", "positive"});
}

TEST(Scene, LayerPressureScaleIsReadWithItsSource) {
  const Scene s = parse(with(R"(thickness = "1130 um")",
                             "thickness = \"1130 um\"\npressure_scale = \"45 kPa\"\n"
                             "pressure_scale_source = \"fitted to my_curve.csv\""));
  ASSERT_TRUE(s.tissue.layers[1].pressure_scale.has_value());
  EXPECT_DOUBLE_EQ(*s.tissue.layers[1].pressure_scale, 45e3);
  EXPECT_EQ(s.tissue.layers[1].pressure_scale_source, "fitted to my_curve.csv");
  EXPECT_FALSE(s.tissue.layers[0].pressure_scale.has_value());
}

TEST(SceneErrors, PressureScaleNeedsItsSource) {
  expect_error(
      with(R"(thickness = "1130 um")", "thickness = \"1130 um\"\npressure_scale = \"45 kPa\""),
      {"tissue.layers[1].pressure_scale_source", "missing"});
}

TEST(SceneErrors, PaperAFig17ModeRefusesALayerPressureScale) {
  expect_error(with(R"(thickness = "1130 um")",
                    "thickness = \"1130 um\"\npressure_scale = \"45 kPa\"\n"
                    "pressure_scale_source = \"x\"") +
                   "\n[loads]\nmode = \"paper_a_fig17\"\nspecimen_diameter = \"44.107 mm\"\n"
                   "specimen_height = \"21.145 mm\"\n",
               {"tissue.layers[1].pressure_scale", "paper_a_fig17"});
}

TEST(SceneErrors, PaperAFig17ModeNeedsThePhantomAndOnlyIt) {
  expect_error(std::string(kBase) + "\n[loads]\nmode = \"paper_a_fig17\"\n",
               {"loads.specimen_diameter", "missing"});
  expect_error(std::string(kBase) +
                   "\n[loads]\nmode = \"paper_a_fig17\"\nspecimen_diameter = \"44.107 mm\"\n"
                   "specimen_height = \"21.145 mm\"\nbeta_length = \"5 um\"\n",
               {"loads.beta_length", "paper_a_fig17 sets it"});
  expect_error(std::string(kBase) + "\n[loads]\nspecimen_height = \"21.145 mm\"\n",
               {"loads.specimen_height", "only to mode"});
}

TEST(SceneErrors, RequirementsAreChecked) {
  expect_error(std::string(kBase) + "\n[requirements]\ntarget_depth = \"900 um\"\n",
               {"test.toml:34:", "requirements.target_depth", "deeper than insertion.depth"});
  expect_error(std::string(kBase) + "\n[requirements]\nsafety_factor = 0.8\n",
               {"requirements.safety_factor", "at least 1"});
}

TEST(SceneErrors, UserMaterialsAreChecked) {
  const std::string material =
      "\n[[materials]]\nname = \"pla\"\nE = \"3.5 GPa\"\nnu = 0.36\nstrength = \"60 MPa\"\n";
  expect_error(std::string(kBase) + material + material,
               {"test.toml:39:", "materials[1].name", "duplicate material name 'pla'"});
  expect_error(std::string(kBase) + with("nu = 0.36", "nu = 0.5", material),
               {"test.toml:36:", "materials[0].nu", "incompressible"});
  expect_error(std::string(kBase) + with("strength = \"60 MPa\"\n", "", material),
               {"materials[0].strength", "missing"});
}

TEST(SceneErrors, WrongValueTypes) {
  expect_error(with("name = \"dermis\"", "name = 3"),
               {"test.toml:11:", "tissue.layers[1].name", "string"});
  expect_error(with("depth = \"800 um\"", "depth = true"),
               {"test.toml:25:", "insertion.depth", "expected a length"});
  expect_error(with("E = \"0.08 MPa\"", "E = nan"),
               {"test.toml:13:", "tissue.layers[1].material.E", "not a finite number"});
  expect_error(with("[tissue.fracture]", "[tissue.fracture.x]"), {"tissue.fracture", "missing"});
}

}  // namespace
