#include "needle/off_check.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <regex>
#include <sstream>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle::off {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& problem) {
  throw InputError(file.string() + ": " + problem);
}

constexpr std::size_t kMaxLine = 4096;  // assimp 5.2's line buffer, its terminator included

// Most corners assimp's OFF reader takes in one face (it drops larger ones, leaving a hole).
constexpr std::uint64_t kMostCorners = 9;

// The file's lines with comments ('#' to the end of the line) removed and blank lines dropped;
// each keeps its line number for the error message.
struct Line {
  std::size_t number = 0;
  std::string text;
};

// Lines end where assimp's OFF reader ends them (IsLineEnd: '\n', '\r' or '\f'), so that the
// check reads the faces assimp reads; a "\r\n" pair is one end.
std::vector<Line> content_lines(const std::filesystem::path& file, const std::string& bytes) {
  std::vector<Line> lines;
  std::size_t number = 1;
  for (std::size_t start = 0; start <= bytes.size();) {
    std::size_t end = bytes.find_first_of("\n\r\f", start);
    if (end == std::string::npos) end = bytes.size();
    // assimp copies a line into a 4096-byte buffer and goes on reading the rest as the next line.
    if (end - start >= kMaxLine)
      fail(file, "OFF line " + std::to_string(number) + " is longer than " +
                     std::to_string(kMaxLine - 1) + " characters");
    std::string text = bytes.substr(start, end - start);
    text = text.substr(0, text.find('#'));
    if (text.find_first_not_of(" \t\v") != std::string::npos) lines.push_back({number, text});
    if (end + 1 < bytes.size() && bytes[end] == '\r' && bytes[end + 1] == '\n') ++end;
    start = end + 1;
    ++number;
  }
  return lines;
}

bool is_count(const std::string& token) {
  return !token.empty() && token.size() <= 18 &&
         token.find_first_not_of("0123456789") == std::string::npos;
}

bool is_number(const std::string& token) {
  if (token.empty()) return false;
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size() && std::isfinite(value);
}

}  // namespace

void check_structure(const std::filesystem::path& file, const std::string& bytes) {
  const std::vector<Line> lines = content_lines(file, bytes);
  // The header's tokens may share a line or not ("OFF 3 1 0" or "OFF\n3 1 0"): read tokens until
  // the counts are complete, remembering which line the last of them is on.
  static const std::regex keyword("(ST)?C?N?4?(n)?OFF");
  std::vector<std::string> counts;
  bool dimension_pending = false;
  std::size_t header_end = 0;  // index into `lines` of the first data line
  for (std::size_t k = 0; k < lines.size() && counts.size() < 3; ++k) {
    std::istringstream tokens(lines[k].text);
    std::string token;
    while (counts.size() < 3 && tokens >> token) {
      std::smatch match;
      if (k == 0 && counts.empty() && !dimension_pending &&
          std::regex_match(token, match, keyword)) {
        dimension_pending = match[2].matched;  // "nOFF" is followed by the dimension
        continue;
      }
      if (dimension_pending) {
        dimension_pending = false;
        continue;
      }
      if (!is_count(token))
        fail(file, "OFF header line " + std::to_string(lines[k].number) + ": '" + token +
                       "' is not a vertex, face or edge count (a whole number >= 0)");
      counts.push_back(token);
    }
    if (counts.size() == 3) header_end = k + 1;
  }
  if (counts.size() < 3) fail(file, "OFF header ends before its vertex, face and edge counts");
  const std::uint64_t vertices = std::stoull(counts[0]);
  const std::uint64_t faces = std::stoull(counts[1]);
  const std::uint64_t data_lines = lines.size() - header_end;
  // Checked before assimp reads the file: it allocates for every declared vertex and face first.
  if (vertices + faces > data_lines)
    fail(file, "OFF header declares " + std::to_string(vertices) + " vertices and " +
                   std::to_string(faces) + " faces but the data has " + std::to_string(data_lines) +
                   " lines");
  // Every vertex line holds three coordinates and every face line its corner count (3 or more)
  // and that many indices of declared vertices: assimp reads a word where an index belongs as
  // some number and crashed on such a face in a later step (a fuzzer's input).
  for (std::uint64_t v = 0; v < vertices; ++v) {
    const Line& line = lines[header_end + v];
    std::istringstream tokens(line.text);
    std::string token;
    for (int axis = 0; axis < 3; ++axis)
      if (token.clear(); !(tokens >> token) || !is_number(token))
        fail(file, "OFF line " + std::to_string(line.number) + ": vertex " + std::to_string(v) +
                       " needs three finite coordinates" +
                       (token.empty() ? std::string() : " ('" + token + "' is not one)"));
  }
  for (std::uint64_t f = 0; f < faces; ++f) {
    const Line& line = lines[header_end + vertices + f];
    std::istringstream tokens(line.text);
    std::string token;
    const std::string where =
        "OFF line " + std::to_string(line.number) + ": face " + std::to_string(f) + ": ";
    if (!(tokens >> token) || !is_count(token) || std::stoull(token) < 3 ||
        std::stoull(token) > kMostCorners)
      fail(file, where + "'" + token + "' is not a corner count (a whole number from 3 to " +
                     std::to_string(kMostCorners) + ", what assimp reads)");
    const std::uint64_t corners = std::stoull(token);
    for (std::uint64_t c = 0; c < corners; ++c) {
      token.clear();
      if (!(tokens >> token) || !is_count(token) || std::stoull(token) >= vertices)
        fail(file, where + (token.empty() ? std::string("fewer indices than its ") +
                                                std::to_string(corners) + " corners"
                                          : "'" + token + "' is not the index of one of its " +
                                                std::to_string(vertices) + " vertices"));
    }
  }
}

}  // namespace mneedle::off
