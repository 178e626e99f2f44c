#include "fe/inp_writer.h"

#include <array>
#include <cstdio>
#include <fstream>
#include <set>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

// CalculiX reads at most 20 characters a field and 132 a line: 14 significant digits fit any
// double's field with its sign and exponent ("-5.7499999999999e-05").
std::string number(double v) {
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%.13e", v);
  return text.data();
}

// *NSET/*ELSET data lines: at most 16 entries a line (the Abaqus limit).
void write_set(std::ostream& out, const std::vector<int>& ids) {
  for (std::size_t i = 0; i < ids.size(); ++i)
    out << ids[i] << ((i + 1) % 16 == 0 || i + 1 == ids.size() ? "\n" : ", ");
}

}  // namespace

void write_inp_deck(const std::string& path, const InpProblem& p) {
  const TetMesh& mesh = *p.mesh;
  for (const TissueLayer& layer : mesh.layers)
    if (layer.material.model != MaterialModel::Linear)
      throw InputError("export: layer '" + layer.name +
                       "' is not linear: the .inp deck holds linear elastic layers only");
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot open for writing");
  out << "*HEADING\nmneedle: 3-D tissue model, sticking needle contact as prescribed "
         "displacements (SI: m, N, Pa)\n";
  // comment lines cut to the 132 characters a line may have
  for (const std::string& line : p.comment_lines)
    for (std::size_t at = 0; at < line.size(); at += 128)
      out << "** " << line.substr(at, 128) << "\n";

  out << "*NODE, NSET=NALL\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    out << i + 1 << ", " << number(mesh.nodes[i].x()) << ", " << number(mesh.nodes[i].y()) << ", "
        << number(mesh.nodes[i].z()) << "\n";
  // C3D10's node order (corners, then mid-edges 1-2 2-3 3-1 1-4 2-4 3-4) is VTK's, ours.
  const int npe = mesh.nodes_per_element();
  for (std::size_t layer = 0; layer < mesh.layers.size(); ++layer) {
    out << "*ELEMENT, TYPE=" << (npe == 4 ? "C3D4" : "C3D10") << ", ELSET=LAYER" << layer << "\n";
    for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
      if (mesh.element_layer[e] != static_cast<int>(layer)) continue;
      out << e + 1;
      for (int a = 0; a < npe; ++a)
        out << ", " << mesh.elements[e][static_cast<std::size_t>(a)] + 1;
      out << "\n";
    }
  }
  for (std::size_t layer = 0; layer < mesh.layers.size(); ++layer) {
    const MaterialParameters& m = mesh.layers[layer].material;
    out << "** layer " << layer << ": " << mesh.layers[layer].name << "\n"
        << "*MATERIAL, NAME=M" << layer << "\n*ELASTIC\n"
        << number(m.E) << ", " << number(m.nu) << "\n"
        << "*SOLID SECTION, ELSET=LAYER" << layer << ", MATERIAL=M" << layer << "\n";
  }

  const std::set<int> held(p.prescribed_nodes.begin(), p.prescribed_nodes.end());
  std::vector<int> fixed, mirror_y, mirror_x, prescribed;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    const int node = static_cast<int>(i);
    if (held.count(node)) continue;  // the needle holds every component
    if (mesh.fixed[i]) fixed.push_back(node + 1);
    if (mesh.mirror_y0 && mesh.nodes[i].y() == 0.0) mirror_y.push_back(node + 1);
    if (mesh.mirror_x0 && mesh.nodes[i].x() == 0.0) mirror_x.push_back(node + 1);
  }
  for (int node : p.prescribed_nodes) prescribed.push_back(node + 1);
  for (const auto& [name, ids] :
       {std::pair{"NFIXED", &fixed}, std::pair{"NMIRRORY", &mirror_y},
        std::pair{"NMIRRORX", &mirror_x}, std::pair{"NNEEDLE", &prescribed}}) {
    if (ids->empty()) continue;
    out << "*NSET, NSET=" << name << "\n";
    write_set(out, *ids);
  }
  out << "*BOUNDARY\n";
  if (!fixed.empty()) out << "NFIXED, 1, 3\n";
  if (!mirror_y.empty()) out << "NMIRRORY, 2, 2\n";
  if (!mirror_x.empty()) out << "NMIRRORX, 1, 1\n";
  out << "*STEP\n*STATIC\n*BOUNDARY\n";
  for (std::size_t k = 0; k < p.prescribed_nodes.size(); ++k)
    for (int dof = 1; dof <= 3; ++dof)
      out << p.prescribed_nodes[k] + 1 << ", " << dof << ", " << dof << ", "
          << number(p.prescribed_u[k](dof - 1)) << "\n";
  if (!prescribed.empty()) out << "*NODE PRINT, NSET=NNEEDLE, TOTALS=YES\nRF\n";
  out << "*END STEP\n";
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace mneedle::fe
