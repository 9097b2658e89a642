#include "core/typed.h"

#include <limits>

#include <gtest/gtest.h>

namespace blurcue {
namespace {

TEST(ParseDecimal, ReadsDecimalNumbersAsWritten) {
  const std::pair<const char*, double> cases[] = {
      {"0", 0},      {"12", 12},       {"-3", -3},     {"+4", 4},       {"0.5", 0.5},  {".5", 0.5},
      {"5.", 5},     {"-0.25", -0.25}, {"1e3", 1000},  {"1E-2", 0.01},  {"2.5e+1", 25}, {"010", 10},
      {"1e308", 1e308}, {"4.9e-324", std::numeric_limits<double>::denorm_min()}, {"1e-999", 0},
  };
  for (const auto& [text, value] : cases) {
    const std::optional<double> v = ParseDecimal(text);
    ASSERT_TRUE(v) << text;
    EXPECT_EQ(*v, value) << text;
  }
}

// Each of these strtod would take (or take the start of): hex as 16, "inf", "nan", a leading space.
TEST(ParseDecimal, RefusesWhatIsNotADecimalNumber) {
  for (const char* text : {"", " ", "+", "-", ".", "e3", "1e", "1e+", "0x10", "0X1p3", "inf", "-inf", "infinity",
                           "nan", "NaN", " 1", "1 ", "1\n", "\t2", "1,5", "1.2.3", "--1", "+-1", "1e3.5", "1e999",
                           "-1e400", "１", "1f", "1d", "0b1"})
    EXPECT_FALSE(ParseDecimal(text)) << "'" << text << "'";
  EXPECT_FALSE(ParseDecimal(std::string_view("12\0" "3", 4)));  // a NUL inside is not the end of the number
}

TEST(ParseDecimal, WholeNumbersHaveNoPointOrExponent) {
  for (const char* text : {"0", "12", "-3", "+7", "007"}) EXPECT_TRUE(IsWholeDecimal(text)) << text;
  for (const char* text : {"12.0", "1e3", "1.", "0x10", "", "1.5", " 3"}) EXPECT_FALSE(IsWholeDecimal(text)) << text;
}

TEST(IsPrintableUtf8, TakesTextInAnyScriptAndRefusesControlsAndBrokenBytes) {
  for (const char* text : {"", "P7", "S-01_a.b", "Zoë", "参加者12", "участник 3", "\xf0\x9f\x98\x80" /* U+1F600 */})
    EXPECT_TRUE(IsPrintableUtf8(text)) << text;
  for (const char* text : {"P\n7", "P7\r", "\tP", "a\x7f", "\x1b[31mred", "\xc2\x85" /* U+0085 NEL */,
                           "\xff", "\xc3", "\xc3(", "\xc0\xaf" /* overlong '/' */, "\xe0\x80\xaf",
                           "\xed\xa0\x80" /* a surrogate */, "\xf4\x90\x80\x80" /* past U+10FFFF */, "\xf8\x88\x80\x80\x80"})
    EXPECT_FALSE(IsPrintableUtf8(text)) << text;
  EXPECT_FALSE(IsPrintableUtf8(std::string_view("P\0" "7", 3)));
}

// What someone typed, echoed in a message, stays one line and cannot drive the terminal.
TEST(OneLine, EscapesControlsAndBrokenBytesAndKeepsText) {
  EXPECT_EQ(OneLine("--seed: must be a number, got '3\n'"), "--seed: must be a number, got '3\\n'");
  EXPECT_EQ(OneLine("a\tb\rc\x1b[2Jd\xff" "e"), "a\\tb\\rc\\x1b[2Jd\\xffe");
  EXPECT_EQ(OneLine("Zoë 参加者 \xf0\x9f\x98\x80"), "Zoë 参加者 \xf0\x9f\x98\x80");
  EXPECT_EQ(OneLine(std::string_view("a\0b", 3)), "a\\x00b");
  for (const char* text : {"x\n", "\x1b", "\xc3(", "\xc2\x85"}) EXPECT_TRUE(IsPrintableUtf8(OneLine(text))) << text;
  // A bidirectional control (U+202E, right-to-left override) would show the rest of a terminal line reversed: its
  // code point is written instead; Arabic and Hebrew letters stay as they are.
  EXPECT_EQ(OneLine("/layuot\xe2\x80\xae: unknown key"), "/layuot\\u202E: unknown key");
  EXPECT_EQ(OneLine("a\xe2\x81\xa6" "b\xd8\x9c"), "a\\u2066b\\u061C");
  EXPECT_EQ(OneLine("שלום مرحبا"), "שלום مرحبا");
}

// A typed value a message quotes is cut after 60 characters, with its whole length said; short values stay whole.
TEST(Echo, CutsLongValuesAndSaysTheirLength) {
  EXPECT_EQ(Echo("nan"), "'nan'");
  EXPECT_EQ(Echo("1e308", false), "1e308");
  EXPECT_EQ(Echo(""), "''");
  EXPECT_EQ(Echo(std::string(60, '7')), "'" + std::string(60, '7') + "'");
  EXPECT_EQ(Echo(std::string(100000, '1')), "'" + std::string(60, '1') + "...' (100000 characters)");
  EXPECT_EQ(Echo(std::string(61, '1'), false), std::string(60, '1') + "... (61 characters)");
  // Characters, not bytes: a cut never splits one, and controls are escaped as OneLine does.
  std::string zoe;
  for (int i = 0; i < 70; ++i) zoe += "\xc3\xab";
  EXPECT_EQ(Echo(zoe), "'" + zoe.substr(0, 120) + "...' (70 characters)");
  EXPECT_EQ(Echo("a\nb\x1b"), "'a\\nb\\x1b'");
}

TEST(UnsafeIdReason, FormulaStartsAndBidiControlsAreNamed) {
  EXPECT_EQ(UnsafeIdReason("P1"), "");
  EXPECT_EQ(UnsafeIdReason("P-1"), "");  // a minus inside is harmless
  EXPECT_EQ(UnsafeIdReason(""), "");
  for (const char* id : {"=1+1", "+1", "-2", "@SUM(A1)"})
    EXPECT_NE(UnsafeIdReason(id).find("formula"), std::string::npos) << id;
  EXPECT_NE(UnsafeIdReason("a\u202Eb").find("U+202E"), std::string::npos);
  EXPECT_NE(UnsafeIdReason("a\u2066b").find("U+2066"), std::string::npos);
  EXPECT_NE(UnsafeIdReason("a\u200Fb").find("U+200F"), std::string::npos);
  EXPECT_NE(UnsafeIdReason("a\u061Cb").find("U+061C"), std::string::npos);
  EXPECT_EQ(UnsafeIdReason("a\u2022b"), "");  // a bullet (E2 80 A2) is not a control
}

// Text that pandas or R reads as a missing value or an infinite number (checked against pandas.read_csv by hand: an
// id column holding Infinity becomes float inf, NA and nan become NaN) is no name: a pattern id Infinity stopped the
// report with exit 10, a participant NA would be dropped as missing (issue 24).
TEST(UnsafeIdReason, WhatTheTablesReadersTakeAsMissingOrInfiniteIsRefused) {
  for (const char* id : {"Infinity", "infinity", "INF", "inf", "NaN", "nan", "NAN", "NA", "na", "null", "NULL", "None",
                         "N/A", "#N/A", "<NA>", "1.#IND"})
    EXPECT_NE(UnsafeIdReason(id).find("missing value or an infinite number"), std::string::npos) << id;
  for (const char* id : {"NA1", "Nancy", "info", "Infinite", "P_nan", "n.a."}) EXPECT_EQ(UnsafeIdReason(id), "") << id;
}

TEST(Utf8Length, CountsCodePoints) {
  EXPECT_EQ(Utf8Length(""), 0u);
  EXPECT_EQ(Utf8Length("abc"), 3u);
  EXPECT_EQ(Utf8Length("\u00e9\u00e9"), 2u);      // 4 bytes
  EXPECT_EQ(Utf8Length("\u6f22\U0001F600"), 2u);  // 3 + 4 bytes
}

}  // namespace
}  // namespace blurcue
