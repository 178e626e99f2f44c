// The descriptor checks on structs built in memory: no library is loaded, so every field the host
// reads can be set to what a careless or hostile plugin might declare.
#include "plugin_descriptor.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "mneedle/base/error.h"

namespace {

mneedle_status generate_nothing(const double*, size_t, mneedle_mesh_sink*, char*, size_t) {
  return MNEEDLE_STATUS_INTERNAL_ERROR;
}

struct Descriptor {
  mneedle_parameter parameters[2] = {{"diameter", "m", 1e-4, 1e-5, 1e-3, "outer diameter"},
                                     {"angle", "rad", 0.5, 0.1, 1.0, "bevel angle"}};
  mneedle_shape shapes[2] = {
      {"bevel", "a bevel", parameters, 2, 1, generate_nothing, nullptr, nullptr},
      {"cone", "a cone", parameters, 1, 0, generate_nothing, nullptr, nullptr}};
  mneedle_plugin plugin = {MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR, "org.test", shapes,
                           2};
};

std::string error_of(const Descriptor& d) {
  try {
    mneedle::read_plugin_shapes(mneedle::check_plugin_descriptor(&d.plugin, "p.so"), "p.so");
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PluginDescriptor, WellFormedDescriptorGivesEveryShapeAndParameter) {
  Descriptor d;
  const auto infos =
      mneedle::read_plugin_shapes(mneedle::check_plugin_descriptor(&d.plugin, "p.so"), "p.so");
  ASSERT_EQ(infos.size(), 2u);
  EXPECT_EQ(infos[0].name, "bevel");
  EXPECT_EQ(infos[0].plugin_id, "org.test");
  EXPECT_TRUE(infos[0].thread_safe);
  ASSERT_EQ(infos[0].parameters.size(), 2u);
  EXPECT_EQ(infos[0].parameters[1].unit, "rad");
  EXPECT_DOUBLE_EQ(infos[0].parameters[0].max, 1e-3);
  EXPECT_EQ(infos[1].parameters.size(), 1u);
  EXPECT_FALSE(infos[1].thread_safe);
}

TEST(PluginDescriptor, NullDescriptorOrAnotherAbiIsRefusedNamingTheFile) {
  EXPECT_THROW(mneedle::check_plugin_descriptor(nullptr, "p.so"), mneedle::InputError);
  Descriptor d;
  d.plugin.abi_major = MNEEDLE_PLUGIN_ABI_MAJOR + 1;
  EXPECT_NE(error_of(d).find("p.so: plugin ABI version"), std::string::npos) << error_of(d);
}

TEST(PluginDescriptor, MissingIdOrShapesAreRefused) {
  Descriptor d;
  d.plugin.plugin_id = "";
  EXPECT_NE(error_of(d).find("without a plugin_id"), std::string::npos);
  Descriptor e;
  e.plugin.shapes = nullptr;
  EXPECT_NE(error_of(e).find("shape_count > 0 but no shapes"), std::string::npos);
}

TEST(PluginDescriptor, ShapeNamesOutsideTheAlphabetOrTwiceAreRefused) {
  for (const char* name : {"", "Bevel", "a-b", "a b"}) {
    Descriptor d;
    d.shapes[0].name = name;
    EXPECT_NE(error_of(d).find("not made of a-z, 0-9 and _"), std::string::npos) << name;
  }
  Descriptor d;
  d.shapes[0].name = nullptr;
  EXPECT_NE(error_of(d).find("is empty"), std::string::npos);
  Descriptor twice;
  twice.shapes[1].name = "bevel";
  EXPECT_NE(error_of(twice).find("shape 'bevel' listed twice"), std::string::npos);
}

TEST(PluginDescriptor, ShapeWithoutGenerateOrParametersIsRefused) {
  Descriptor d;
  d.shapes[1].generate = nullptr;
  EXPECT_NE(error_of(d).find("shape 'cone': no generate function"), std::string::npos);
  Descriptor e;
  e.shapes[1].parameters = nullptr;
  EXPECT_NE(error_of(e).find("parameter_count > 0 but no parameters"), std::string::npos);
}

TEST(PluginDescriptor, ParameterWithoutAUnitNameOrOrderedFiniteBoundsIsRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Bad {
    const char* name;
    const char* unit;
    double def, lo, hi;
    const char* expected;
  };
  for (const Bad& b :
       {Bad{"x", "mm", 1, 0, 2, "unit 'mm' is not one of m, rad, 1"},
        Bad{"x", nullptr, 1, 0, 2, "unit '' is not one of"},
        Bad{nullptr, "m", 1, 0, 2, "parameter without a name"},
        Bad{"x", "m", nan, 0, 2, "must be finite"}, Bad{"x", "m", 1, -inf, 2, "must be finite"},
        Bad{"x", "m", 1, 2, 0, "min <= default <= max"},
        Bad{"x", "m", 3, 0, 2, "min <= default <= max"}}) {
    Descriptor d;
    d.parameters[1] = {b.name, b.unit, b.def, b.lo, b.hi, nullptr};
    EXPECT_NE(error_of(d).find(b.expected), std::string::npos) << error_of(d);
  }
  Descriptor twice;
  twice.parameters[1].name = "diameter";
  EXPECT_NE(error_of(twice).find("parameter 'diameter' listed twice"), std::string::npos);
}

}  // namespace
