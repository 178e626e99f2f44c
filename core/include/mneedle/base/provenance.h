#pragma once
// What produced an output (docs/cli.md, "Provenance"): the tool's version and source revision,
// the command line, a SHA-256 of every input (scene, needle meshes, curves), the seed and the
// time. The time honours SOURCE_DATE_EPOCH, so two runs of the same inputs can be compared byte
// for byte.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mneedle {

/// One input of a run: its role ("scene", "needle", "curve", …), its name as the user gave it
/// and the SHA-256 of its bytes (lower-case hex; `sha256sum FILE` prints the same).
struct InputDigest {
  std::string role;
  std::string name;
  std::string sha256;
};

struct Provenance {
  std::string version;          ///< mneedle's version (the CMake project version)
  std::string source_revision;  ///< `git describe` of the build's sources, "unknown" outside git
  std::string command;          ///< the command line, words joined by spaces
  std::string time_utc;         ///< ISO 8601 UTC to the second (SOURCE_DATE_EPOCH when set)
  std::optional<std::uint64_t> seed;
  std::vector<InputDigest> inputs;
};

std::string tool_version();
std::string source_revision();

/// SHA-256 of `bytes` as 64 lower-case hex digits.
std::string sha256_hex(std::string_view bytes);

/// SHA-256 of a file's bytes; throws InputError "<file>: cannot read" when it cannot be read.
std::string sha256_of_file(const std::filesystem::path& file);

/// The time outputs carry: SOURCE_DATE_EPOCH (whole seconds since 1970, UTC) when it is set,
/// otherwise now; as "YYYY-MM-DDThh:mm:ssZ". Throws InputError naming SOURCE_DATE_EPOCH when it
/// is set but not a whole, non-negative number of seconds.
std::string output_time_utc();

/// version, source revision and time filled in; `command` as given; no inputs yet.
Provenance start_provenance(std::string command);

}  // namespace mneedle
