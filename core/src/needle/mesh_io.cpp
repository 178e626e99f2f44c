#include "mneedle/needle/mesh_io.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "mneedle/base/error.h"
#include "needle/off_check.h"
#include "needle/ply_check.h"

namespace mneedle {
namespace {

constexpr std::size_t kStlHeaderBytes = 80;
constexpr std::size_t kStlPreambleBytes = kStlHeaderBytes + 4;  // header + triangle count
constexpr std::size_t kStlTriangleBytes = 50;  // normal, 3 vertices (12 floats), attribute

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& problem) {
  throw InputError(file.string() + ": " + problem);
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open the file for reading");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint32_t read_u32_le(const std::string& bytes, std::size_t offset) {
  std::uint32_t value = 0;
  for (int i = 3; i >= 0; --i) {
    value = (value << 8) | static_cast<unsigned char>(bytes[offset + static_cast<std::size_t>(i)]);
  }
  return value;
}

float read_f32_le(const std::string& bytes, std::size_t offset) {
  return std::bit_cast<float>(read_u32_le(bytes, offset));
}

bool starts_with_solid(const std::string& bytes) {
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  return first != std::string::npos && lowercase(bytes.substr(first, 5)) == "solid";
}

bool is_binary_stl_size(const std::string& bytes) {
  if (bytes.size() < kStlPreambleBytes) return false;
  const std::uint64_t count = read_u32_le(bytes, kStlHeaderBytes);
  return kStlPreambleBytes + kStlTriangleBytes * count == bytes.size();
}

// Assimp reads binary STL without complaint when the triangle count disagrees with the
// file size, so the arithmetic 84 + 50 n is checked here first.
void check_binary_stl(const std::filesystem::path& file, const std::string& bytes) {
  if (bytes.size() < kStlPreambleBytes) {
    fail(file, "truncated binary STL (" + std::to_string(bytes.size()) +
                   " bytes, shorter than the 84-byte header)");
  }
  const std::uint64_t count = read_u32_le(bytes, kStlHeaderBytes);
  const std::uint64_t expected = kStlPreambleBytes + kStlTriangleBytes * count;
  if (expected != bytes.size()) {
    fail(file, "truncated binary STL (header declares " + std::to_string(count) +
                   " triangles = " + std::to_string(expected) + " bytes, file has " +
                   std::to_string(bytes.size()) + " bytes)");
  }
  std::size_t non_finite = 0;
  std::uint64_t first_bad_triangle = 0;
  for (std::uint64_t t = 0; t < count; ++t) {
    const std::size_t vertices_at = kStlPreambleBytes + kStlTriangleBytes * t + 12;
    for (std::size_t k = 0; k < 9; ++k) {
      if (!std::isfinite(read_f32_le(bytes, vertices_at + 4 * k))) {
        if (non_finite++ == 0) first_bad_triangle = t;
      }
    }
  }
  if (non_finite > 0) {
    fail(file, std::to_string(non_finite) + " non-finite vertex coordinate(s) (first in triangle " +
                   std::to_string(first_bad_triangle) + ")");
  }
  if (count == 0) fail(file, "mesh is empty (no triangles)");
}

bool names_non_finite_number(std::string token) {
  token = lowercase(token);
  if (!token.empty() && (token[0] == '+' || token[0] == '-')) token.erase(0, 1);
  return token == "nan" || token == "inf" || token == "infinity" || token.starts_with("nan(") ||
         token.find("#inf") != std::string::npos || token.find("#nan") != std::string::npos ||
         token.find("#qnan") != std::string::npos || token.find("#ind") != std::string::npos;
}

// Text formats may spell 'nan' or 'inf'; a reader may turn them into 0 or drop the vertex,
// so they are caught in the text itself, with the line number.
void check_text_for_non_finite(const std::filesystem::path& file, const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  for (std::size_t number = 1; std::getline(lines, line); ++number) {
    std::istringstream tokens(line);
    std::string token;
    while (tokens >> token) {
      if (names_non_finite_number(token)) {
        throw InputError(file.string() + ":" + std::to_string(number) +
                         ": non-finite coordinate '" + token + "'");
      }
    }
  }
}

bool is_text(const std::string& bytes) {
  const std::size_t probe = std::min<std::size_t>(bytes.size(), 4096);
  return std::none_of(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(probe),
                      [](char c) { return c == '\0'; });
}

void precheck_file(const std::filesystem::path& file, const std::string& extension) {
  std::error_code error;
  if (!std::filesystem::exists(file, error)) fail(file, "file not found");
  if (!std::filesystem::is_regular_file(file, error)) fail(file, "not a regular file");
  if (extension != ".stl" && extension != ".obj" && extension != ".ply" && extension != ".off") {
    fail(file, "unsupported mesh format '" + extension + "' (expected .stl, .obj, .ply or .off)");
  }
  const std::string bytes = read_bytes(file);
  if (bytes.empty()) fail(file, "file is empty (0 bytes)");
  const bool ascii_stl = starts_with_solid(bytes) && is_text(bytes);
  if (extension == ".stl" && !is_binary_stl_size(bytes) && !ascii_stl) {
    if (is_text(bytes)) fail(file, "not a mesh: neither ASCII STL ('solid ...') nor binary STL");
    check_binary_stl(file, bytes);
  }
  if (extension == ".ply") ply::check_structure(file, bytes);
  if (extension == ".off") off::check_structure(file, bytes);
  if (extension == ".stl" && is_binary_stl_size(bytes)) {
    check_binary_stl(file, bytes);
  } else if (is_text(bytes)) {
    check_text_for_non_finite(file, bytes);
  }
}

struct PositionLess {
  bool operator()(const Vec3& a, const Vec3& b) const { return a < b; }
};

// Welds across all meshes of the scene (a file may hold several solids or groups).
TriangleMesh collect_triangles(const std::filesystem::path& file, const aiScene& scene,
                               double metres_per_unit) {
  TriangleMesh mesh;
  std::map<Vec3, std::uint32_t, PositionLess> index_of;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& part = *scene.mMeshes[m];
    std::vector<std::uint32_t> welded(part.mNumVertices);
    for (unsigned v = 0; v < part.mNumVertices; ++v) {
      const aiVector3D& p = part.mVertices[v];
      const Vec3 position{p.x * metres_per_unit, p.y * metres_per_unit, p.z * metres_per_unit};
      if (!std::isfinite(position[0]) || !std::isfinite(position[1]) ||
          !std::isfinite(position[2])) {
        fail(file, "non-finite vertex coordinate (" + std::to_string(p.x) + ", " +
                       std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
      }
      const auto [it, inserted] =
          index_of.emplace(position, static_cast<std::uint32_t>(mesh.vertices.size()));
      if (inserted) mesh.vertices.push_back(position);
      welded[v] = it->second;
    }
    for (unsigned f = 0; f < part.mNumFaces; ++f) {
      const aiFace& face = part.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      for (unsigned k = 0; k < 3; ++k)
        if (face.mIndices[k] >= part.mNumVertices)
          fail(file, "face " + std::to_string(f) + " refers to vertex " +
                         std::to_string(face.mIndices[k]) + " of " +
                         std::to_string(part.mNumVertices));
      mesh.triangles.push_back(
          {welded[face.mIndices[0]], welded[face.mIndices[1]], welded[face.mIndices[2]]});
    }
  }
  return mesh;
}

void put_u32_le(std::string& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFFu));
}

