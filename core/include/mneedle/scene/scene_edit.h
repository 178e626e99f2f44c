#pragma once
// Writing a scene back with some of its constants replaced (`mneedle calibrate --out`): the
// file's own TOML with the fitted values set, a comment saying where they come from, and STL
// paths made absolute when the new file lives in another folder. Comments of the original file
// are not kept (the TOML library does not carry them).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace mneedle {

struct SceneConstantEdits {
  /// Per layer, from the surface down: q to write as the layer's pressure_scale (Pa).
  std::vector<std::optional<double>> layer_pressure_scale_Pa;
  std::string pressure_scale_source;  ///< written as each edited layer's pressure_scale_source
  std::optional<double> friction_coefficient;
  std::optional<double> critical_pressure_Pa;  ///< into the fracture data the top layer uses
  std::optional<double> toughness_J_per_m2;
  /// A factor on every layer's stiffness constants (E; C10, C01 and K for Mooney-Rivlin).
  std::optional<double> modulus_factor;
  std::vector<std::string> header_comment;  ///< lines, written as '# ' comments first
};

/// The text of `scene_file` with `edits` applied, for writing to `out_file`. Throws InputError
/// naming the file for a scene that does not parse, a layer index beyond its layers, or a
/// criterion constant with no fracture table to hold it.
std::string edited_scene_text(const std::filesystem::path& scene_file,
                              const SceneConstantEdits& edits,
                              const std::filesystem::path& out_file);

/// The scene file's values as JSON text (toml++'s JSON form: tables as objects, quantities as
/// their strings), STL paths made absolute so that the values stand anywhere — what Python's
/// read_scene returns as a dict (docs/python.md). InputError "<file>: <problem>" for a file
/// that is missing or not TOML; the scene's keys are checked when it is run, not here.
std::string scene_values_json(const std::filesystem::path& scene_file);

}  // namespace mneedle
