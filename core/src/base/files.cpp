#include "mneedle/base/files.h"

#include <fstream>
#include <iterator>
#include <system_error>

#include "mneedle/base/error.h"

namespace mneedle {

namespace fs = std::filesystem;

std::string read_input_file(const fs::path& file) {
  std::error_code ec;
  if (fs::is_directory(file, ec)) throw InputError(file.string() + ": is a folder, not a file");
  if (!fs::exists(file, ec)) throw InputError(file.string() + ": no such file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open the file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file.string() + ": reading the file failed");
  return text;
}

void create_output_folder(const fs::path& dir, std::string_view option) {
  const std::string where = std::string(option) + " '" + dir.string() + "'";
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(where + ": is a file, not a folder");
  fs::create_directories(dir, ec);
  if (ec) throw InputError(where + ": cannot create the folder (" + ec.message() + ")");
}

void write_output_file(const fs::path& file, std::string_view text, std::string_view option) {
  std::ofstream out(file, std::ios::binary);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw InputError(std::string(option) + ": cannot write '" + file.string() + "'");
}

}  // namespace mneedle
