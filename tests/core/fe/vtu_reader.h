#pragma once
// Test helper: reads back the binary VTU files mneedle writes (appended raw data, UInt64
// headers) — an independent check of the byte layout; the meshio test reads them too.
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace mneedle::test {

struct VtuArrayRead {
  std::string type;
  int components = 1;
  std::vector<double> values;
};

struct VtuRead {
  std::string header;  ///< the XML before the appended block
  std::map<std::string, VtuArrayRead> arrays;
  std::size_t points = 0, cells = 0;
};

inline std::string attribute(const std::string& tag, const std::string& key) {
  const std::string k = " " + key + "=\"";
  const std::size_t at = tag.find(k);
  if (at == std::string::npos) return "";
  const std::size_t begin = at + k.size();
  return tag.substr(begin, tag.find('"', begin) - begin);
}

inline VtuRead read_vtu(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::stringstream text;
  text << in.rdbuf();
  const std::string all = text.str();
  const std::string marker = "<AppendedData encoding=\"raw\">\n_";
  const std::size_t at = all.find(marker);
  if (at == std::string::npos) throw std::runtime_error(path + ": no raw appended block");
  VtuRead r;
  r.header = all.substr(0, at);
  const std::size_t block = at + marker.size();
  r.points = std::stoul(attribute(r.header, "NumberOfPoints"));
  r.cells = std::stoul(attribute(r.header, "NumberOfCells"));
  for (std::size_t pos = r.header.find("<DataArray"); pos != std::string::npos;
       pos = r.header.find("<DataArray", pos + 1)) {
    const std::string tag = r.header.substr(pos, r.header.find('>', pos) - pos);
    VtuArrayRead a;
    a.type = attribute(tag, "type");
    const std::string components = attribute(tag, "NumberOfComponents");
    a.components = components.empty() ? 1 : std::stoi(components);
    const std::size_t offset = block + std::stoul(attribute(tag, "offset"));
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, all.data() + offset, sizeof bytes);
    const char* data = all.data() + offset + sizeof bytes;
    auto take = [&]<class T>(T) {
      for (std::size_t i = 0; i < bytes / sizeof(T); ++i) {
        T v;
        std::memcpy(&v, data + i * sizeof(T), sizeof(T));
        a.values.push_back(static_cast<double>(v));
      }
    };
    if (a.type == "Float64")
      take(double{});
    else if (a.type == "Int64")
      take(std::int64_t{});
    else if (a.type == "Int32")
      take(std::int32_t{});
    else if (a.type == "UInt8")
      take(std::uint8_t{});
    else
      throw std::runtime_error(path + ": type " + a.type);
    r.arrays[attribute(tag, "Name")] = a;
  }
  return r;
}

}  // namespace mneedle::test
