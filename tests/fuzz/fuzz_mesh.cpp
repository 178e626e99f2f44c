// libFuzzer harness: the mesh loader (STL, OBJ, PLY, OFF through assimp, with the checks mneedle
// runs before assimp sees a file; docs/cli.md, "mneedle inspect") and the mesh validation after it.
// The format is chosen from the content, as a user's file would be named, so the repository's
// test meshes seed every format. A clean InputError is the only acceptable failure.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "mneedle/base/error.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/needle/mesh_validation.h"

namespace {

std::string extension_for(std::string_view text) {
  if (text.substr(0, 3) == "ply") return ".ply";
  if (text.substr(0, 3) == "OFF") return ".off";
  if (text.substr(0, 5) == "solid" || text.size() >= 84) return ".stl";
  return ".obj";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // A relative name in the working folder run_fuzzer.cmake gives each harness: the error messages
  // hold the path, and libFuzzer learns from the bytes the harness compares, so a path that held
  // the process id or the machine's folders made runs with the same seed take different inputs.
  const std::filesystem::path file = "fuzz_input" + std::string(extension_for(text));
  std::ofstream(file, std::ios::binary).write(text.data(), static_cast<std::streamsize>(size));
  try {
    const mneedle::TriangleMesh mesh = mneedle::load_mesh(file, 1e-3);
    (void)mneedle::validate_mesh(mesh);
  } catch (const mneedle::InputError&) {
  }
  std::filesystem::remove(file);
  return 0;
}
