#pragma once
// The shipped skin scene (designs/scenes/human_skin.toml) with its puncture criterion replaced,
// written to a file: tests that run the closed-form pre-puncture model on skin use it with
// "pressure", whose closed form takes every tip shape (the scene's own stress criterion takes
// pointed tips only there: docs/model.md, "The stress criterion on the analytic path").

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace mneedle::test {

inline std::filesystem::path write_skin_scene_with_criterion(const std::string& criterion,
                                                             const std::filesystem::path& file) {
  const std::filesystem::path source =
      std::string(MNEEDLE_SOURCE_ROOT) + "/designs/scenes/human_skin.toml";
  std::ifstream in(source);
  std::stringstream text;
  text << in.rdbuf();
  std::string scene = text.str();
  const std::string key = "\ncriterion = \"stress\"";
  const std::size_t at = scene.find(key);
  if (at == std::string::npos)
    throw std::runtime_error("write_skin_scene_with_criterion: no criterion = \"stress\" in " +
                             source.string());
  scene.replace(at, key.size(), "\ncriterion = \"" + criterion + "\"");
  std::ofstream(file) << scene;
  return file;
}

}  // namespace mneedle::test
