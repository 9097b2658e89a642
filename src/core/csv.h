#pragma once
// A CSV file as spreadsheets write it (RFC 4180): fields separated by commas; records ended by CRLF, LF or a lone
// CR (old Mac Excel); a field in double quotes may hold commas, quotes written "" and line breaks; a UTF-8 byte order
// mark (Excel's "CSV UTF-8", Notepad) is not part of the first field. Empty lines are skipped. Every problem names
// its line and column, counted from 1 as an editor counts them, once.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace blurcue {

struct CsvRecord {
  size_t line = 0;  // where the record starts, from 1
  std::vector<std::string> fields;
};

struct CsvProblem {
  size_t line = 0, column = 0;  // from 1; column counts characters (UTF-8 code points) within the line
  std::string message;          // "a quote inside a field that does not start with one", ...
};

struct CsvText {
  std::vector<CsvRecord> records;  // the header first
  std::vector<CsvProblem> problems;
};

// Splits `text` into records. Stops after `max_records` records (the caller says the limit in its own words when
// records.size() exceeds it) and at the first malformed quote (text after a closing quote, a quote inside an
// unquoted field, a quote still open at the end of the file: each names where it is).
CsvText ParseCsv(std::string_view text, size_t max_records);

// Throws Error(kInput) "FILE: line N: has 3 fields, the header 19 ..." for the first record after the header with
// another number of fields than the header: a row cut short (a file truncated mid-line, its last line without its
// line break) or run together. For tables whose every row has every column (track.csv).
void RequireFullRecords(const CsvText& csv, const std::string& file);

}  // namespace blurcue
