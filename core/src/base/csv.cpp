#include "mneedle/base/csv.h"

#include <fstream>
#include <iterator>
#include <set>
#include <string_view>

#include "mneedle/base/error.h"
#include "mneedle/base/files.h"

namespace mneedle {
namespace {

std::string at(const std::string& source, std::size_t line) {
  return source + ":" + std::to_string(line);
}

bool is_comment_or_blank(std::string_view text, std::size_t pos) {
  const auto first = text.find_first_not_of(" \t\r", pos);
  return first == std::string_view::npos || text[first] == '\n' || text[first] == '#';
}

// Reads one record starting at `pos` (the start of a line); leaves `pos` after its line break and
// advances `line` past every line break consumed, quoted ones included.
std::vector<std::string> read_record(std::string_view text, std::size_t& pos, std::size_t& line,
                                     const std::string& source) {
  const std::size_t first_line = line;
  std::vector<std::string> fields;
  std::string field;
  while (true) {
    // one field
    field.clear();
    while (pos < text.size() && (text[pos] == ' ' || text[pos] == '\t')) ++pos;
    if (pos < text.size() && text[pos] == '"') {
      ++pos;
      while (true) {
        if (pos >= text.size()) {
          throw InputError(at(source, first_line) + ": a quoted field is never closed");
        }
        const char c = text[pos++];
        if (c == '"') {
          if (pos < text.size() && text[pos] == '"') {
            field += '"';
            ++pos;
          } else {
            break;
          }
        } else {
          if (c == '\n') ++line;
          field += c;
        }
      }
      while (pos < text.size() && (text[pos] == ' ' || text[pos] == '\t' || text[pos] == '\r')) {
        ++pos;
      }
      if (pos < text.size() && text[pos] != ',' && text[pos] != '\n') {
        throw InputError(at(source, line) + ": field " + std::to_string(fields.size() + 1) +
                         ": text after the closing quote");
      }
    } else {
      const std::size_t start = pos;
      while (pos < text.size() && text[pos] != ',' && text[pos] != '\n') {
        if (text[pos] == '"') {
          throw InputError(at(source, line) + ": field " + std::to_string(fields.size() + 1) +
                           ": a quote inside an unquoted field (quote the whole field and "
                           "write the quote twice)");
        }
        ++pos;
      }
      field = std::string(trim(text.substr(start, pos - start)));
    }
    fields.push_back(field);
    if (pos >= text.size()) return fields;
    if (text[pos] == '\n') {
      ++pos;
      ++line;
      return fields;
    }
    ++pos;  // the comma: another field follows, empty if the record ends here
  }
}

}  // namespace

std::string CsvTable::where(std::size_t line) const {
  return at(source, line);
}

std::size_t CsvTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  std::string names;
  for (const auto& h : header) names += (names.empty() ? "" : ", ") + h;
  throw InputError(where(header_line) + ": no column '" + std::string(name) +
                   "' (columns: " + names + ")");
}

CsvTable parse_csv(std::string_view text, std::string source) {
  CsvTable table;
  table.source = std::move(source);
  // Excel's "CSV UTF-8" starts with a byte-order mark, which would become part of the first
  // column's name ("\xEF\xBB\xBFdepth [mm]" looks like "depth [mm]" and matches nothing).
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::size_t pos = 0;
  std::size_t line = 1;
  while (pos < text.size()) {
    if (is_comment_or_blank(text, pos)) {
      const auto end = text.find('\n', pos);
      pos = end == std::string_view::npos ? text.size() : end + 1;
      ++line;
      continue;
    }
    const std::size_t record_line = line;
    auto fields = read_record(text, pos, line, table.source);
    if (table.header.empty()) {
      // A name twice is two columns a reader cannot tell apart (the first was taken).
      std::set<std::string_view> names;
      for (const std::string& name : fields)
        if (!name.empty() && !names.insert(name).second)
          throw InputError(table.source + ":" + std::to_string(record_line) + ": column '" + name +
                           "' appears twice in the header");
      table.header = std::move(fields);
      table.header_line = record_line;
      continue;
    }
    if (fields.size() != table.header.size()) {
      throw InputError(table.where(record_line) + ": expected " +
                       std::to_string(table.header.size()) + " fields (as the header on line " +
                       std::to_string(table.header_line) + "), found " +
                       std::to_string(fields.size()));
    }
    table.rows.push_back({record_line, std::move(fields)});
  }
  if (table.header.empty()) throw InputError(table.source + ":1: empty file, no header line");
  return table;
}

CsvTable read_csv(const std::filesystem::path& file) {
  return parse_csv(read_input_file(file), file.string());
}

}  // namespace mneedle
