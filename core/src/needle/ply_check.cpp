#include "needle/ply_check.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle::ply {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& problem) {
  throw InputError(file.string() + ": " + problem);
}

// Bytes of a PLY scalar type; 0 for an unknown name.
std::size_t type_size(const std::string& type) {
  static const std::map<std::string, std::size_t> sizes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

bool is_signed(const std::string& type) {
  return type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" ||
         type == "int32";
}

struct Property {
  std::string name;
  std::size_t size = 0;        // scalar, or the list's item
  std::size_t count_size = 0;  // 0 for a scalar
  bool count_signed = false;
  bool item_signed = false;
  bool item_float = false;
};

bool is_float(const std::string& type) {
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

bool face_list(const std::string& element, const Property& p) {
  return element == "face" && p.count_size != 0 &&
         (p.name == "vertex_indices" || p.name == "vertex_index");
}

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

// A little- or big-endian integer of `size` bytes at `at`.
std::int64_t read_integer(const std::string& bytes, std::size_t at, std::size_t size,
                          bool is_signed_type, bool big_endian) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < size; ++i) {
    const std::size_t k = big_endian ? i : size - 1 - i;
    value = (value << 8) | static_cast<unsigned char>(bytes[at + k]);
  }
  if (is_signed_type && size < 8 && (value >> (8 * size - 1)) != 0)
    return static_cast<std::int64_t>(value) - (std::int64_t{1} << (8 * size));
  return static_cast<std::int64_t>(value);
}

// A face's vertex index must name one of the file's vertices (assimp 5.2 aborts otherwise).
void check_face_size(const std::filesystem::path& file, std::uint64_t n, std::uint64_t face) {
  // assimp 5.2 aborts in its post-processing on a face of fewer than three vertices.
  if (n < 3)
    fail(file, "PLY face " + std::to_string(face) + " has " + std::to_string(n) +
                   " vertices (a face needs at least 3)");
}

void check_index(const std::filesystem::path& file, double index, std::uint64_t face,
                 std::uint64_t vertices) {
  if (!(index >= 0.0 && index < static_cast<double>(vertices)) ||
      index != static_cast<double>(static_cast<std::uint64_t>(index))) {
    // Printed as written: an index like 2e99 or -1.5 has no integer to convert to.
    std::ostringstream shown;
    shown << index;
    fail(file, "PLY face " + std::to_string(face) + " refers to vertex " + shown.str() + " of " +
                   std::to_string(vertices));
  }
}

// A list's count, read in the file's byte order; negative counts are malformed.
std::uint64_t read_count(const std::string& bytes, std::size_t at, const Property& p,
                         bool big_endian, const std::filesystem::path& file) {
  const std::int64_t value = read_integer(bytes, at, p.count_size, p.count_signed, big_endian);
  if (value < 0) fail(file, "PLY list with a negative length");
  return static_cast<std::uint64_t>(value);
}

// One line per element instance, each with exactly the numbers its properties call for (a list:
// its length, then that many). assimp 5.2 aborts on a face line shorter than its list length.
void check_ascii(const std::filesystem::path& file, const std::string& bytes, std::size_t data,
                 const std::vector<Element>& elements, std::uint64_t vertex_count) {
  std::uint64_t declared = 0;
  for (const Element& e : elements) declared += e.count;
  std::uint64_t lines = 0;
  for (std::size_t k = data; k < bytes.size(); ++k) lines += bytes[k] == '\n';
  if (data < bytes.size() && bytes.back() != '\n') ++lines;
  // Checked before reading: a count beyond the lines left would have the reader reserve memory
  // for data that is not there.
  if (declared > lines)
    fail(file, "PLY header declares " + std::to_string(declared) + " elements but the data has " +
                   std::to_string(lines) + " lines");
  std::istringstream in(bytes.substr(data));
  std::string line;
  std::uint64_t line_number = 0;
  for (const Element& e : elements) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      do {
        std::getline(in, line);
        ++line_number;
      } while (line.find_first_not_of(" \t\r") == std::string::npos && in);
      std::istringstream words(line);
      const auto bad = [&](const std::string& what) {
        fail(file, "PLY data line " + std::to_string(line_number) + " (element '" + e.name + "' " +
                       std::to_string(i) + "): " + what);
      };
      for (const Property& p : e.properties) {
        double value = 0.0;
        if (!(words >> value)) bad("fewer numbers than its properties");
        if (p.count_size == 0) continue;
        // Range first: converting a length of 1e30 to an integer is itself undefined.
        if (!(value >= 0.0 && value < 4294967296.0) ||
            value != static_cast<double>(static_cast<std::uint64_t>(value)))
          bad("a list length that is not a whole number from 0 to 2^32 - 1");
        const auto length = static_cast<std::uint64_t>(value);
        if (face_list(e.name, p)) check_face_size(file, length, i);
        for (std::uint64_t k = 0; k < length; ++k) {
          if (!(words >> value)) bad("fewer numbers than its list length");
          if (face_list(e.name, p)) check_index(file, value, i, vertex_count);
        }
      }
      std::string extra;
      if (words >> extra) bad("more numbers than its properties");
    }
  }
}

}  // namespace

