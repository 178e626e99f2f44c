#pragma once
// Reading a user's input file and creating a user's output folder, with the one-line errors of
// docs/cli.md ("Exit status"): a folder where a file is expected, or a file where a folder is, is
// the user's mistake (InputError naming the path), never a library exception.

#include <filesystem>
#include <string>
#include <string_view>

namespace mneedle {

/// The whole file as bytes. InputError "<file>: ..." when it is missing, a folder or unreadable.
std::string read_input_file(const std::filesystem::path& file);

/// Creates `dir` and its parents if missing. InputError naming `option` (e.g. "--out") and the
/// path when it is a file or cannot be created.
void create_output_folder(const std::filesystem::path& dir, std::string_view option);

/// Writes `text` to `file` (replacing it) and checks that every byte reached it. InputError
/// "<option>: cannot write '<file>'" otherwise (a full disk, a folder of that name).
void write_output_file(const std::filesystem::path& file, std::string_view text,
                       std::string_view option);

}  // namespace mneedle