void put_f32_le(std::string& out, double value) {
  put_u32_le(out, std::bit_cast<std::uint32_t>(static_cast<float>(value)));
}

std::string stl_header(std::string_view text) {
  std::string header(text.substr(0, kStlHeaderBytes));
  if (lowercase(header.substr(0, 5)) == "solid") header = ("binary " + header);
  header.resize(kStlHeaderBytes, '\0');
  return header;
}

Vec3 unit_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Vec3 w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const Vec3 n{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (length == 0.0) return {0.0, 0.0, 0.0};
  return {n[0] / length, n[1] / length, n[2] / length};
}

void check_unit_scale(const std::filesystem::path& file, double metres_per_unit) {
  if (!std::isfinite(metres_per_unit) || metres_per_unit <= 0.0) {
    fail(file, "the length unit must be a positive, finite number of metres (got " +
                   std::to_string(metres_per_unit) + ")");
  }
}

}  // namespace

TriangleMesh load_mesh(const std::filesystem::path& file, double metres_per_unit) {
  check_unit_scale(file, metres_per_unit);
  const std::string extension = lowercase(file.extension().string());
  precheck_file(file, extension);
  Assimp::Importer importer;
  // ValidateDataStructure runs before the other steps and refuses a face that indexes past the
  // vertex list (a PLY with a bad index otherwise crashes assimp's own post-processing). No
  // JoinIdenticalVertices: it joins within an absolute 1e-5 file units (10 um in a file in
  // metres), which fuses a fine tip; collect_triangles welds identical positions exactly.
  const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                         aiProcess_DropNormals | aiProcess_PreTransformVertices;
  const aiScene* scene = importer.ReadFile(file.string(), flags);
  if (scene == nullptr) {
    const std::string reason = importer.GetErrorString();
    if (reason.find("No output meshes") != std::string::npos ||
        reason.find("contains no vertices") != std::string::npos ||
        reason.find("contains no faces") != std::string::npos) {
      fail(file, "mesh is empty (no triangles)");
    }
    // assimp's validation names its own structures (aiMesh::mFaces[3]::mIndices[2]): say what
    // that means in the file instead.
    if (reason.find("Validation failed") != std::string::npos)
      fail(file, "not a readable mesh (a face refers to vertices the file does not hold)");
    fail(file, "not a readable mesh (" + reason + ")");
  }
  TriangleMesh mesh = collect_triangles(file, *scene, metres_per_unit);
  if (mesh.triangles.empty()) fail(file, "mesh is empty (no triangles)");
  return mesh;
}

