// What every one-list table (table_columns.h) shares that is no template: binding, copying and writing a cell.
#include "store/table_columns.h"

#include <charconv>

#include "store/sqlite.h"

namespace blurcue::store {

void BindValue(Statement& insert, int index, const Value& value) {
  if (const auto* i = std::get_if<int64_t>(&value))
    insert.Bind(index, *i);
  else if (const auto* d = std::get_if<double>(&value))
    insert.Bind(index, *d);
  else if (const auto* t = std::get_if<std::string>(&value))
    insert.Bind(index, *t);
  else
    insert.BindNull(index);
}

std::string CellText(Statement& rows, int at, enum Cell cell) {
  if (rows.IsNull(at)) return "";
  switch (cell) {
    case Cell::kInteger:
      return std::to_string(rows.GetInt64(at));
    case Cell::kNumber: {
      // The shortest text that reads back as the same double.
      char text[64];
      const auto result = std::to_chars(text, text + sizeof(text), rows.GetDouble(at));
      return std::string(text, result.ptr);
    }
    case Cell::kText:
    case Cell::kSeed:
    case Cell::kAnswer:
      break;
  }
  return rows.GetText(at);
}

void CopyCell(const std::string& sql, Statement& from, int at, Statement& to, int to_at) {
  if (from.IsNull(at))
    to.BindNull(to_at);
  else if (sql == "TEXT")
    to.Bind(to_at, from.GetText(at));
  else if (sql == "REAL")
    to.Bind(to_at, from.GetDouble(at));
  else
    to.Bind(to_at, from.GetInt64(at));
}

}  // namespace blurcue::store
