#include "core/csv.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace blurcue {
namespace {

std::vector<std::vector<std::string>> Fields(const CsvText& csv) {
  std::vector<std::vector<std::string>> out;
  for (const auto& r : csv.records) out.push_back(r.fields);
  return out;
}

using Table = std::vector<std::vector<std::string>>;

TEST(ParseCsv, LfCrlfAndLoneCrEndRecordsAlike) {
  const Table want = {{"edge", "id"}, {"3", "a"}, {"6", "b"}};
  for (const char* text : {"edge,id\n3,a\n6,b\n", "edge,id\r\n3,a\r\n6,b\r\n", "edge,id\r3,a\r6,b\r", "edge,id\n3,a\n6,b"}) {
    const CsvText csv = ParseCsv(text, 100);
    EXPECT_TRUE(csv.problems.empty()) << text;
    EXPECT_EQ(Fields(csv), want) << text;
  }
}

TEST(ParseCsv, ByteOrderMarkIsNotPartOfTheFirstName) {
  const CsvText csv = ParseCsv("\xEF\xBB\xBF" "edge\n3\n", 100);
  ASSERT_EQ(csv.records.size(), 2u);
  EXPECT_EQ(csv.records[0].fields[0], "edge");
}

TEST(ParseCsv, QuotedFieldsHoldCommasQuotesAndLineBreaks) {
  const CsvText csv = ParseCsv("label,edge\n\"a, \"\"b\"\"\",3\n\"two\nlines\",4\n\"\",5\n", 100);
  ASSERT_TRUE(csv.problems.empty());
  EXPECT_EQ(Fields(csv), (Table{{"label", "edge"}, {"a, \"b\"", "3"}, {"two\nlines", "4"}, {"", "5"}}));
  // The record after a quoted line break starts on line 3 and ends on 4: the next one is on line 5.
  EXPECT_EQ(csv.records[2].line, 3u);
  EXPECT_EQ(csv.records[3].line, 5u);
}

TEST(ParseCsv, EmptyLinesAreSkippedAndEmptyFieldsKept) {
  const CsvText csv = ParseCsv("a,b\n\n,\n\r\n1,\n", 100);
  EXPECT_EQ(Fields(csv), (Table{{"a", "b"}, {"", ""}, {"1", ""}}));
  EXPECT_EQ(csv.records[1].line, 3u);
  EXPECT_EQ(csv.records[2].line, 5u);
}

TEST(ParseCsv, TextAfterAClosingQuoteIsRefusedWhereItIs) {
  const CsvText csv = ParseCsv("edge,side\n3,\"ne\"ar\n", 100);
  ASSERT_EQ(csv.problems.size(), 1u);
  EXPECT_EQ(csv.problems[0].line, 2u);
  EXPECT_EQ(csv.problems[0].column, 7u);  // 3 , " n e " a: the a
  EXPECT_NE(csv.problems[0].message.find("after a field's closing quote"), std::string::npos);
}

TEST(ParseCsv, AQuoteInsideAnUnquotedFieldIsRefused) {
  const CsvText csv = ParseCsv("label\nsay \"hi\"\n", 100);
  ASSERT_EQ(csv.problems.size(), 1u);
  EXPECT_EQ(csv.problems[0].line, 2u);
  EXPECT_EQ(csv.problems[0].column, 5u);
}

TEST(ParseCsv, AnUnclosedQuoteNamesWhereItOpened) {
  const CsvText csv = ParseCsv("label,edge\n\"open,3\n4,5\n", 100);
  ASSERT_EQ(csv.problems.size(), 1u);
  EXPECT_EQ(csv.problems[0].line, 2u);
  EXPECT_EQ(csv.problems[0].column, 1u);
}

TEST(ParseCsv, ColumnsCountCharactersNotBytes) {
  const CsvText csv = ParseCsv("label,side\n\xC3\xA9\xC3\xA9,\"x\"y\n", 100);  // éé: two characters, four bytes
  ASSERT_EQ(csv.problems.size(), 1u);
  EXPECT_EQ(csv.problems[0].column, 7u);
}

TEST(ParseCsv, StopsAfterTheLimit) {
  std::string text = "a\n";
  for (int i = 0; i < 50; ++i) text += "1\n";
  EXPECT_EQ(ParseCsv(text, 10).records.size(), 11u);
}

// A file cut inside its last row leaves a short record (3 of 19 fields) that parses: refused with its file and line.
TEST(RequireFullRecords, ShortOrLongRowIsRefusedNamingFileAndLine) {
  const std::string whole = "frame,time_s,status,note\n0,0.0,found,\"\"\n1,0.03,found,\"\"\n";
  EXPECT_NO_THROW(RequireFullRecords(ParseCsv(whole, 100), "track.csv"));
  const std::string cut = whole.substr(0, whole.size() - 6);  // "1,0.03,fo": no line break, 3 fields
  try {
    RequireFullRecords(ParseCsv(cut, 100), "track.csv");
    FAIL() << "a cut row was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_EQ(std::string(e.what()), "track.csv: line 3: has 3 fields, the header 4: the row is cut short (a truncated "
                                     "file, or an edit)");
  }
  EXPECT_THROW(RequireFullRecords(ParseCsv("a,b\n1,2,3\n", 100), "x.csv"), Error);
}

}  // namespace
}  // namespace blurcue
