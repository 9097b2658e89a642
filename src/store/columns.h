#pragma once
// The record's columns as one table: every variable of a trial's row of trials.csv, defined once - its name, type,
// unit, allowed values, meaning, where trials.csv puts it and how it is read (a column of the record, a variable the
// runner records with the trial, or the answer) - with the typed columns the record keeps it in. Generated from it:
// the schema's typed columns (the migrations to versions 7 and 8, and how version 7 fills them in older rows), the
// record's INSERT of a session's, a trial's and a response's typed columns, the export's SELECT and cells, the
// codebook's rows, the names a design's level may not take (IsRecordedName) and the merge's column lists. Values the
// protocol allows (levels, ranges, choices) are not here: the design table (design_columns) gives them per protocol
// version. The tables beside trials.csv have one list each: frames (frame_columns.h) and procedures (procedures.h)
// through table_columns.h, adjustments.csv's in export_table.h; the summaries' are written with them.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/json_io.h"
#include "protocol/vocabulary.h"

namespace blurcue::store {

struct TrialRecord;
struct Response;
struct SessionMeta;
class Statement;

// Where trials.csv writes a column: with the session (before the group and info_KEY columns), with the trial (before
// the design's variables), among the design's variables (sorted with the levels; a cell only where the trial recorded
// it), with the answer (after them), or nowhere (a typed column the record keeps for readers of the file).
enum class Place { kSession, kTrial, kVariable, kAnswer, kNone };

// How a cell is written from the value the export's SELECT reads: as text, an integer, a number (the shortest text
// that reads back the same), the seed ("s" and its unsigned digits); NULL writes Column::if_null. kAnswer: decided
// from the answer (Column::answer). A variable's cell is its JSON value (export.cc TidyCell).
enum class Cell { kText, kInteger, kNumber, kSeed, kAnswer };

// The cells decided from the answer when it is exported: one column per kind of answer, each of one type.
enum class Answer { kNone, kStatus, kChosenSide, kChoseMoreBlurred, kChosenInterval, kYesNo, kRating, kAdjustedLevel };

// What the codebook says of a column - the part every table of the record and its exports shares (trials.csv's
// columns below, the TableColumn of frames.csv and procedures.csv, adjustments.csv's AdjustmentColumn): its name in the table
// and the CSV, its type (string | integer | number | boolean: 0|1 | datetime: ISO 8601 UTC), unit, allowed values
// and meaning. A table's header and its codebook rows are written from the same ColumnSpec (CodebookRow).
struct ColumnSpec {
  std::string name, type, unit, allowed, meaning;
};

// A value for a typed column: NULL, an integer, a number or a text.
using Value = std::variant<std::monostate, int64_t, double, std::string>;
// Binds a value to parameter `index` of `insert` (NULL for none).
void BindValue(Statement& insert, int index, const Value& value);

// The name of a column of one side's (or the scene's) quantity, QUANTITY_SIDE_SUFFIX with the side's word
// (protocol::Side's, or scene): r_left_px, floor_sigma_right_screen_px, motion_left_x_px, u_right_mm. The one place
// every per-side column of the record and its exports is named, for both sides.
std::string SideColumn(const std::string& quantity, const std::string& side, const std::string& suffix);
std::string SideColumn(const std::string& quantity, protocol::Side side, const std::string& suffix);

// What the runner records of one object of a pair beside its radius (RecordedVariables::r_px): the PSF's other parts
// (render/psf.h) - the lens floor inside the radius (std) and the streak's x and y on the screen - where it is (its
// centre's depth u along the camera's optical axis, mm, and its elevation on the display, deg of visual angle, up
// positive, from the photo's principal point) and its largest extent on screen at onset (deg).
struct SideVariables {
  std::optional<double> floor_sigma_px, floor_sigma_screen_px, motion_x_screen_px, motion_y_screen_px, u_mm,
      elevation_deg, size_deg;
};

// What a new session's typed columns are read from: its description, its display profile parsed, its number.
struct SessionValues {
  const SessionMeta& meta;
  const Json& profile;
  int64_t number;
};

// What the runner records of a trial beside its levels, typed: the variables' JSON of a trial (planned), and of a
// response (as a procedure decided it at the trial, or why a trial was skipped). Each member is read by one column of
// RecordColumns() (Column::variable), whose name is its key in the JSON: the keys, trials.csv's columns and the
// codebook's rows are that one table. Unset: not recorded for this trial.
struct RecordedVariables {
  std::optional<bool> practice, swapped, correct;  // recorded 1 | 0
  std::optional<std::string> block_name, test_side, adjust_levels, kernel, blur_plan, skipped;
  std::optional<int64_t> round, procedure_cell, odd_interval, intervals, reversals;
  std::optional<double> level, start_level, picture_width_arcmin, screen_px_per_photo_px, r_span_screen_px,
      brightness, contrast, white_balance_r, white_balance_g, white_balance_b, posterior_threshold, posterior_slope;
  // Each radius of the kSides places (protocol::Index(side) for the two sides, kScene for the scene; SideName spells
  // them) as the camera made it (photo px), on the screen (screen px) and at the eye (arcmin).
  static constexpr size_t kSides = 3, kScene = 2;
  // A place's word in the column names: protocol::Side's for the sides, scene for the scene.
  static std::string SideName(size_t k);
  std::array<std::optional<double>, kSides> r_px, r_screen_px, r_arcmin;
  // The exposure a moving object's streak lasts, and the rest of what each side's object shows, indexed by
  // protocol::Index(side).
  std::optional<double> exposure_ms;
  std::array<SideVariables, 2> sides;
};

// The JSON the record keeps `variables` in: {NAME: value} for each member set, NAME its column's.
Json VariablesJson(const RecordedVariables& variables);

// A column of the record that keeps a variable: its table, SQL type and CHECK, and the schema version that added it.
// Columns of version 7 on (the typed record) are added by migrations generated from this table, written by the
// record's INSERTs through `of_*` (the one of its table) and copied by merge (but for the session number, which merge
// gives again); older ones (`since` < 7) are the shipped migrations' and the record writes them itself.
struct Stored {
  std::string table;   // "" (not kept), studies, protocol_versions, participants, sessions, trials or responses
  std::string column;  // "" = the variable's name
  std::string sql;     // TEXT | REAL | INTEGER
  std::string check;   // the CHECK expression, "" for none
  int since = 0;
  // Version 7: how a row written before it had the value (SQL over the row's older texts: the display, the display
  // profile, the variables' JSON), for DeriveTypedColumns; "" for none.
  std::string derive;
  std::function<Value(const SessionValues&)> of_session;
  std::function<Value(const TrialRecord&)> of_trial;
  std::function<Value(const Response&)> of_response;
};

// A column of trials.csv: its codebook definition (ColumnSpec; `allowed` is what the record allows, and a variable of
// type string without it lists the values seen), where the CSV puts it and how it is read and kept.
struct Column : ColumnSpec {
  Place place = Place::kNone;
  Cell cell = Cell::kText;
  std::string select;   // the export's SQL over st, pv, p, s, t, r; "" = the kept column (at), e.g. t.block_name
  std::string if_null;  // the cell of a NULL
  Answer answer = Answer::kNone;
  // Where the record keeps it, and for a trial's variable decided when the trial is shown, the response's copy.
  Stored at, shown;
  // Also in the trial's variables (factors or shown JSON), written there by the runner: exported from the typed
  // column, not from there.
  bool in_variables = false;
  // A variable the runner records (a Place::kVariable column, or in_variables): its member of RecordedVariables, as
  // JSON (null when unset).
  std::function<Json(const RecordedVariables&)> variable;
};

// The record's columns, in the order schema 7 added the typed ones within each table (trials.csv orders by place).
const std::vector<Column>& RecordColumns();

// The column's SQL name in its table (Stored::column, else its name), and the alias the export reads it under.
std::string ColumnName(const Column& column, const Stored& stored);
// What the export selects for `column`: Column::select, else ALIAS.COLUMN of where it is kept.
std::string SelectOf(const Column& column);

// One column of the record kept in `table` by `columns` (at or shown), with its definition.
struct Kept {
  const Column* column;
  const Stored* stored;
  std::string name;  // its SQL name
};
// The columns `columns` keep in `table` that version `since` or later added (>= 7: the typed record), in order.
std::vector<Kept> KeptIn(const std::vector<Column>& columns, const std::string& table, int since);

// The SQL that adds the columns version `version` brought to sessions, trials, responses and protocol_versions
// ("ALTER TABLE T ADD COLUMN C TYPE CHECK (...);" each).
std::string AddColumnsSql(const std::vector<Column>& columns, int version);

// "a = DERIVE, b = DERIVE" for the columns of `table` version 7 added: DeriveTypedColumns' UPDATE.
std::string DerivedColumnsSql(const std::vector<Column>& columns, const std::string& table);

// ", a, b" and ", ?, ?" for the typed columns (version 7 on) of `table`: the INSERT's part this table generates.
std::string InsertNames(const std::vector<Column>& columns, const std::string& table);
std::string InsertPlaceholders(const std::vector<Column>& columns, const std::string& table);
// Binds a new row's typed columns of sessions, trials or responses from its values, from parameter `first` on.
void BindTyped(const std::vector<Column>& columns, Statement& insert, int first, const SessionValues& session);
void BindTyped(const std::vector<Column>& columns, Statement& insert, int first, const TrialRecord& trial);
void BindTyped(const std::vector<Column>& columns, Statement& insert, int first, const Response& response);

}  // namespace blurcue::store
