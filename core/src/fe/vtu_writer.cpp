#include "fe/vtu_writer.h"

#include <array>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

std::string comment_text(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '-' && !out.empty() && out.back() == '-')
      out += "\\u002d";
    else
      out += c;
  }
  if (!out.empty() && out.back() == '-') out += ' ';  // "--->" would end the comment badly
  return out;
}

// The shortest text that reads back as the same double.
std::string shortest(double v) {
  std::array<char, 32> text{};
  const auto end = std::to_chars(text.data(), text.data() + text.size(), v).ptr;
  return std::string(text.data(), end);
}

// The appended block: each array as a UInt64 byte count followed by its raw bytes.
class Appended {
 public:
  template <class T>
  std::size_t add(const T* data, std::size_t count) {
    const std::size_t offset = bytes_.size();
    const std::uint64_t size = count * sizeof(T);
    bytes_.append(reinterpret_cast<const char*>(&size), sizeof size);
    bytes_.append(reinterpret_cast<const char*>(data), size);
    return offset;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// NumberOfTuples is required by VTK's reader for field data (without it ParaView reads the array
// as empty); it is written on every array, where it is harmless.
std::string array_tag(const VtuArray& a, std::size_t tuples, std::size_t offset) {
  return std::string("<DataArray type=\"") + (a.int32.empty() ? "Float64" : "Int32") +
         "\" Name=\"" + a.name + "\" NumberOfComponents=\"" + std::to_string(a.components) +
         "\" NumberOfTuples=\"" + std::to_string(tuples) + "\" format=\"appended\" offset=\"" +
         std::to_string(offset) + "\"/>\n";
}

void check_size(const VtuArray& a, std::size_t tuples, const std::string& where) {
  const std::size_t n = a.int32.empty() ? a.float64.size() : a.int32.size();
  if (a.components < 1 || n != tuples * static_cast<std::size_t>(a.components))
    throw SolverError("VTU writer: " + where + " array '" + a.name + "' has " + std::to_string(n) +
                      " values for " + std::to_string(tuples) + " tuples");
}

std::string arrays(const std::vector<VtuArray>& list, Appended* block) {
  std::string xml;
  for (const VtuArray& a : list) {
    const std::size_t values = a.int32.empty() ? a.float64.size() : a.int32.size();
    xml += array_tag(a, values / static_cast<std::size_t>(a.components),
                     a.int32.empty() ? block->add(a.float64.data(), a.float64.size())
                                     : block->add(a.int32.data(), a.int32.size()));
  }
  return xml;
}

}  // namespace

void write_vtu(const std::string& path, const VtuFile& f) {
  const std::size_t points = f.points_m.size(), cells = f.types.size();
  if (f.offsets.size() != cells ||
      (cells > 0 && static_cast<std::size_t>(f.offsets.back()) != f.connectivity.size()))
    throw SolverError("VTU writer: offsets do not match the cells");
  for (const VtuArray& a : f.point_data) check_size(a, points, "point");
  for (const VtuArray& a : f.cell_data) check_size(a, cells, "cell");
  for (const VtuArray& a : f.field_data) check_size(a, 1, "field");

  Appended block;
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n";
  if (!f.comment.empty()) xml += "<!-- " + comment_text(f.comment) + " -->\n";
  xml += "<UnstructuredGrid>\n";
  if (!f.field_data.empty())
    xml += "<FieldData>\n" + arrays(f.field_data, &block) + "</FieldData>\n";
  xml += "<Piece NumberOfPoints=\"" + std::to_string(points) + "\" NumberOfCells=\"" +
         std::to_string(cells) + "\">\n<PointData>\n" + arrays(f.point_data, &block) +
         "</PointData>\n<CellData>\n" + arrays(f.cell_data, &block) + "</CellData>\n<Points>\n";
  std::vector<double> xyz;
  xyz.reserve(3 * points);
  for (const auto& p : f.points_m) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  xml += array_tag({"Points", 3, {}, {}}, points, block.add(xyz.data(), xyz.size())) +
         "</Points>\n<Cells>\n";
  xml += "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"" +
         std::to_string(block.add(f.connectivity.data(), f.connectivity.size())) + "\"/>\n";
  xml += "<DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"" +
         std::to_string(block.add(f.offsets.data(), f.offsets.size())) + "\"/>\n";
  xml += "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"" +
         std::to_string(block.add(f.types.data(), f.types.size())) + "\"/>\n";
  xml += "</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_";

  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path + ": cannot open for writing");
  out << xml;
  out.write(block.bytes().data(), static_cast<std::streamsize>(block.bytes().size()));
  out << "\n</AppendedData>\n</VTKFile>\n";
  if (!out) throw InputError(path + ": write failed");
}

void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries,
               const std::string& comment) {
  const std::string temporary = path + ".part";
  {
    std::ofstream out(temporary);
    if (!out) throw InputError(path + ": cannot open for writing");
    out << "<?xml version=\"1.0\"?>\n";
    if (!comment.empty()) out << "<!-- " << comment_text(comment) << " -->\n";
    out << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
           "<Collection>\n";
    for (const PvdEntry& e : entries)
      out << "<DataSet timestep=\"" << shortest(e.time) << "\" group=\"\" part=\"" << e.part
          << "\" file=\"" << e.file << "\"/>\n";
    out << "</Collection>\n</VTKFile>\n";
    if (!out) {
      out.close();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw InputError(path + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw InputError(path + ": cannot write (" + ec.message() + ")");
  }
}

void clear_step_files(const std::string& directory) {
  static const std::regex step(R"((step|needles)_[0-9]+\.vtu|steps\.pvd)");
  // Every call takes an error code: a folder that changes under us is not worth an exception.
  std::error_code ec;
  std::filesystem::directory_iterator it(directory, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code type_ec;
    if (it->is_regular_file(type_ec) && !type_ec && std::regex_match(name, step)) {
      std::error_code ignored;
      std::filesystem::remove(it->path(), ignored);
    }
  }
}

}  // namespace mneedle::fe