void check_structure(const std::filesystem::path& file, const std::string& bytes) {
  const std::size_t end = bytes.find("end_header");
  if (bytes.compare(0, 3, "ply") != 0) fail(file, "not a PLY file (no 'ply' on its first line)");
  if (end == std::string::npos) fail(file, "PLY header without 'end_header'");
  std::size_t data = bytes.find('\n', end);
  data = data == std::string::npos ? bytes.size() : data + 1;
  // 'end_header' alone on its line: assimp 5.2 read for ever on one followed by other bytes.
  if ((end > 0 && bytes[end - 1] != '\n') || bytes.find_first_not_of(" \t\r\n", end + 10) < data)
    fail(file, "PLY 'end_header' is not alone on its line");

  std::istringstream header(bytes.substr(0, end));
  std::string format;
  std::vector<Element> elements;
  for (std::string line; std::getline(header, line);) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    // Every header line is one assimp knows; it loops forever on some it does not (fuzz_mesh).
    if (keyword != "ply" && keyword != "format" && keyword != "comment" && keyword != "obj_info" &&
        keyword != "element" && keyword != "property" && !keyword.empty())
      fail(file, "PLY header line '" + line.substr(0, 40) + "' is not a PLY header keyword");
    if (keyword == "format") {
      words >> format;
    } else if (keyword == "element") {
      Element e;
      long long count = -1;
      words >> e.name >> count;
      if (!words || count < 0) fail(file, "PLY element line '" + line + "' without a count");
      e.count = static_cast<std::uint64_t>(count);
      // assimp 5.2 aborts on an element declared twice.
      for (const Element& known : elements)
        if (known.name == e.name) fail(file, "PLY element '" + e.name + "' declared twice");
      elements.push_back(e);
    } else if (keyword == "property") {
      if (elements.empty()) fail(file, "PLY property before any element");
      std::string type;
      words >> type;
      Property p;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        p.count_size = type_size(count_type);
        p.count_signed = is_signed(count_type);
        p.size = type_size(item_type);
        p.item_signed = is_signed(item_type);
        p.item_float = is_float(item_type);
        words >> p.name;
        if (p.count_size == 0 || p.count_size > 4 || p.size == 0)
          fail(file, "PLY property line '" + line + "' with an unknown type");
      } else {
        p.size = type_size(type);
        words >> p.name;
        if (p.size == 0) fail(file, "PLY property line '" + line + "' with an unknown type");
      }
      elements.back().properties.push_back(p);
    }
  }
  if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
    fail(file,
         "PLY format '" + format + "' is not ascii, binary_little_endian or binary_big_endian");
  for (const Element& e : elements)
    if (e.count > 0 && e.properties.empty())
      fail(file, "PLY element '" + e.name + "' has a count but no properties");
  // What mneedle reads: vertex x, y, z and face vertex lists (assimp 5.2 aborts in its
  // post-processing on vertices without y).
  const auto has = [](const Element& e, const std::string& name, bool list) {
    return std::any_of(e.properties.begin(), e.properties.end(), [&](const Property& p) {
      return p.name == name && (p.count_size != 0) == list;
    });
  };
  const auto vertex = std::find_if(elements.begin(), elements.end(),
                                   [](const Element& e) { return e.name == "vertex"; });
  if (vertex == elements.end() || !has(*vertex, "x", false) || !has(*vertex, "y", false) ||
      !has(*vertex, "z", false))
    fail(file, "PLY without a vertex element with x, y and z properties");
  for (const Element& e : elements)
    if (e.name == "face" && !has(e, "vertex_indices", true) && !has(e, "vertex_index", true))
      fail(file, "PLY face element without a vertex_indices list");
  if (format == "ascii") {
    check_ascii(file, bytes, data, elements, vertex->count);
    return;
  }

  // Walk the binary data element by element: every byte the header promises must be there.
  const bool big_endian = format == "binary_big_endian";
  const std::uint64_t vertex_count = vertex->count;
  std::size_t at = data;
  for (const Element& e : elements) {
    for (std::uint64_t i = 0; i < e.count; ++i) {
      for (const Property& p : e.properties) {
        if (p.count_size == 0) {
          if (bytes.size() - at < p.size)
            at = bytes.size() + 1;
          else
            at += p.size;
        } else if (bytes.size() - at < p.count_size) {
          at = bytes.size() + 1;
        } else {
          const std::uint64_t n = read_count(bytes, at, p, big_endian, file);
          at += p.count_size;
          if ((bytes.size() - at) / p.size < n) {
            at = bytes.size() + 1;
          } else if (face_list(e.name, p)) {
            if (p.item_float) fail(file, "PLY face indices are not integers");
            check_face_size(file, n, i);
            for (std::uint64_t k = 0; k < n; ++k, at += p.size)
              check_index(
                  file,
                  static_cast<double>(read_integer(bytes, at, p.size, p.item_signed, big_endian)),
                  i, vertex_count);
          } else {
            at += static_cast<std::size_t>(n) * p.size;
          }
        }
        if (at > bytes.size())
          fail(file, "PLY data ends inside element '" + e.name + "' " + std::to_string(i) + " of " +
                         std::to_string(e.count) + " (the file is shorter than its header says)");
      }
    }
  }
}

}  // namespace mneedle::ply
