// libFuzzer harness: the scene parser (docs/scene.md). A clean InputError is the only acceptable
// failure; any other exception, a crash or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "mneedle/base/error.h"
#include "mneedle/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)mneedle::parse_scene(text, "fuzz.toml");
  } catch (const mneedle::InputError&) {
  }
  return 0;
}
