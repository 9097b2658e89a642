#pragma once
// What the export's writers share (store-internal): a column's codebook definition, cells and CSV lines, and the
// tables beside trials.csv (summaries, adjustments, frames) with their codebook rows.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "store/columns.h"
#include "store/export.h"
#include "store/sqlite.h"

namespace blurcue::store {

// A column of an exported table as the codebook says it (ColumnSpec), with a design column's role. The tables are
// written from these definitions and the codebook is written from the same ones, so the two cannot drift.
struct ColumnDef : ColumnSpec {
  std::string role = "";  // a design's column: within, group, procedure_cell, label or practice (the design table's)
};

// The codebook's row (table, column, type, unit, allowed, meaning, role) of `column` of `table` (e.g. "frames.csv").
std::string CodebookRow(const std::string& table, const ColumnSpec& column, const std::string& role = "");


// A JSON value as a cell: strings bare, null empty, anything else as compact JSON.
std::string Cell(const Json& value);
// `text` parsed as JSON; Error(kInput) naming `where` when it is not.
Json ParseColumn(const std::string& text, const std::string& where);
// Shortest text that reads back as the same double.
std::string Number(double value);
// "DB: session S trial T", for messages.
std::string Where(const std::filesystem::path& db, int64_t session, int64_t trial);
// What an export folder may hold and still be replaced as a whole: the files an export writes, and the
// temporaries an earlier version left beside them when killed (FILE.csv.tmpPID).
bool IsExportFile(const std::string& name);
// Tells `note` of each leftover removed.
void Note(const ProgressNote& note, const std::vector<std::filesystem::path>& removed);
// One CSV line (CRLF) of `cells`, each through CsvField.
std::string CsvLine(const std::vector<std::string>& cells);
// Removes a database file and its -wal, -shm and -journal (never throws).
void RemoveDatabaseFiles(const std::filesystem::path& path);

struct Column;
// ExportCsv with the record's columns given (RecordColumns(), or a test's table with a column more).
int64_t ExportCsvWith(const std::vector<Column>& table, const std::filesystem::path& db_path,
                      const std::filesystem::path& out_dir, const ProgressNote& note);

// Per study, one row per session: trials planned and answered (practice apart), the median response time, and
// how often each answer was given - for forced choice the source chosen (the one shown on the side picked) or
// cant_tell, for adjustment the level accepted. Writes OUT/SummaryFileName(STUDY) for every study and returns the
// codebook's rows for them.
std::string WriteSummaries(Database& db, const std::filesystem::path& out_dir);
// A column of frames.csv, defined once: its codebook row, what the export selects for it (SQL over f = frames, t, s,
// p, st) and how its cell is written (kText, kInteger, kNumber; NULL: empty). Its header, SELECT, cells and codebook
// rows are generated from this table.
struct FrameColumn {
  ColumnDef def;
  std::string select;
  enum Cell cell = Cell::kText;  // the enum (columns.h), which the function Cell below hides
};
// The columns of adjustments.csv and frames.csv, for their writers and the codebook.
const std::vector<ColumnDef>& AdjustmentColumns();
const std::vector<FrameColumn>& FrameColumns();
// OUT/frames.csv: every recorded display flip, one row each (FrameColumns): what each frame showed of a pair, empty
// where nothing was shown and for pictures.
void WriteFrames(Database& db, const std::filesystem::path& out_dir);

}  // namespace blurcue::store
