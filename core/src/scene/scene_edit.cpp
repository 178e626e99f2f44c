#include "mneedle/scene/scene_edit.h"

#include <toml++/toml.h>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/units.h"

namespace mneedle {
namespace {

std::string quantity(double value, const char* unit) {
  std::ostringstream s;
  s << std::setprecision(9) << value << ' ' << unit;
  return s.str();
}

// The fracture table whose values the top layer uses: its own, else [tissue.fracture].
toml::table* fracture_table(toml::table& root, toml::table& top_layer) {
  if (auto* own = top_layer["fracture"].as_table()) return own;
  return root["tissue"]["fracture"].as_table();
}

void make_stl_paths_absolute(toml::table& root, const std::filesystem::path& scene_dir) {
  auto* needles = root["needles"].as_array();
  if (!needles) return;
  for (auto& n : *needles) {
    auto* geometry = n.as_table() ? (*n.as_table())["geometry"].as_table() : nullptr;
    if (!geometry) continue;
    if (auto* stl = (*geometry)["stl"].as_string()) {
      const std::filesystem::path p(stl->get());
      if (p.is_relative())
        *stl = std::filesystem::absolute(scene_dir / p).lexically_normal().string();
    }
  }
}

}  // namespace

std::string edited_scene_text(const std::filesystem::path& scene_file,
                              const SceneConstantEdits& edits,
                              const std::filesystem::path& out_file) {
  toml::table root;
  try {
    root = toml::parse_file(scene_file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(scene_file.string() + ": " + std::string(e.description()));
  }
  auto* layers = root["tissue"]["layers"].as_array();
  const std::string where = scene_file.string() + ": ";
  if (!layers || layers->empty()) throw InputError(where + "tissue.layers: missing");
  if (edits.layer_pressure_scale_Pa.size() > layers->size()) {
    throw InputError(where + "more pressure scales than tissue layers");
  }
  for (std::size_t i = 0; i < edits.layer_pressure_scale_Pa.size(); ++i) {
    if (!edits.layer_pressure_scale_Pa[i]) continue;
    auto* layer = (*layers)[i].as_table();
    if (!layer) throw InputError(where + "tissue.layers[" + std::to_string(i) + "]: not a table");
    layer->insert_or_assign("pressure_scale", quantity(*edits.layer_pressure_scale_Pa[i], "Pa"));
    layer->insert_or_assign("pressure_scale_source", edits.pressure_scale_source);
  }
  if (edits.modulus_factor) {
    for (std::size_t i = 0; i < layers->size(); ++i) {
      const std::string at = where + "tissue.layers[" + std::to_string(i) + "].material";
      auto* layer = (*layers)[i].as_table();
      auto* material = layer ? (*layer)["material"].as_table() : nullptr;
      if (!material) throw InputError(at + ": not a table");
      for (const char* key : {"E", "C10", "C01", "K"}) {
        const toml::node* value = material->get(key);
        if (!value) continue;
        double stiffness = 0.0;
        if (const auto* text = value->as_string()) {
          try {
            stiffness = parse_quantity(text->get(), Dimension::Pressure);
          } catch (const InputError& e) {
            throw InputError(at + "." + key + ": " + e.what());
          }
        } else if (const auto number = value->value<double>()) {
          stiffness = *number;  // 0, the one plain number the parser takes for a pressure
        } else {
          throw InputError(at + "." + key + ": not a pressure");
        }
        material->insert_or_assign(key, quantity(*edits.modulus_factor * stiffness, "Pa"));
      }
    }
  }
  if (edits.friction_coefficient) {
    if (!root["loads"].as_table()) root.insert("loads", toml::table{});
    root["loads"].as_table()->insert_or_assign("friction_coefficient", *edits.friction_coefficient);
  }
  if (edits.critical_pressure_Pa || edits.toughness_J_per_m2) {
    toml::table* fracture = fracture_table(root, *(*layers)[0].as_table());
    if (!fracture) {
      throw InputError(where +
                       "no fracture table (tissue.fracture or the top layer's) to write "
                       "the fitted criterion constant into");
    }
    if (edits.critical_pressure_Pa) {
      fracture->insert_or_assign("critical_pressure", quantity(*edits.critical_pressure_Pa, "Pa"));
    }
    if (edits.toughness_J_per_m2) {
      fracture->insert_or_assign("toughness", quantity(*edits.toughness_J_per_m2, "J/m^2"));
    }
  }
  // A bare file name's folder is the current one ("" has no absolute form).
  const auto folder = [](const std::filesystem::path& file) {
    const std::filesystem::path dir = file.parent_path();
    return dir.empty() ? std::filesystem::path(".") : dir;
  };
  const std::filesystem::path scene_dir = folder(scene_file);
  const std::filesystem::path out_dir = folder(out_file);
  if (std::filesystem::absolute(scene_dir).lexically_normal() !=
      std::filesystem::absolute(out_dir).lexically_normal()) {
    make_stl_paths_absolute(root, scene_dir);
  }
  std::ostringstream text;
  for (const std::string& line : edits.header_comment) text << "# " << line << "\n";
  text << root << "\n";
  return text.str();
}

std::string scene_values_json(const std::filesystem::path& scene_file) {
  const std::string text = read_input_file(scene_file);
  toml::table root;
  try {
    root = toml::parse(text, scene_file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(scene_file.string() + ":" + std::to_string(e.source().begin.line) + ": " +
                     std::string(e.description()));
  }
  make_stl_paths_absolute(root, scene_file.parent_path());
  std::ostringstream json;
  json << toml::json_formatter{root};
  return json.str();
}

}  // namespace mneedle
