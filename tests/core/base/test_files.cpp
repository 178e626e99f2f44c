#include "mneedle/base/files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "mneedle/base/error.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch() {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_files_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string error_of(auto&& call) {
  try {
    call();
  } catch (const mneedle::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Files, InputFileIsReadWhole) {
  const fs::path file = scratch() / "a.csv";
  std::ofstream(file, std::ios::binary) << std::string("x,y\n1,2\n\0end", 12);
  EXPECT_EQ(mneedle::read_input_file(file), std::string("x,y\n1,2\n\0end", 12));
  fs::remove_all(scratch());
}

TEST(Files, FolderOrMissingFileGivenAsInputIsNamed) {
  const fs::path dir = scratch();
  EXPECT_EQ(error_of([&] { mneedle::read_input_file(dir); }),
            dir.string() + ": is a folder, not a file");
  EXPECT_EQ(error_of([&] { mneedle::read_input_file(dir / "none.csv"); }),
            (dir / "none.csv").string() + ": no such file");
  fs::remove_all(dir);
}

TEST(Files, OutputFolderIsCreatedWithItsParents) {
  const fs::path dir = scratch() / "a" / "b";
  mneedle::create_output_folder(dir, "--out");
  EXPECT_TRUE(fs::is_directory(dir));
  mneedle::create_output_folder(dir, "--out");  // already there: fine
  fs::remove_all(scratch());
}

TEST(Files, FileWhereTheOutputFolderShouldBeIsNamedWithItsOption) {
  const fs::path file = scratch() / "result.toml";
  std::ofstream(file) << "x";
  EXPECT_EQ(error_of([&] { mneedle::create_output_folder(file, "--out"); }),
            "--out '" + file.string() + "': is a file, not a folder");
  EXPECT_NE(error_of([&] {
              mneedle::create_output_folder(file / "sub", "--vtu");
            }).find("--vtu '" + (file / "sub").string() + "': "),
            std::string::npos);
  fs::remove_all(scratch());
}

// A written file holds every byte; a folder in its place, or a full device, is the option's
// one-line error (a stream's failure was not looked at, and rows were lost with exit 0).
TEST(Files, OutputFileIsWrittenWholeOrItsFailureNamed) {
  const fs::path dir = scratch();
  mneedle::write_output_file(dir / "a.json", std::string("{}\n\0z", 5), "--out");
  EXPECT_EQ(mneedle::read_input_file(dir / "a.json"), std::string("{}\n\0z", 5));
  EXPECT_EQ(error_of([&] { mneedle::write_output_file(dir, "x", "--out"); }),
            "--out: cannot write '" + dir.string() + "'");
  if (fs::exists("/dev/full")) {
    EXPECT_EQ(error_of([&] { mneedle::write_output_file("/dev/full", "x", "--csv"); }),
              "--csv: cannot write '/dev/full'");
  }
  fs::remove_all(dir);
}

}  // namespace
