#include "mneedle/plugin_host.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

namespace fs = std::filesystem;

const fs::path kBrokenDir = fs::path(MNEEDLE_TEST_PLUGIN_DIR) / "broken";
const fs::path kBadShapesDir = fs::path(MNEEDLE_TEST_PLUGIN_DIR) / "bad_shapes";

// The thrown InputError's message, or "" if nothing was thrown.
template <class Body>
std::string input_error_of(Body&& body) {
  try {
    body();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Sets MNEEDLE_PLUGIN_PATH for one test and restores the previous value.
class ScopedPluginPath {
 public:
  explicit ScopedPluginPath(const std::string& value) {
    if (const char* old = getenv("MNEEDLE_PLUGIN_PATH")) previous_ = old;
    setenv("MNEEDLE_PLUGIN_PATH", value.c_str(), 1);
  }
  ~ScopedPluginPath() {
    if (previous_) {
      setenv("MNEEDLE_PLUGIN_PATH", previous_->c_str(), 1);
    } else {
      unsetenv("MNEEDLE_PLUGIN_PATH");
    }
  }

 private:
  std::optional<std::string> previous_;
};

PluginRegistry registry_with_bad_shapes() {
  PluginRegistry registry;
  registry.load_library(kBadShapesDir / "bad_shapes.so");
  return registry;
}

TEST(PluginHost, DiscoversTheFourBuiltInShapesWithoutWarnings) {
  const PluginRegistry registry = PluginRegistry::discover();
  std::vector<std::string> names;
  for (const auto& s : registry.shapes()) names.push_back(s.name);
  for (const char* expected : {"sharp_bevel", "blunt_bevel", "cylinder", "cone"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
  EXPECT_TRUE(registry.warnings().empty()) << registry.warnings().front();
}

TEST(PluginHost, BuiltInShapeDescribesItsParametersInSi) {
  const PluginRegistry registry = PluginRegistry::discover();
  const PluginShapeInfo& info = registry.shape("sharp_bevel");
  EXPECT_EQ(info.plugin_id, "mneedle.builtin.sharp_bevel");
  EXPECT_TRUE(info.thread_safe);
  EXPECT_TRUE(info.has_section_area);
  EXPECT_TRUE(info.has_section_properties);
  ASSERT_GE(info.parameters.size(), 5u);
  EXPECT_EQ(info.parameters[0].name, "diameter");
  EXPECT_EQ(info.parameters[0].unit, "m");
  EXPECT_DOUBLE_EQ(info.parameters[0].default_value, 230e-6);
  EXPECT_EQ(info.parameters[4].name, "bevel_angle");
  EXPECT_EQ(info.parameters[4].unit, "rad");
}

TEST(PluginHost, RefusesAWrongAbiMajorVersionNamingTheFile) {
  PluginRegistry registry;
  const std::string message =
      input_error_of([&] { registry.load_library(kBrokenDir / "wrong_abi.so"); });
  EXPECT_TRUE(contains(message, "wrong_abi.so")) << message;
  EXPECT_TRUE(contains(message, "ABI version 2.0")) << message;
  EXPECT_TRUE(registry.shapes().empty());
}

TEST(PluginHost, RefusesALibraryWithoutTheEntrySymbol) {
  PluginRegistry registry;
  const std::string message =
      input_error_of([&] { registry.load_library(kBrokenDir / "missing_symbol.so"); });
  EXPECT_TRUE(contains(message, "missing_symbol.so")) << message;
  EXPECT_TRUE(contains(message, "mneedle_plugin_entry")) << message;
}

TEST(PluginHost, RefusesAFileThatIsNoLibrary) {
  PluginRegistry registry;
  const std::string message = input_error_of([&] {
    registry.load_library(fs::path(MNEEDLE_SOURCE_ROOT) / "tests/plugins/test_plugin_host.cpp");
  });
  EXPECT_TRUE(contains(message, "cannot load plugin")) << message;
}

TEST(PluginHost, DiscoveryReportsBrokenPluginsAsWarningsAndKeepsTheRest) {
  const PluginRegistry registry = PluginRegistry::discover({kBrokenDir});
  ASSERT_EQ(registry.warnings().size(), 2u);
  EXPECT_TRUE(contains(registry.warnings()[0], "missing_symbol.so"));
  EXPECT_TRUE(contains(registry.warnings()[1], "wrong_abi.so"));
  EXPECT_NO_THROW(registry.shape("cylinder"));
}

TEST(PluginHost, UnknownShapeErrorListsKnownShapesAndBrokenPlugins) {
  const PluginRegistry registry = PluginRegistry::discover({kBrokenDir});
  const std::string message = input_error_of([&] { registry.shape("pyramid"); });
  EXPECT_TRUE(contains(message, "unknown tip shape 'pyramid'")) << message;
  EXPECT_TRUE(contains(message, "sharp_bevel")) << message;
  EXPECT_TRUE(contains(message, "wrong_abi.so")) << message;
  // Where it looked, and the two ways to add a folder.
  EXPECT_TRUE(contains(message, "looked in ")) << message;
  EXPECT_TRUE(contains(message, kBrokenDir)) << message;
  EXPECT_TRUE(contains(message, "--plugin-dir DIR or MNEEDLE_PLUGIN_PATH")) << message;
}

TEST(PluginHost, MissingExtraFolderIsAnInputError) {
  EXPECT_THROW(PluginRegistry::discover({"/nonexistent/mneedle/plugins"}), InputError);
}

TEST(PluginHost, SearchesMneedlePluginPath) {
  const ScopedPluginPath path("/nonexistent:" + kBadShapesDir.string());
  const PluginRegistry registry = PluginRegistry::discover();
  EXPECT_EQ(registry.shape("failing").library, kBadShapesDir / "bad_shapes.so");
  EXPECT_NO_THROW(registry.shape("cone"));
}

TEST(PluginHost, IgnoresRelativeEntriesOfMneedlePluginPath) {
  const ScopedPluginPath path(fs::relative(kBadShapesDir).string());
  const PluginRegistry registry = PluginRegistry::discover();
  EXPECT_THROW(registry.shape("failing"), InputError);
  ASSERT_FALSE(registry.warnings().empty());
  EXPECT_TRUE(contains(registry.warnings().back(), "relative"));
}

TEST(PluginHost, SecondLibraryWithAKnownShapeNameIsRefused) {
  PluginRegistry registry = registry_with_bad_shapes();
  const std::string message =
      input_error_of([&] { registry.load_library(kBadShapesDir / "bad_shapes.so"); });
  EXPECT_TRUE(contains(message, "already provided")) << message;
}

TEST(PluginHost, FailingShapeErrorNamesTheFileAndCarriesTheMessage) {
  const PluginRegistry registry = registry_with_bad_shapes();
  const std::string message = input_error_of([&] { registry.generate("failing", {}); });
  EXPECT_TRUE(contains(message, "bad_shapes.so")) << message;
  EXPECT_TRUE(contains(message, "invalid parameter")) << message;
  EXPECT_TRUE(contains(message, "this shape always fails")) << message;
}

TEST(PluginHost, ExceptionCaughtInsideThePluginBecomesAnInputError) {
  const PluginRegistry registry = registry_with_bad_shapes();
  const std::string message = input_error_of([&] { registry.generate("throwing", {}); });
  EXPECT_TRUE(contains(message, "thrown inside the plugin")) << message;
}

TEST(PluginHost, OpenMeshIsRejectedNamingTheFileAndTheDefect) {
  const PluginRegistry registry = registry_with_bad_shapes();
  const std::string message = input_error_of([&] { registry.generate("open_mesh", {}); });
  EXPECT_TRUE(contains(message, "bad_shapes.so")) << message;
  EXPECT_TRUE(contains(message, "not closed")) << message;
}

// The contract's frame (docs/plugins.md): a mesh whose tip is not at z = 0, or hundreds of
// metres long (micrometres written as metres), was used as it came; strength read its sections
// from the wrong heights. A message over two lines is one line.
TEST(PluginHost, AMeshOutsideTheNeedleFrameAndAMessageOverTwoLinesAreOneLineErrors) {
  const PluginRegistry registry = registry_with_bad_shapes();
  const std::string lifted = input_error_of([&] { registry.generate("lifted", {}); });
  EXPECT_TRUE(contains(lifted,
                       "bad_shapes.so: shape 'lifted': the mesh's lowest point is at "
                       "z = 50 um, not 0"))
      << lifted;
  const std::string huge = input_error_of([&] { registry.generate("micrometres", {}); });
  EXPECT_TRUE(contains(huge, "the needle is 600 m long: the plugin contract is metres")) << huge;
  const std::string two = input_error_of([&] { registry.generate("two_lines", {}); });
  EXPECT_TRUE(contains(two, "line one line two")) << two;
  EXPECT_EQ(two.find('\n'), std::string::npos) << two;
}

TEST(PluginHost, OutOfRangeVertexIndexIsRejected) {
  const PluginRegistry registry = registry_with_bad_shapes();
  const std::string message = input_error_of([&] { registry.generate("bad_index", {}); });
  EXPECT_TRUE(contains(message, "uses vertex 99 of 4")) << message;
}

TEST(PluginHost, ShapeThatAllocatesNothingIsRejected) {
  const PluginRegistry registry = registry_with_bad_shapes();
  const std::string message = input_error_of([&] { registry.generate("no_mesh", {}); });
  EXPECT_TRUE(contains(message, "returned no mesh")) << message;
}

TEST(PluginHost, NegativeSectionAreaIsRejected) {
  const PluginRegistry registry = registry_with_bad_shapes();
  EXPECT_NO_THROW(registry.generate("negative_area", {}));
  EXPECT_THROW(registry.section_area("negative_area", {}, 0.0), InputError);
}

TEST(PluginHost, ShapeWithoutHooksHasNoAnalyticSection) {
  const PluginRegistry registry = registry_with_bad_shapes();
  EXPECT_FALSE(registry.section_area("serial_only", {}, 0.0).has_value());
  EXPECT_FALSE(registry.section_properties("serial_only", {}, 0.0).has_value());
}

TEST(PluginHost, CallsToAShapeThatIsNotThreadSafeAreSerialised) {
  const PluginRegistry registry = registry_with_bad_shapes();
  ASSERT_FALSE(registry.shape("serial_only").thread_safe);
  std::vector<std::future<TriangleMesh>> calls;
  for (int i = 0; i < 8; ++i) {
    calls.push_back(
        std::async(std::launch::async, [&] { return registry.generate("serial_only", {}); }));
  }
  for (auto& call : calls) EXPECT_NO_THROW(call.get());
}

// Two registries of the same library (Python keeps one per plugin folder list) share the
// shape's lock: calls through both at once were let in together.
TEST(PluginHost, TwoRegistriesOfOneLibrarySerialiseAShapeThatIsNotThreadSafe) {
  const PluginRegistry first = registry_with_bad_shapes();
  const PluginRegistry second = registry_with_bad_shapes();
  std::vector<std::future<TriangleMesh>> calls;
  for (int i = 0; i < 8; ++i) {
    const PluginRegistry& registry = i % 2 == 0 ? first : second;
    calls.push_back(std::async(std::launch::async,
                               [&registry] { return registry.generate("serial_only", {}); }));
  }
  for (auto& call : calls) EXPECT_NO_THROW(call.get());
}

TEST(PluginHost, OutOfBoundsParameterNamesTheParameterAndTheBound) {
  const PluginRegistry registry = PluginRegistry::discover();
  const std::string above = input_error_of([&] {
    registry.resolve_parameters("cylinder", {{"diameter", 0.5}});
  });
  EXPECT_TRUE(contains(above, "'diameter'")) << above;
  EXPECT_TRUE(contains(above, "above the maximum 10 mm")) << above;
  const std::string below = input_error_of([&] {
    registry.generate("cylinder", {{"resolution", 3}});
  });
  EXPECT_TRUE(contains(below, "'resolution'")) << below;
  EXPECT_TRUE(contains(below, "below the minimum 8")) << below;
}

TEST(PluginHost, UnknownParameterIsAnInputErrorListingTheParameters) {
  const PluginRegistry registry = PluginRegistry::discover();
  const std::string message = input_error_of([&] {
    registry.generate("cylinder", {{"bevel_angle", 0.5}});
  });
  EXPECT_TRUE(contains(message, "unknown parameter 'bevel_angle'")) << message;
  EXPECT_TRUE(contains(message, "diameter, length, bore, resolution")) << message;
}

TEST(PluginHost, NonFiniteParameterIsAnInputError) {
  const PluginRegistry registry = PluginRegistry::discover();
  EXPECT_THROW(registry.resolve_parameters("cylinder", {{"length", std::nan("")}}), InputError);
}

TEST(PluginHost, MissingParametersTakeTheirDefaults) {
  const PluginRegistry registry = PluginRegistry::discover();
  const std::vector<double> values = registry.resolve_parameters("cylinder", {{"length", 2e-3}});
  ASSERT_EQ(values.size(), 5u);
  EXPECT_DOUBLE_EQ(values[0], 230e-6);
  EXPECT_DOUBLE_EQ(values[1], 2e-3);
  EXPECT_DOUBLE_EQ(values[2], 0.0);
  EXPECT_DOUBLE_EQ(values[3], 64.0);
  EXPECT_DOUBLE_EQ(values[4], 0.0);  // edge_radius: a sharp rim
}

TEST(PluginHost, MovedRegistryKeepsItsLibrariesLoaded) {
  PluginRegistry first = PluginRegistry::discover();
  PluginRegistry second = std::move(first);
  EXPECT_GT(signed_volume(second.generate("cylinder", {})), 0);
}

}  // namespace
}  // namespace mneedle
