#pragma once
// What PLplot's svg driver writes, read back for tests: its texts (characters written as &#xNN;
// entities) with their anchors, and the points of the polylines of one colour.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mneedle::test {

inline std::string read_svg(const std::filesystem::path& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// What PLplot's svg driver writes, read back: every text (its characters are written as
// &#xNN; entities) with its anchor in the plot's coordinates, and every polyline of a colour.
struct Text {
  std::string text;
  double x, y;
};
inline std::vector<Text> texts(const std::string& svg) {
  std::vector<Text> out;
  const std::regex text_re(
      R"(matrix\([^ ]+ [^ ]+ [^ ]+ [^ ]+ ([-0-9.]+) ([-0-9.]+)\)[^>]*>\s*<tspan[^>]*>([^<]*)</tspan>)");
  for (std::sregex_iterator it(svg.begin(), svg.end(), text_re), end; it != end; ++it) {
    std::string decoded;
    const std::string raw = (*it)[3];
    for (std::size_t i = 0; i < raw.size();) {
      if (raw.compare(i, 3, "&#x") == 0) {
        const auto semi = raw.find(';', i);
        const unsigned long code = std::stoul(raw.substr(i + 3, semi - i - 3), nullptr, 16);
        if (code < 0x80) {
          decoded += static_cast<char>(code);
        } else {  // two-byte UTF-8 is all the labels use (µ, °)
          decoded += static_cast<char>(0xC0 | (code >> 6));
          decoded += static_cast<char>(0x80 | (code & 0x3F));
        }
        i = semi + 1;
      } else {
        decoded += raw[i++];
      }
    }
    out.push_back({decoded, std::stod((*it)[1]), std::stod((*it)[2])});
  }
  return out;
}

// Plain string search: std::regex recurses per character and overflows the stack on long
// point lists.
inline std::vector<std::pair<double, double>> polyline(const std::string& svg,
                                                       const std::string& colour) {
  std::vector<std::pair<double, double>> out;
  const std::string stroke = "stroke=\"" + colour + "\"";
  for (auto at = svg.find(stroke); at != std::string::npos; at = svg.find(stroke, at + 1)) {
    const auto end = svg.find('>', at);
    const auto points = svg.find("points=\"", at);
    if (points == std::string::npos || points > end) continue;
    const auto close = svg.find('"', points + 8);
    const std::string list = svg.substr(points + 8, close - points - 8);
    // The legend's sample of the line is a polyline of 2 points in the same colour: not data.
    if (std::count(list.begin(), list.end(), ',') <= 2) continue;
    std::stringstream s(list);
    for (std::string pair; s >> pair;) {
      const auto comma = pair.find(',');
      out.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
    }
  }
  return out;
}

inline bool has_text(const std::vector<Text>& t, const std::string& s) {
  for (const auto& x : t)
    if (x.text == s) return true;
  return false;
}

}  // namespace mneedle::test
