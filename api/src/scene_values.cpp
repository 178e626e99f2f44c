#include "mneedle/api/scene_values.h"

#include <toml++/toml.h>

#include <cmath>
#include <sstream>

#include "mneedle/base/error.h"
#include "mneedle/scene/scene_edit.h"

namespace mneedle {
namespace {

toml::array to_toml_array(const nlohmann::json& values, const std::string& where);
toml::table to_toml_table(const nlohmann::json& values, const std::string& where);

// One value; `where` is its key path for messages.
template <class Insert>
void add_value(const nlohmann::json& v, const std::string& where, Insert insert) {
  if (v.is_object()) {
    insert(to_toml_table(v, where));
  } else if (v.is_array()) {
    insert(to_toml_array(v, where));
  } else if (v.is_string()) {
    insert(v.get<std::string>());
  } else if (v.is_boolean()) {
    insert(v.get<bool>());
  } else if (v.is_number_unsigned()) {  // before is_number_integer, which is also true here
    if (v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX))
      throw InputError(where + ": integer too large for a scene");
    insert(static_cast<std::int64_t>(v.get<std::uint64_t>()));
  } else if (v.is_number_integer()) {
    insert(v.get<std::int64_t>());
  } else if (v.is_number_float()) {
    if (!std::isfinite(v.get<double>())) throw InputError(where + ": not a finite number");
    insert(v.get<double>());
  } else {
    throw InputError(where + ": no value (null/None) — leave the key out instead");
  }
}

toml::array to_toml_array(const nlohmann::json& values, const std::string& where) {
  toml::array a;
  for (std::size_t i = 0; i < values.size(); ++i)
    add_value(values[i], where + "[" + std::to_string(i) + "]",
              [&](auto&& x) { a.push_back(std::forward<decltype(x)>(x)); });
  return a;
}

toml::table to_toml_table(const nlohmann::json& values, const std::string& where) {
  toml::table t;
  for (auto it = values.begin(); it != values.end(); ++it) {
    const std::string key = where.empty() ? it.key() : where + "." + it.key();
    add_value(it.value(), key,
              [&](auto&& x) { t.insert_or_assign(it.key(), std::forward<decltype(x)>(x)); });
  }
  return t;
}

}  // namespace

nlohmann::json read_scene_values(const std::filesystem::path& scene_file) {
  load_scene(scene_file);  // checked as `scene check` checks it: the same errors, word for word
  return nlohmann::json::parse(scene_values_json(scene_file));
}

std::string scene_values_toml(const nlohmann::json& values, const std::string& source) {
  if (!values.is_object()) throw InputError(source + ": a scene is a table of values (a dict)");
  try {
    std::ostringstream text;
    text << to_toml_table(values, "");
    return text.str();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

Scene scene_from_values(const nlohmann::json& values, const std::string& source) {
  return parse_scene(scene_values_toml(values, source), source);
}

}  // namespace mneedle
