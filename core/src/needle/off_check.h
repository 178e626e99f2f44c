#pragma once
// An OFF file's header counts checked before assimp reads it: Debian's assimp 5.2 allocates and
// zero-fills every vertex its header declares before it reads a line, so a 40-byte file that
// declares two billion vertices took 50 s and 48 GB of address space (found by fuzz_mesh). mneedle
// refuses such files itself (docs/cli.md, "mneedle inspect").

#include <filesystem>
#include <string>

namespace mneedle::off {

/// Throws InputError "<file>: ..." unless `bytes` is an OFF file whose header (an optional
/// `[ST][C][N][4][n]OFF` keyword, then the vertex, face and edge counts) is complete and whose
/// data has at least one line for every vertex and face it declares.
void check_structure(const std::filesystem::path& file, const std::string& bytes);

}  // namespace mneedle::off
