#pragma once
// A scene given as values (a Python dict, a JSON object) rather than a file: the same keys and
// strings with units as the TOML file (docs/scene.md), checked by the same parser, so a scene
// read, changed and run from Python meets exactly the checks of the file (docs/python.md).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "mneedle/scene/scene.h"

namespace mneedle {

/// The file's values (scene_values_json), STL paths absolute; the file is checked first as
/// load_scene checks it (the same errors as the CLI's).
nlohmann::json read_scene_values(const std::filesystem::path& scene_file);

/// The values as TOML text: objects become tables, arrays arrays, strings, booleans, integers
/// and floats themselves. InputError "<source>: <key path>: ..." for a null or a non-finite
/// number (TOML has neither).
std::string scene_values_toml(const nlohmann::json& values, const std::string& source);

/// Parsed and validated as load_scene does a file; `source` names it in messages and its folder
/// anchors relative STL paths.
Scene scene_from_values(const nlohmann::json& values, const std::string& source);

}  // namespace mneedle
