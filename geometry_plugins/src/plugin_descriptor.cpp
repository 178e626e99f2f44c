#include "plugin_descriptor.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {

namespace fs = std::filesystem;

namespace {

bool valid_shape_name(const char* name) {
  if (name == nullptr || *name == '\0') return false;
  return std::all_of(name, name + std::char_traits<char>::length(name), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

std::string text_or_empty(const char* text) {
  return text == nullptr ? std::string{} : text;
}

PluginParameter read_parameter(const mneedle_parameter& p, const std::string& where) {
  if (p.name == nullptr || *p.name == '\0') throw InputError(where + ": parameter without a name");
  const std::string here = where + ": parameter '" + p.name + "'";
  const std::string unit = text_or_empty(p.unit);
  if (unit != "m" && unit != "rad" && unit != "1") {
    throw InputError(here + ": unit '" + unit + "' is not one of m, rad, 1");
  }
  if (!std::isfinite(p.min_value) || !std::isfinite(p.max_value) ||
      !std::isfinite(p.default_value) || p.min_value > p.max_value ||
      p.default_value < p.min_value || p.default_value > p.max_value) {
    throw InputError(here + ": default, min and max must be finite with min <= default <= max");
  }
  return {p.name, unit, text_or_empty(p.help), p.default_value, p.min_value, p.max_value};
}

PluginShapeInfo read_shape(const mneedle_shape& s, const mneedle_plugin& plugin,
                           const fs::path& library) {
  const std::string file = library.string();
  if (!valid_shape_name(s.name)) {
    throw InputError(file + ": shape name '" + text_or_empty(s.name) +
                     "' is empty or not made of a-z, 0-9 and _");
  }
  const std::string where = file + ": shape '" + s.name + "'";
  if (s.generate == nullptr) throw InputError(where + ": no generate function");
  if (s.parameter_count > 0 && s.parameters == nullptr) {
    throw InputError(where + ": parameter_count > 0 but no parameters");
  }
  PluginShapeInfo info;
  info.name = s.name;
  info.plugin_id = plugin.plugin_id;
  info.help = text_or_empty(s.help);
  info.library = library;
  info.thread_safe = s.thread_safe != 0;
  info.has_section_area = s.section_area != nullptr;
  info.has_section_properties = s.section_properties != nullptr;
  for (std::size_t i = 0; i < s.parameter_count; ++i) {
    info.parameters.push_back(read_parameter(s.parameters[i], where));
    for (std::size_t j = 0; j + 1 < info.parameters.size(); ++j) {
      if (info.parameters[j].name == info.parameters.back().name) {
        throw InputError(where + ": parameter '" + info.parameters[j].name + "' listed twice");
      }
    }
  }
  return info;
}

}  // namespace

const mneedle_plugin& check_plugin_descriptor(const mneedle_plugin* plugin,
                                              const fs::path& library) {
  if (plugin == nullptr) throw InputError(library.string() + ": plugin entry returned null");
  if (plugin->abi_major != MNEEDLE_PLUGIN_ABI_MAJOR) {
    throw InputError(library.string() + ": plugin ABI version " +
                     std::to_string(plugin->abi_major) + "." + std::to_string(plugin->abi_minor) +
                     " is incompatible with this mneedle (ABI major " +
                     std::to_string(MNEEDLE_PLUGIN_ABI_MAJOR) + ")");
  }
  if (plugin->plugin_id == nullptr || *plugin->plugin_id == '\0') {
    throw InputError(library.string() + ": plugin without a plugin_id");
  }
  if (plugin->shape_count > 0 && plugin->shapes == nullptr) {
    throw InputError(library.string() + ": shape_count > 0 but no shapes");
  }
  return *plugin;
}

std::vector<PluginShapeInfo> read_plugin_shapes(const mneedle_plugin& plugin,
                                                const fs::path& library) {
  std::vector<PluginShapeInfo> infos;
  for (std::size_t i = 0; i < plugin.shape_count; ++i) {
    infos.push_back(read_shape(plugin.shapes[i], plugin, library));
    for (std::size_t j = 0; j + 1 < infos.size(); ++j) {
      if (infos[j].name == infos.back().name) {
        throw InputError(library.string() + ": shape '" + infos[j].name + "' listed twice");
      }
    }
  }
  return infos;
}

}  // namespace mneedle
