#include "mneedle/base/csv.h"

#include <gtest/gtest.h>

#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

std::string message_of(const std::string& text) {
  try {
    parse_csv(text, "t.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// Two columns of one name cannot be told apart (every reader took the first).
TEST(Csv, AColumnNameTwiceInTheHeaderIsNamedWithItsLine) {
  EXPECT_EQ(message_of("travel_mm,force_N,force_N\n1,2,3\n"),
            "t.csv:1: column 'force_N' appears twice in the header");
}

TEST(Csv, QuotedFieldKeepsItsCommaAsOneField) {
  const auto t = parse_csv("value,group\n1,\"g,1\"\n", "t.csv");
  ASSERT_EQ(t.rows.size(), 1u);
  ASSERT_EQ(t.rows[0].fields.size(), 2u);
  EXPECT_EQ(t.rows[0].fields[1], "g,1");
}

TEST(Csv, DoubledQuoteInsideQuotesIsOneQuote) {
  const auto t = parse_csv("a\n\"say \"\"hi\"\"\"\n", "t.csv");
  EXPECT_EQ(t.rows.at(0).fields.at(0), "say \"hi\"");
}

TEST(Csv, LineBreakInsideQuotesBelongsToTheFieldAndLinesStillCount) {
  const auto t = parse_csv("a,b\n\"x\ny\",2\n3,4\n", "t.csv");
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0].fields[0], "x\ny");
  EXPECT_EQ(t.rows[0].line, 2u);
  EXPECT_EQ(t.rows[1].line, 4u);
}

TEST(Csv, TrailingCommaIsOneMoreEmptyField) {
  const auto t = parse_csv("a,b,\n1,2,\n", "t.csv");
  ASSERT_EQ(t.header.size(), 3u);
  EXPECT_EQ(t.header[2], "");
  EXPECT_EQ(t.rows.at(0).fields.at(2), "");
}

TEST(Csv, TrailingCommaOnlyOnDataRowsIsAFieldCountError) {
  EXPECT_EQ(message_of("a,b\n1,2,\n"),
            "t.csv:2: expected 2 fields (as the header on line 1), found 3");
}

TEST(Csv, ExtraAndMissingFieldsNameTheLine) {
  EXPECT_EQ(message_of("a,b\n1,2\n1,2,3\n"),
            "t.csv:3: expected 2 fields (as the header on line 1), found 3");
  EXPECT_EQ(message_of("a,b\n1\n"),
            "t.csv:2: expected 2 fields (as the header on line 1), found 1");
}

TEST(Csv, CommentsBlankLinesAndCrLfAreSkipped) {
  const auto t = parse_csv("# recorded 2024\r\n\r\n z [mm] , F [N]\r\n# mid\r\n1, 2\r\n", "t.csv");
  EXPECT_EQ(t.header_line, 3u);
  EXPECT_EQ(t.header[0], "z [mm]");
  EXPECT_EQ(t.header[1], "F [N]");
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.rows[0].line, 5u);
  EXPECT_EQ(t.rows[0].fields[1], "2");
}

TEST(Csv, UnterminatedQuoteNamesTheLineWhereTheFieldStarts) {
  EXPECT_EQ(message_of("a\n\"open\n\n"), "t.csv:2: a quoted field is never closed");
}

TEST(Csv, TextAfterClosingQuoteIsAnError) {
  EXPECT_EQ(message_of("a,b\n\"x\"y,1\n"), "t.csv:2: field 1: text after the closing quote");
}

TEST(Csv, QuoteInsideUnquotedFieldIsAnError) {
  EXPECT_NE(message_of("a\nx\"y\n").find("t.csv:2: field 1: a quote inside an unquoted field"),
            std::string::npos);
}

TEST(Csv, EmptyTextHasNoHeader) {
  EXPECT_EQ(message_of("# only a comment\n"), "t.csv:1: empty file, no header line");
}

TEST(Csv, UnknownColumnListsTheHeader) {
  const auto t = parse_csv("a,b\n1,2\n", "t.csv");
  EXPECT_EQ(t.column("b"), 1u);
  try {
    t.column("c");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "t.csv:1: no column 'c' (columns: a, b)");
  }
}

TEST(Csv, MissingFileNamesTheFile) {
  EXPECT_THROW(read_csv("/nonexistent/x.csv"), InputError);
}

}  // namespace
}  // namespace mneedle
