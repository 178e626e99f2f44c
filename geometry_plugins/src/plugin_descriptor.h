#pragma once
// The checks on what a plugin declares (docs/plugins.md, "Build, load, check"): its descriptor
// struct and every shape and parameter in it. Plain data in, InputError out; no library is loaded
// here, so the checks can be tested and fuzzed on descriptor structs built in memory.

#include <filesystem>
#include <vector>

#include "mneedle/plugin.h"
#include "mneedle/plugin_host.h"

namespace mneedle {

/// The descriptor a plugin's entry returned: not null, the host's ABI major version, a
/// plugin_id, shapes when shape_count > 0. Throws InputError naming `library`.
const mneedle_plugin& check_plugin_descriptor(const mneedle_plugin* plugin,
                                              const std::filesystem::path& library);

/// Every shape of a checked descriptor: names of a-z, 0-9 and _, a generate function, parameters
/// with a name, a unit of m, rad or 1 and finite min <= default <= max, no name twice. Throws
/// InputError naming `library`, the shape and the parameter.
std::vector<PluginShapeInfo> read_plugin_shapes(const mneedle_plugin& plugin,
                                                const std::filesystem::path& library);

}  // namespace mneedle