std::optional<std::string> declared_length_unit(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(kStlHeaderBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  head = head.substr(0, head.find('\n'));  // ASCII: the `solid` line only
  for (const char* unit : {"um", "mm", "m"}) {
    const std::string token = std::string("unit=") + unit;
    const auto at = head.find(token);
    if (at == std::string::npos) continue;
    const std::size_t end = at + token.size();
    if (end == head.size() || !std::isalnum(static_cast<unsigned char>(head[end]))) return unit;
  }
  return std::nullopt;
}

void write_stl_binary(const TriangleMesh& mesh, const std::filesystem::path& file,
                      double metres_per_unit, std::string_view header) {
  check_unit_scale(file, metres_per_unit);
  std::string out = stl_header(header);
  out.reserve(kStlPreambleBytes + kStlTriangleBytes * mesh.triangles.size());
  put_u32_le(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices.at(t[0]);
    const Vec3& b = mesh.vertices.at(t[1]);
    const Vec3& c = mesh.vertices.at(t[2]);
    for (double component : unit_normal(a, b, c)) put_f32_le(out, component);
    for (const Vec3* p : {&a, &b, &c}) {
      for (double component : *p) {
        if (!std::isfinite(component)) fail(file, "cannot write a non-finite coordinate");
        put_f32_le(out, component / metres_per_unit);
      }
    }
    out.append(2, '\0');  // attribute byte count
  }
  std::ofstream stream(file, std::ios::binary | std::ios::trunc);
  if (!stream) fail(file, "cannot open the file for writing");
  stream.write(out.data(), static_cast<std::streamsize>(out.size()));
  if (!stream) fail(file, "writing failed");
}

}  // namespace mneedle
