#include "fe/vtu_writer.h"

#include <fstream>

#include "mneedle/base/error.h"

namespace mneedle::fe {

void write_vtu(const std::string& path, const VtuFields& f) {
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot open for writing");
  out.precision(9);
  const std::size_t cells = f.von_mises_Pa.size();
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n"
      << "<UnstructuredGrid><Piece NumberOfPoints=\"" << f.points_m.size() << "\" NumberOfCells=\""
      << cells << "\">\n<Points>\n"
      << "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& p : f.points_m) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  out << "</DataArray>\n</Points>\n<Cells>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < f.connectivity.size(); ++i)
    out << f.connectivity[i]
        << ((i + 1) % static_cast<std::size_t>(f.nodes_per_cell) == 0 ? '\n' : ' ');
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t e = 1; e <= cells; ++e)
    out << e * static_cast<std::size_t>(f.nodes_per_cell) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t e = 0; e < cells; ++e) out << f.cell_type << '\n';
  out << "</DataArray>\n</Cells>\n<PointData Vectors=\"displacement_m\">\n"
      << "<DataArray type=\"Float64\" Name=\"displacement_m\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (const auto& u : f.displacement_m) out << u.x() << ' ' << u.y() << ' ' << u.z() << '\n';
  out << "</DataArray>\n</PointData>\n<CellData>\n"
      << "<DataArray type=\"Float64\" Name=\"von_mises_Pa\" format=\"ascii\">\n";
  for (double s : f.von_mises_Pa) out << s << '\n';
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"energy_density_J_per_m3\" "
         "format=\"ascii\">\n";
  for (double w : f.energy_density_J_per_m3) out << w << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"layer\" format=\"ascii\">\n";
  for (int layer : f.layer) out << layer << '\n';
  out << "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  if (!out) throw InputError(path + ": write failed");
}

}  // namespace mneedle::fe
