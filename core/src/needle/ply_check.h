#pragma once
// A PLY file's structure checked before assimp reads it: Debian's assimp 5.2 reads past the end
// of a binary PLY whose data is shorter than its header declares (SIGSEGV, found by fuzz_mesh),
// and it cannot be patched here, so mneedle refuses such files itself (docs/cli.md, "mneedle
// inspect").

#include <filesystem>
#include <string>

namespace mneedle::ply {

/// Throws InputError "<file>: ..." unless `bytes` is a PLY whose header ends with `end_header`,
/// declares known property types, and — for binary formats — whose data holds every element the
/// header declares, list counts included. ASCII data is left to assimp's own reader.
void check_structure(const std::filesystem::path& file, const std::string& bytes);

}  // namespace mneedle::ply
