#include "fe/inp_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"

namespace {

namespace fs = std::filesystem;
using namespace mneedle::fe;

TetMesh small_block(mneedle::MaterialModel model, bool half) {
  TissueBlockSpec spec;
  spec.size_x = spec.size_y = 400e-6;
  spec.layers = {{"top", 50e-6, {model, 1e6, 0.45, 0.0, 0.0}},
                 {"bottom", 150e-6, {mneedle::MaterialModel::Linear, 2e5, 0.45, 0.0, 0.0}}};
  spec.sites = {{0.0, 0.0, 50e-6}};
  spec.order = 2;
  spec.fidelity = Fidelity::Fast;
  spec.insertion_depth = 20e-6;
  spec.half_y = half;
  return generate_tissue_mesh(spec);
}

std::string write(const InpProblem& p) {
  const fs::path file = fs::temp_directory_path() / ("mneedle_inp_" + std::to_string(::getpid()));
  write_inp_deck(file.string(), p);
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  fs::remove(file);
  return s.str();
}

// CalculiX reads 20 characters a field and 132 a line: a longer number is an error there.
TEST(InpWriter, EveryFieldAndLineFitsCalculixLimits) {
  const TetMesh mesh = small_block(mneedle::MaterialModel::Linear, true);
  InpProblem p;
  p.mesh = &mesh;
  p.prescribed_nodes = {mesh.top_faces[0][0]};
  p.prescribed_u = {{-1.2345678901234567e-10, 0.0, -2.0e-5}};
  p.comment_lines = {std::string(300, 'x')};
  const std::string deck = write(p);
  std::istringstream lines(deck);
  for (std::string line; std::getline(lines, line);) {
    ASSERT_LE(line.size(), 132u) << line.substr(0, 40);
    if (line.rfind("**", 0) == 0 || line.rfind("mneedle: ", 0) == 0) continue;  // comments, title
    std::istringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');)
      ASSERT_LE(field.size(), 21u) << line;  // 20 characters and the space after the comma
  }
  for (const char* card :
       {"*ELEMENT, TYPE=C3D10, ELSET=LAYER0", "*ELEMENT, TYPE=C3D10, ELSET=LAYER1",
        "*SOLID SECTION, ELSET=LAYER1, MATERIAL=M1", "NFIXED, 1, 3", "NMIRRORY, 2, 2",
        "*NODE PRINT, NSET=NNEEDLE, TOTALS=YES"})
    EXPECT_NE(deck.find(card), std::string::npos) << card;
  EXPECT_EQ(deck.find("NMIRRORX"), std::string::npos);  // a half model has one plane
  // the prescribed node's three components, to 14 digits
  const std::string node = std::to_string(p.prescribed_nodes[0] + 1);
  EXPECT_NE(deck.find(node + ", 1, 1, -1.2345678901235e-10"), std::string::npos);
  EXPECT_NE(deck.find(node + ", 3, 3, -2.0000000000000e-05"), std::string::npos);
}

TEST(InpWriter, NonlinearLayerIsRefusedByName) {
  const TetMesh mesh = small_block(mneedle::MaterialModel::NeoHookean, false);
  InpProblem p;
  p.mesh = &mesh;
  try {
    write(p);
    FAIL() << "a neo-Hookean layer was written as linear";
  } catch (const mneedle::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "export: layer 'top' is not linear: the .inp deck holds linear elastic layers only");
  }
}

}  // namespace
