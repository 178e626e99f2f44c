#pragma once
// The one reader of tabular input (measured curves, grouped samples): RFC 4180 comma-separated
// values with file:line errors. docs/cli.md ("CSV input") states the rules for users.
//
// - Fields are separated by commas; a field in double quotes may hold commas, line breaks and
//   quotes written twice (""). Spaces and tabs around a field (outside its quotes) are dropped.
// - A trailing comma ends the record with one more, empty, field (RFC 4180: "a,b," has three).
// - Blank lines and lines whose first character (after spaces) is '#' are comments (an extension
//   of RFC 4180 that recordings use for metadata); the first other record is the header.
// - Every record has as many fields as the header; a record with more or fewer is an error.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mneedle/base/text.h"

namespace mneedle {

struct CsvRecord {
  std::size_t line = 0;  ///< 1-based line where the record starts
  std::vector<std::string> fields;
};

struct CsvTable {
  std::string source;  ///< the file name (or what the caller named the text) used in messages
  std::size_t header_line = 0;
  std::vector<std::string> header;
  std::vector<CsvRecord> rows;

  /// "<source>:<line>" for messages about a record.
  std::string where(std::size_t line) const;
  /// Index of the header field equal to `name`; InputError listing the header otherwise.
  std::size_t column(std::string_view name) const;
};

/// Parses CSV text. Throws InputError "<source>:<line>: <problem>" for an unterminated quote, text
/// after a closing quote, a record whose field count differs from the header's, or no header.
CsvTable parse_csv(std::string_view text, std::string source);

/// Reads and parses a file; InputError "<file>: cannot open the file" when it cannot be read.
CsvTable read_csv(const std::filesystem::path& file);

}  // namespace mneedle
