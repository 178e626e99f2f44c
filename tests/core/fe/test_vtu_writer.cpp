#include "fe/vtu_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "fe/vtu_reader.h"
#include "mneedle/base/error.h"

namespace {

namespace fs = std::filesystem;
using mneedle::fe::PvdEntry;
using mneedle::fe::VtuFile;

fs::path work_dir() {
  const fs::path dir = fs::temp_directory_path() / ("mneedle_vtu_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

VtuFile one_tetrahedron() {
  VtuFile f;
  f.points_m = {{0, 0, 0}, {1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}};
  f.connectivity = {0, 1, 2, 3};
  f.offsets = {4};
  f.types = {10};
  f.point_data = {{"displacement_m", 3, {0, 0, 0, 1, 2, 3, 0, 0, 0, -1e-9, 0, 0}, {}}};
  f.cell_data = {{"von_mises_Pa", 1, {1234.5}, {}}, {"layer", 1, {}, {7}}};
  f.field_data = {{"depth_m", 1, {2.5e-5}, {}}};
  f.comment = "provenance: {\"command\": \"mneedle simulate --vtu out\"}";
  return f;
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(VtuWriter, EveryArrayReadsBackBitForBit) {
  const fs::path file = work_dir() / "one.vtu";
  mneedle::fe::write_vtu(file.string(), one_tetrahedron());
  const auto r = mneedle::test::read_vtu(file.string());
  EXPECT_EQ(r.points, 4u);
  EXPECT_EQ(r.cells, 1u);
  EXPECT_EQ(r.arrays.at("Points").values[3], 1e-3);
  EXPECT_EQ(r.arrays.at("connectivity").values, (std::vector<double>{0, 1, 2, 3}));
  EXPECT_EQ(r.arrays.at("offsets").values, (std::vector<double>{4}));
  EXPECT_EQ(r.arrays.at("types").values, (std::vector<double>{10}));
  EXPECT_EQ(r.arrays.at("displacement_m").components, 3);
  EXPECT_EQ(r.arrays.at("displacement_m").values[9], -1e-9);
  EXPECT_EQ(r.arrays.at("von_mises_Pa").values, (std::vector<double>{1234.5}));
  EXPECT_EQ(r.arrays.at("layer").type, "Int32");
  EXPECT_EQ(r.arrays.at("layer").values, (std::vector<double>{7}));
  EXPECT_EQ(r.arrays.at("depth_m").values, (std::vector<double>{2.5e-5}));
  // VTK's reader takes a field array without NumberOfTuples as empty (ParaView shows nothing)
  EXPECT_NE(r.header.find("Name=\"depth_m\" NumberOfComponents=\"1\" NumberOfTuples=\"1\""),
            std::string::npos)
      << r.header;
  EXPECT_NE(r.header.find("Name=\"displacement_m\" NumberOfComponents=\"3\" NumberOfTuples=\"4\""),
            std::string::npos);
  fs::remove_all(file.parent_path());
}

TEST(VtuWriter, CommentNeverHoldsTheSequenceThatEndsIt) {
  const fs::path file = work_dir() / "comment.vtu";
  mneedle::fe::write_vtu(file.string(), one_tetrahedron());
  const std::string header = mneedle::test::read_vtu(file.string()).header;
  const std::size_t open = header.find("<!-- "), close = header.find(" -->");
  ASSERT_NE(open, std::string::npos);
  const std::string body = header.substr(open + 5, close - open - 5);
  EXPECT_EQ(body.find("--"), std::string::npos) << body;
  // "-\u002d" is "--" to a JSON reader
  EXPECT_NE(body.find("mneedle simulate -\\u002dvtu out"), std::string::npos) << body;
  fs::remove_all(file.parent_path());
}

TEST(VtuWriter, ArrayOfTheWrongSizeIsABugNotAFile) {
  VtuFile f = one_tetrahedron();
  f.point_data[0].float64.pop_back();
  const fs::path file = work_dir() / "bad.vtu";
  EXPECT_THROW(mneedle::fe::write_vtu(file.string(), f), mneedle::SolverError);
  EXPECT_FALSE(fs::exists(file));
  fs::remove_all(file.parent_path());
}

TEST(VtuWriter, UnwritablePathIsAnErrorNamingIt) {
  try {
    mneedle::fe::write_vtu("/no/such/dir/x.vtu", one_tetrahedron());
    FAIL();
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/dir/x.vtu"), std::string::npos);
  }
}

TEST(PvdWriter, ListsEveryStepWithItsDepthAndPart) {
  const fs::path dir = work_dir();
  mneedle::fe::write_pvd((dir / "steps.pvd").string(),
                         {{1e-5, 0, "step_1.vtu"}, {1e-5, 1, "needles_1.vtu"}}, "made by a test");
  const std::string text = text_of(dir / "steps.pvd");
  EXPECT_NE(text.find("<DataSet timestep=\"1e-05\" group=\"\" part=\"1\" "
                      "file=\"needles_1.vtu\"/>"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("<!-- made by a test -->"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "steps.pvd.part"));
  fs::remove_all(dir);
}

TEST(StepFiles, OnlyAnEarlierRunsStepFilesAreRemoved) {
  const fs::path dir = work_dir();
  for (const char* name : {"step_1.vtu", "step_12.vtu", "needles_3.vtu", "steps.pvd", "mine.vtu",
                           "step_x.vtu", "notes.txt"})
    std::ofstream(dir / name) << "x";
  mneedle::fe::clear_step_files(dir.string());
  for (const char* gone : {"step_1.vtu", "step_12.vtu", "needles_3.vtu", "steps.pvd"})
    EXPECT_FALSE(fs::exists(dir / gone)) << gone;
  for (const char* kept : {"mine.vtu", "step_x.vtu", "notes.txt"})
    EXPECT_TRUE(fs::exists(dir / kept)) << kept;
  fs::remove_all(dir);
}

}  // namespace
