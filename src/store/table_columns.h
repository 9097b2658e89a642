#pragma once
// A table of the record beside trials.csv's (frames, procedures) as one list of columns: each column once - its
// codebook definition (ColumnSpec), where the record keeps it (SQL type, CHECK, the schema version that added it) and
// how the record's INSERT reads it from the row the session hands the store, and how the table's CSV selects and
// writes its cell. Generated from the list: the migration's columns (ALTER TABLE ... ADD COLUMN, or a new table's
// CREATE TABLE), the record's INSERT, merge's copy, the CSV's header, SELECT and cells, and the codebook's rows. A
// column of the CSV read from another table (the session's, the trial's) is in the list too, with its SQL (select)
// and no SQL type: a declared join, not a column of the table. trials.csv's columns are columns.h's Column (they
// are spread over several tables); this is the same idea for a table of one kind of row.
#include <functional>
#include <string>
#include <vector>

#include "store/columns.h"
#include "store/sqlite.h"

namespace blurcue::store {

class Statement;

// The cell of column `at` of `rows` as a CSV writes it: kInteger its digits, kNumber the shortest text that reads back
// the same, otherwise the text; NULL empty.
std::string CellText(Statement& rows, int at, enum Cell cell);
// Copies column `at` of `from` (NULL or of SQL type `sql`: INTEGER | REAL | TEXT) to parameter `to_at` of `to`.
void CopyCell(const std::string& sql, Statement& from, int at, Statement& to, int to_at);
// The codebook's row (table, column, type, unit, allowed, meaning, role) of `column` of `table` (e.g. "frames.csv").
std::string CodebookRow(const std::string& table, const ColumnSpec& column, const std::string& role = "");

template <typename Row>
struct TableColumn : ColumnSpec {
  std::string sql;        // INTEGER | REAL | TEXT; "" = not kept in the table: the CSV reads it through `select`
  std::string check;      // the CHECK expression; "" for none
  bool required = false;  // NOT NULL (a column a new table's CREATE makes; one added later cannot be)
  int since = 0;          // the schema version that added it to the table
  std::function<Value(const Row&)> of;  // what the record writes (a kept column of a row the record inserts)
  std::string select;                   // the export's SQL for its cell; "" = ALIAS.NAME of the table's own column
  bool exported = true;                 // false: kept in the table only (no CSV column, no codebook row)
  // How the CSV writes the cell: kText, kInteger or kNumber (NULL: empty); for a kept column its SQL type's.
  enum Cell cell = Cell::kText;
};

// Fills each kept column's cell from its SQL type (TEXT: text, REAL: number, INTEGER: integer).
template <typename Row>
std::vector<TableColumn<Row>> WithCells(std::vector<TableColumn<Row>> columns) {
  for (TableColumn<Row>& c : columns)
    if (!c.sql.empty()) c.cell = c.sql == "TEXT" ? Cell::kText : c.sql == "REAL" ? Cell::kNumber : Cell::kInteger;
  return columns;
}

// "NAME TYPE [NOT NULL] [CHECK (...)]" of a kept column.
template <typename Row>
std::string ColumnSql(const TableColumn<Row>& c) {
  return c.name + " " + c.sql + (c.required ? " NOT NULL" : "") + (c.check.empty() ? "" : " CHECK (" + c.check + ")");
}

// "ALTER TABLE TABLE ADD COLUMN ...;" for the columns schema version `version` added to `table`.
template <typename Row>
std::string AddTableColumnsSql(const std::string& table, const std::vector<TableColumn<Row>>& columns, int version) {
  std::string sql;
  for (const TableColumn<Row>& c : columns)
    if (!c.sql.empty() && c.since == version) sql += "ALTER TABLE " + table + " ADD COLUMN " + ColumnSql(c) + ";";
  return sql;
}

// ", a TYPE ..., b TYPE ..." for the columns version `version` made with its CREATE TABLE (after its keys).
template <typename Row>
std::string CreatedColumnsSql(const std::vector<TableColumn<Row>>& columns, int version) {
  std::string sql;
  for (const TableColumn<Row>& c : columns)
    if (!c.sql.empty() && c.since == version) sql += ", " + ColumnSql(c);
  return sql;
}

// The kept columns, in the table's order.
template <typename Row>
std::vector<const TableColumn<Row>*> KeptColumns(const std::vector<TableColumn<Row>>& columns) {
  std::vector<const TableColumn<Row>*> kept;
  for (const TableColumn<Row>& c : columns)
    if (!c.sql.empty()) kept.push_back(&c);
  return kept;
}

// "INSERT INTO TABLE (KEY, a, b) VALUES (?, ?, ?)": the key (the row's parent id) bound first, then the kept columns
// (BindRow). `verb`: INSERT, or INSERT OR IGNORE to keep a row already there.
template <typename Row>
std::string InsertSql(const std::string& table, const std::string& key, const std::vector<TableColumn<Row>>& columns,
                      const std::string& verb = "INSERT") {
  std::string names = key, marks = "?";
  for (const TableColumn<Row>* c : KeptColumns(columns)) names += ", " + c->name, marks += ", ?";
  return verb + " INTO " + table + " (" + names + ") VALUES (" + marks + ")";
}

// Binds a row's kept columns from parameter `first` on.
template <typename Row>
void BindRow(const std::vector<TableColumn<Row>>& columns, Statement& insert, int first, const Row& row) {
  for (const TableColumn<Row>* c : KeptColumns(columns)) BindValue(insert, first++, c->of(row));
}

// ", a, b" of the kept columns for a SELECT over an input of schema `version` (NULL for a column it predates): merge's
// read; the INSERT is InsertSql's, bound by CopyKept.
template <typename Row>
std::string CopySelect(const std::vector<TableColumn<Row>>& columns, int version) {
  std::string list;
  for (const TableColumn<Row>* c : KeptColumns(columns)) list += ", " + (version >= c->since ? c->name : "NULL");
  return list;
}
// Binds the kept columns read by CopySelect (from column `first` of `from`) to `to`, from parameter `at`, by type.
template <typename Row>
void CopyKept(const std::vector<TableColumn<Row>>& columns, Statement& from, int first, Statement& to, int at) {
  for (const TableColumn<Row>* c : KeptColumns(columns)) CopyCell(c->sql, from, first++, to, at++);
}

// The CSV's columns (exported), in order.
template <typename Row>
std::vector<const TableColumn<Row>*> CsvColumns(const std::vector<TableColumn<Row>>& columns) {
  std::vector<const TableColumn<Row>*> out;
  for (const TableColumn<Row>& c : columns)
    if (c.exported) out.push_back(&c);
  return out;
}

// The CSV's SELECT list: each exported column's `select`, else ALIAS.NAME.
template <typename Row>
std::string CsvSelect(const std::vector<TableColumn<Row>>& columns, const std::string& alias) {
  std::string select;
  for (const TableColumn<Row>* c : CsvColumns(columns))
    select += (select.empty() ? "" : ", ") + (c->select.empty() ? alias + "." + c->name : c->select);
  return select;
}

// The CSV's header line and its rows' cells, over a statement whose columns are CsvSelect's.
template <typename Row>
std::vector<std::string> CsvHeader(const std::vector<TableColumn<Row>>& columns) {
  std::vector<std::string> header;
  for (const TableColumn<Row>* c : CsvColumns(columns)) header.push_back(c->name);
  return header;
}
template <typename Row>
std::vector<std::string> CsvCells(const std::vector<TableColumn<Row>>& columns, Statement& rows) {
  std::vector<std::string> cells;
  int at = 0;
  for (const TableColumn<Row>* c : CsvColumns(columns)) cells.push_back(CellText(rows, at++, c->cell));
  return cells;
}

// The codebook's rows of the CSV `file` (one per exported column).
template <typename Row>
std::string CsvCodebook(const std::string& file, const std::vector<TableColumn<Row>>& columns) {
  std::string rows;
  for (const TableColumn<Row>* c : CsvColumns(columns)) rows += CodebookRow(file, *c);
  return rows;
}

}  // namespace blurcue::store
