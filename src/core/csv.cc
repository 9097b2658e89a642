#include "core/csv.h"

#include "core/error.h"

namespace blurcue {
namespace {

bool IsContinuationByte(char c) { return (static_cast<unsigned char>(c) & 0xC0) == 0x80; }

}  // namespace

CsvText ParseCsv(std::string_view text, size_t max_records) {
  CsvText out;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  size_t line = 1, column = 1;  // of text[i]
  size_t i = 0;
  auto problem = [&](size_t at_line, size_t at_column, std::string message) {
    out.problems.push_back({at_line, at_column, std::move(message)});
  };
  // Advances past text[i], keeping line and column; a CRLF counts as one line break.
  auto advance = [&] {
    const char c = text[i++];
    if (c == '\n' || (c == '\r' && (i >= text.size() || text[i] != '\n'))) {
      ++line;
      column = 1;
    } else if (c != '\r' && !IsContinuationByte(c)) {
      ++column;
    }
  };
  auto at_record_end = [&] { return i >= text.size() || text[i] == '\n' || text[i] == '\r'; };
  auto skip_break = [&] {
    if (i < text.size() && text[i] == '\r') advance();
    if (i < text.size() && text[i] == '\n') advance();
  };
  while (i < text.size()) {
    if (at_record_end()) {  // an empty line
      skip_break();
      continue;
    }
    CsvRecord record;
    record.line = line;
    while (true) {
      std::string field;
      if (i < text.size() && text[i] == '"') {
        const size_t open_line = line, open_column = column;
        advance();
        bool closed = false;
        while (i < text.size()) {
          if (text[i] == '"') {
            if (i + 1 < text.size() && text[i + 1] == '"') {
              field += '"';
              advance();
              advance();
              continue;
            }
            advance();
            closed = true;
            break;
          }
          field += text[i];
          advance();
        }
        if (!closed) {
          problem(open_line, open_column, "a quoted field is not closed before the end of the file (a quote inside "
                                          "a quoted field is written \"\")");
          return out;
        }
        if (!at_record_end() && text[i] != ',') {
          problem(line, column, "text after a field's closing quote (put the whole field in quotes and write a "
                                "quote inside it as \"\")");
          return out;
        }
      } else {
        while (!at_record_end() && text[i] != ',') {
          if (text[i] == '"') {
            problem(line, column, "a quote inside a field that does not start with one (put the whole field in "
                                  "quotes and write a quote inside it as \"\")");
            return out;
          }
          field += text[i];
          advance();
        }
      }
      record.fields.push_back(std::move(field));
      if (i < text.size() && text[i] == ',') {
        advance();
        continue;
      }
      break;
    }
    skip_break();
    out.records.push_back(std::move(record));
    if (out.records.size() > max_records) return out;
  }
  return out;
}

void RequireFullRecords(const CsvText& csv, const std::string& file) {
  if (csv.records.empty()) return;
  const size_t want = csv.records.front().fields.size();
  for (size_t k = 1; k < csv.records.size(); ++k) {
    const CsvRecord& r = csv.records[k];
    if (r.fields.size() == want) continue;
    throw InputError(file + ": line " + std::to_string(r.line),
                     "has " + std::to_string(r.fields.size()) + " fields, the header " + std::to_string(want) +
                         (r.fields.size() < want ? ": the row is cut short (a truncated file, or an edit)"
                                                 : ": the row has more fields than the header names"));
  }
}

}  // namespace blurcue
