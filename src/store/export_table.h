#pragma once
// What the export's writers share (store-internal): a column's codebook definition, cells and CSV lines, and the
// tables beside trials.csv (summaries, adjustments, frames) with their codebook rows.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "store/columns.h"
#include "store/export.h"
#include "store/sqlite.h"
#include "store/table_columns.h"

namespace blurcue::store {

// A column of an exported table as the codebook says it (ColumnSpec), with a design column's role. The tables are
// written from these definitions and the codebook is written from the same ones, so the two cannot drift.
struct ColumnDef : ColumnSpec {
  std::string role = "";  // a design's column: within, group, procedure_cell, label or practice (the design table's)
};



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
// One step of a trial's recorded adjustment (responses.adjustment: [{"level": L, "t_ms": T}, ...]) with its trial.
struct AdjustmentStep {
  const std::string& study;
  const std::string& participant;
  int64_t session, trial;
  size_t index;      // from 0
  const Json& step;  // the step as recorded
};
// A column of adjustments.csv, defined once: its codebook definition and how its cell is read from a step (a
// recorded value by export.cc's TidyCell). Its header, cells and codebook rows are generated from the list.
struct AdjustmentColumn : ColumnSpec {
  std::function<std::string(const AdjustmentStep&)> cell;
};
const std::vector<AdjustmentColumn>& AdjustmentColumns();
// OUT/frames.csv: every recorded display flip, one row each (frame_columns.h FrameColumns): what each frame showed of
// a pair, empty where nothing was shown and for pictures.
void WriteFrames(Database& db, const std::filesystem::path& out_dir);

}  // namespace blurcue::store
