#include "store/columns.h"

#include <algorithm>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "store/export.h"
#include "store/export_table.h"
#include "store/frame_columns.h"
#include "store/procedures.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

using testing::ReadCsv;
using testing::Rows;

// The columns SQLite says `table` has in `db`, with their declared types.
std::map<std::string, std::string> TableColumns(Database& db, const std::string& table) {
  std::map<std::string, std::string> columns;
  Statement info(db, "SELECT name, type FROM pragma_table_info('" + table + "')");
  while (info.Step()) columns[info.GetText(0)] = info.GetText(1);
  return columns;
}

// A database migrated to `version` by the shipped steps.
void MigrateTo(Database& db, int version) {
  for (int i = 0; i < version; ++i) {
    const Migration& step = Migrations()[size_t(i)];
    if (!step.sql.empty()) db.Exec(step.sql);
    if (step.data) step.data(db);
  }
}

// A record with one session of one trial (a level edge, two recorded variables) answered, exported to `out`.
void OneAnsweredTrial(const std::filesystem::path& db_path) {
  Record record = Record::Open(db_path);
  SessionMeta meta;
  meta.simulated = true;
  meta.observer_params = "sim:model=arcmin";
  meta.window = false;
  meta.display_profile = R"({"name":"lab","width_mm":531.4})";
  const int64_t session = record.StartOrResumeSession("s", "P1", R"({"study":"s"})", 7, meta, false).session_id;
  TrialRecord t;
  t.factors_json = R"({"block_name":"b","edge":9,"kernel":"gaussian","practice":0,"r_left_px":3.5,"swapped":0})";
  t.source_json[0] = R"("measured")";
  t.source_json[1] = R"({"screen_px":2.5})";
  t.block_name = "b";
  t.task = "forced_choice";
  t.r_px[0] = 3.5;
  t.r_px[1] = 1.25;
  record.SaveTrialList(session, {t});
  Response r;
  r.choice = "left";
  r.rt_ms = 512;
  r.answered_at = "2026-01-02T03:04:05.000Z";
  r.correct = true;
  record.RecordResponse(session, 0, r);
  record.FinishSession(session, SessionStatus::kCompleted);
}

// The codebook's rows of trials.csv, by column name: how often each is defined, and its type|unit|allowed|meaning.
std::map<std::string, std::vector<std::string>> CodebookOfTrials(const std::filesystem::path& codebook) {
  std::map<std::string, std::vector<std::string>> rows;
  for (const auto& row : ReadCsv(codebook))
    if (row.at(0) == "trials.csv") rows[row.at(1)].push_back(row.at(2) + "|" + row.at(3) + "|" + row.at(4) + "|" + row.at(5));
  return rows;
}

TEST(Columns, EachNameIsDefinedOnce) {
  std::set<std::string> names;
  for (const Column& c : RecordColumns()) EXPECT_TRUE(names.insert(c.name).second) << c.name << " is defined twice";
  // Every column read from the answer says which answer; every other one written by a SELECT says from where.
  for (const Column& c : RecordColumns()) {
    EXPECT_EQ(c.cell == Cell::kAnswer, c.answer != Answer::kNone) << c.name;
    if (c.place != Place::kVariable && c.place != Place::kNone && c.cell != Cell::kAnswer) {
      EXPECT_FALSE(c.select.empty() && c.at.table.empty()) << c.name << " is read from nowhere";
    }
    // A column of the typed record says how a row of an older record gets it (DeriveTypedColumns).
    for (const Stored* stored : {&c.at, &c.shown}) {
      if (stored->since == 7) {
        EXPECT_FALSE(stored->derive.empty()) << c.name << " in " << stored->table;
      }
    }
  }
}

// Migrations once shipped never change: versions 7 and 8 are generated from the table now, and must still add these
// columns, in this order, with these types and checks (the SQL the shipped lists made).
TEST(Columns, TheShippedTypedMigrationsAreGeneratedUnchanged) {
  EXPECT_EQ(AddColumnsSql(RecordColumns(), 7),
            "ALTER TABLE sessions ADD COLUMN observer TEXT CHECK (observer IN ('person', 'simulated'));"
            "ALTER TABLE sessions ADD COLUMN observer_params TEXT;"
            "ALTER TABLE sessions ADD COLUMN window INTEGER CHECK (window IN (0, 1));"
            "ALTER TABLE sessions ADD COLUMN profile_name TEXT;"
            "ALTER TABLE sessions ADD COLUMN screen_width_mm REAL;"
            "ALTER TABLE sessions ADD COLUMN screen_height_mm REAL;"
            "ALTER TABLE sessions ADD COLUMN viewing_distance_mm REAL;"
            "ALTER TABLE sessions ADD COLUMN px_per_deg REAL;"
            "ALTER TABLE trials ADD COLUMN block_name TEXT;"
            "ALTER TABLE trials ADD COLUMN task TEXT;"
            "ALTER TABLE trials ADD COLUMN practice INTEGER CHECK (practice IN (0, 1));"
            "ALTER TABLE trials ADD COLUMN swapped INTEGER CHECK (swapped IN (0, 1));"
            "ALTER TABLE trials ADD COLUMN left_source TEXT;"
            "ALTER TABLE trials ADD COLUMN left_fixed REAL;"
            "ALTER TABLE trials ADD COLUMN right_source TEXT;"
            "ALTER TABLE trials ADD COLUMN right_fixed REAL;"
            "ALTER TABLE trials ADD COLUMN r_left_px REAL;"
            "ALTER TABLE trials ADD COLUMN r_right_px REAL;"
            "ALTER TABLE trials ADD COLUMN r_scene_px REAL;"
            "ALTER TABLE responses ADD COLUMN level REAL;"
            "ALTER TABLE responses ADD COLUMN correct INTEGER CHECK (correct IN (0, 1));"
            "ALTER TABLE responses ADD COLUMN r_left_px REAL;"
            "ALTER TABLE responses ADD COLUMN r_right_px REAL;");
  EXPECT_EQ(AddColumnsSql(RecordColumns(), 8),
            "ALTER TABLE protocol_versions ADD COLUMN version INTEGER CHECK (version >= 1);"
            "ALTER TABLE sessions ADD COLUMN session_number INTEGER CHECK (session_number >= 1);"
            "ALTER TABLE trials ADD COLUMN cell TEXT;");
  // And they are what the migrations run.
  EXPECT_EQ(Migrations().at(6).sql.rfind(AddColumnsSql(RecordColumns(), 7), 0), 0u);
  EXPECT_EQ(Migrations().at(7).sql.rfind(AddColumnsSql(RecordColumns(), 8), 0), 0u);
}

// What SQLite finds in a fresh record: every column the table says is kept is there with its type, and every column
// the typed record (version 7 on) added is one the table defines.
TEST(Columns, TheTableNamesEveryTypedColumnOfAFreshRecord) {
  Database fresh(":memory:"), six(":memory:");
  Migrate(fresh);
  MigrateTo(six, 6);
  for (const Column& c : RecordColumns())
    for (const Stored* stored : {&c.at, &c.shown}) {
      if (stored->table.empty()) continue;
      const auto columns = TableColumns(fresh, stored->table);
      const auto it = columns.find(ColumnName(c, *stored));
      ASSERT_NE(it, columns.end()) << c.name << ": no " << stored->table << "." << ColumnName(c, *stored);
      EXPECT_EQ(it->second, stored->sql) << c.name;
      // A column of the shipped versions 1-6 is found in a record of version 6; one of 7 on is not.
      EXPECT_EQ(TableColumns(six, stored->table).count(ColumnName(c, *stored)) > 0, stored->since < 7) << c.name;
    }
  for (const char* table : {"protocol_versions", "sessions", "trials", "responses"}) {
    std::set<std::string> added, defined;
    const auto before = TableColumns(six, table);
    for (const auto& [name, type] : TableColumns(fresh, table))
      if (!before.count(name)) added.insert(name);
    for (const Kept& kept : KeptIn(RecordColumns(), table, 7)) defined.insert(kept.name);
    EXPECT_EQ(added, defined) << table;
  }
}

// trials.csv's header as shipped (the analysis reads these names), and a codebook row for each of its columns, as the
// table defines it.
TEST(Columns, TrialsCsvAndItsCodebookFollowTheTable) {
  testing::TempDir dir;
  OneAnsweredTrial(dir / "r.sqlite");
  ASSERT_EQ(ExportCsv(dir / "r.sqlite", dir / "out"), 1);
  const Rows trials = ReadCsv(dir / "out" / "trials.csv");
  const std::vector<std::string> shipped = {
      "study", "protocol_hash", "protocol_version", "participant", "observer", "observer_params", "window",
      "session_id", "session_number", "session_status", "seed", "trial_index", "block", "block_name", "task",
      "practice", "swapped", "cell", "edge", "kernel", "r_left_px", "left_source", "left_fixed", "right_source",
      "right_fixed", "status", "chosen_side", "chose_more_blurred", "chosen_interval", "yes_no", "rating",
      "adjusted_level", "correct", "rt_ms", "answered_at"};
  ASSERT_EQ(trials.at(0), shipped);
  std::map<std::string, std::string> row;
  for (size_t i = 0; i < shipped.size(); ++i) row[shipped[i]] = trials.at(1).at(i);
  // Each cell read as the table says: typed columns, the seed's text, the answer decided from the choice and radii.
  EXPECT_EQ(row["observer"], "simulated");
  EXPECT_EQ(row["window"], "0");
  EXPECT_EQ(row["seed"], "s7");
  EXPECT_EQ(row["block_name"], "b");
  EXPECT_EQ(row["right_source"], "fixed_screen_px");
  EXPECT_EQ(row["right_fixed"], "2.5");
  EXPECT_EQ(row["chosen_side"], "left");
  EXPECT_EQ(row["chose_more_blurred"], "1");  // left 3.5 px against right 1.25 px
  EXPECT_EQ(row["correct"], "1");
  EXPECT_EQ(row["rt_ms"], "512");
  EXPECT_EQ(row["r_left_px"], "3.5");
  EXPECT_EQ(row["kernel"], "gaussian");

  const auto codebook = CodebookOfTrials(dir / "out" / "codebook.csv");
  for (const std::string& name : shipped) EXPECT_EQ(codebook.count(name) ? codebook.at(name).size() : 0, 1u) << name;
  EXPECT_EQ(codebook.size(), shipped.size());
  for (const Column& c : RecordColumns()) {
    if (!codebook.count(c.name) || c.place == Place::kVariable) continue;
    EXPECT_EQ(codebook.at(c.name).at(0), c.type + "|" + c.unit + "|" + c.allowed + "|" + c.meaning) << c.name;
  }
  EXPECT_EQ(codebook.at("r_left_px").at(0),
            "number|photo px||the left object's blur radius, as the camera makes it (moving: averaged over the run)");
  EXPECT_EQ(codebook.at("edge").at(0).substr(0, 11), "integer||9|");
}

// One row more in a (test-only) table reaches every part generated from it: the migration's SQL, the INSERT and its
// binding, the export's SELECT, trials.csv's header and cells, the codebook and the names a level may not take.
TEST(Columns, AColumnAddedToTheTableReachesEveryGeneratedPart) {
  std::vector<Column> table = RecordColumns();
  Column eye;
  eye.name = "eye_dominance", eye.type = "string", eye.allowed = "left|right", eye.place = Place::kTrial;
  eye.meaning = "the eye the participant sights with";
  eye.at.table = "trials", eye.at.sql = "TEXT", eye.at.check = "eye_dominance IN ('left', 'right')", eye.at.since = 9;
  eye.at.of_trial = [](const TrialRecord& t) { return Value(t.block_name == "b" ? "right" : "left"); };
  table.push_back(eye);

  EXPECT_EQ(AddColumnsSql(table, 9),
            "ALTER TABLE trials ADD COLUMN eye_dominance TEXT CHECK (eye_dominance IN ('left', 'right'));");
  EXPECT_EQ(SelectOf(table.back()), "t.eye_dominance");
  const std::string names = InsertNames(table, "trials"), marks = InsertPlaceholders(table, "trials");
  EXPECT_EQ(names.substr(names.size() - 15), ", eye_dominance");
  EXPECT_EQ(std::count(marks.begin(), marks.end(), '?'), std::count(names.begin(), names.end(), ','));

  testing::TempDir dir;
  OneAnsweredTrial(dir / "r.sqlite");
  {
    Database db(dir / "r.sqlite");
    db.Exec(AddColumnsSql(table, 9));
    // The INSERT as generated, bound from a trial as the row says.
    Statement insert(db, "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, right_shown" + names +
                             ") VALUES (1, 1, 0, '{}', 'null', 'null'" + marks + ")");
    TrialRecord t;
    t.block_name = "b";
    t.task = "forced_choice";
    BindTyped(table, insert, 1, t);
    insert.Run();
    EXPECT_EQ(db.QueryText("SELECT eye_dominance FROM trials WHERE trial_index = 1"), "right");
    EXPECT_EQ(db.QueryText("SELECT task FROM trials WHERE trial_index = 1"), "forced_choice");
    db.Exec("UPDATE trials SET eye_dominance = 'left' WHERE trial_index = 0");
  }
  ExportCsvWith(table, dir / "r.sqlite", dir / "out", {});
  const Rows trials = ReadCsv(dir / "out" / "trials.csv");
  const auto& header = trials.at(0);
  const auto at = std::find(header.begin(), header.end(), "eye_dominance");
  ASSERT_NE(at, header.end());
  EXPECT_EQ(*(at - 1), "cell");  // the last of the trial's columns before it
  EXPECT_EQ(trials.at(1).at(size_t(at - header.begin())), "left");
  EXPECT_EQ(trials.at(2).at(size_t(at - header.begin())), "right");
  const auto codebook = CodebookOfTrials(dir / "out" / "codebook.csv");
  ASSERT_EQ(codebook.count("eye_dominance"), 1u);
  EXPECT_EQ(codebook.at("eye_dominance"), std::vector<std::string>{"string||left|right|the eye the participant sights with"});
}

// A merge copies every typed column the table keeps, as the input holds it (the session number is numbered again
// by start across the inputs: with one input, the same).
TEST(Columns, MergeCopiesEveryTypedColumn) {
  testing::TempDir dir;
  OneAnsweredTrial(dir / "a.sqlite");
  {
    Database db(dir / "a.sqlite");
    db.Exec("UPDATE trials SET cell = 'edge=9', r_scene_px = 0.5, left_fixed = 1.5; UPDATE responses SET level = 2, r_left_px = 3, "
            "r_right_px = 1; UPDATE sessions SET px_per_deg = 37.5, screen_height_mm = 300, viewing_distance_mm = 600");
  }
  MergeDatabases({dir / "a.sqlite"}, dir / "m.sqlite");
  Database a(dir / "a.sqlite", OpenMode::kReadOnly), m(dir / "m.sqlite", OpenMode::kReadOnly);
  for (const char* table : {"protocol_versions", "sessions", "trials", "responses"})
    for (const Kept& kept : KeptIn(RecordColumns(), table, 7)) {
      const std::string query = "SELECT quote(" + kept.name + ") FROM " + table;
      EXPECT_NE(a.QueryText(query), "NULL") << table << "." << kept.name << " is not set in the input";
      EXPECT_EQ(m.QueryText(query), a.QueryText(query)) << table << "." << kept.name;
    }
}

// The runner's variables are the table's: every variable column (and every column also kept in the variables) reads
// one member of RecordedVariables, each member is read by one column, and the JSON's keys are the columns' names.
// The record of a trial that recorded a practice round, a procedure's level and one radius, hand-written.
TEST(Columns, TheRunnersVariablesAreTheTablesColumns) {
  for (const Column& c : RecordColumns())
    EXPECT_EQ(bool(c.variable), c.place == Place::kVariable || c.in_variables) << c.name;
  EXPECT_EQ(VariablesJson(RecordedVariables{}), Json::object());
  RecordedVariables v;
  v.practice = true;
  v.round = 2;
  v.level = 0.25;
  v.test_side = "left";
  v.r_px[2] = 1.5;             // the scene's
  v.r_arcmin[0] = 0.75;        // the left one's
  EXPECT_EQ(VariablesJson(v).dump(),
            R"({"level":0.25,"practice":1,"r_left_arcmin":0.75,"r_scene_px":1.5,"round":2,"test_side":"left"})");
  // Every member set: one key per member (28 single ones, 3 sides x 3 units of radius), none twice.
  RecordedVariables all;
  all.practice = all.swapped = all.correct = false;
  all.block_name = all.test_side = all.adjust_levels = all.kernel = all.blur_plan = all.skipped = std::string("x");
  all.round = all.procedure_cell = all.odd_interval = all.intervals = all.reversals = int64_t{1};
  for (std::optional<double>* x : {&all.level, &all.start_level, &all.picture_width_arcmin,
                                   &all.screen_px_per_photo_px, &all.r_span_screen_px, &all.brightness,
                                   &all.contrast, &all.white_balance_r, &all.white_balance_g, &all.white_balance_b,
                                   &all.posterior_threshold, &all.posterior_slope})
    *x = 2.5;
  for (SideVariables& side : all.sides) side.size_deg = 2.5;  // size_left_deg, size_right_deg
  for (size_t k = 0; k < 3; ++k) all.r_px[k] = all.r_screen_px[k] = all.r_arcmin[k] = 3.5;
  const Json json = VariablesJson(all);
  EXPECT_EQ(json.size(), 28u + 9u) << json.dump();
  EXPECT_EQ(json["practice"], 0);
  EXPECT_EQ(json["r_right_screen_px"], 3.5);
}

// Each side's columns are named from one place (SideColumn), the same way for both sides; the names are the users'
// data format, so the frames table's are pinned here, and each reads its own side's values.
TEST(Columns, BothSidesColumnsAreNamedFromOnePlace) {
  EXPECT_EQ(SideColumn("floor_sigma", protocol::Side::kRight, "screen_px"), "floor_sigma_right_screen_px");
  EXPECT_EQ(SideColumn("", protocol::Side::kLeft, "source"), "left_source");
  EXPECT_EQ(SideColumn("r", "scene", "px"), "r_scene_px");
  std::vector<std::string> names;
  for (const FrameColumn* v : KeptColumns(FrameColumns())) names.push_back(v->name);
  EXPECT_EQ(names, (std::vector<std::string>{"frame_index", "flip_time_s", "dropped", "r_left_px", "r_right_px", "y_mm",
                                             "take_frame", "take_status", "floor_sigma_left_px",
                                             "floor_sigma_right_px", "motion_left_x_px", "motion_left_y_px",
                                             "motion_right_x_px", "motion_right_y_px"}));
  FrameRecord f;
  f.sides[protocol::Index(protocol::Side::kLeft)] = {1.0, 2.0, 3.0, 4.0};
  f.sides[protocol::Index(protocol::Side::kRight)] = {5.0, 6.0, 7.0, 8.0};
  std::map<std::string, Value> read;
  for (const FrameColumn* v : KeptColumns(FrameColumns())) read[v->name] = v->of(f);
  EXPECT_EQ(read["r_left_px"], Value(1.0));
  EXPECT_EQ(read["floor_sigma_left_px"], Value(2.0));
  EXPECT_EQ(read["motion_left_y_px"], Value(4.0));
  EXPECT_EQ(read["r_right_px"], Value(5.0));
  EXPECT_EQ(read["motion_right_x_px"], Value(7.0));
  EXPECT_EQ(read["motion_right_y_px"], Value(8.0));
  EXPECT_EQ(read["y_mm"], Value());
  // The runner's variables of a side land in that side's columns.
  RecordedVariables v;
  v.sides[protocol::Index(protocol::Side::kRight)].size_deg = 1.5;
  v.sides[protocol::Index(protocol::Side::kLeft)].u_mm = 400;
  EXPECT_EQ(VariablesJson(v).dump(), R"({"size_right_deg":1.5,"u_left_mm":400.0})");
}

// The tables beside trials.csv keep their shipped SQL too: the frames columns versions 4 and 9 added, and version 10's
// procedures table, as their one lists (frame_columns.h, procedures.h) generate them.
TEST(TableColumns, TheShippedMigrationsAreGeneratedUnchanged) {
  EXPECT_EQ(AddTableColumnsSql("frames", FrameColumns(), 4),
            "ALTER TABLE frames ADD COLUMN r_left_px REAL;ALTER TABLE frames ADD COLUMN r_right_px REAL;"
            "ALTER TABLE frames ADD COLUMN y_mm REAL;");
  EXPECT_EQ(AddTableColumnsSql("frames", FrameColumns(), 9),
            "ALTER TABLE frames ADD COLUMN take_frame INTEGER CHECK (take_frame >= 0);"
            "ALTER TABLE frames ADD COLUMN take_status TEXT CHECK (take_status IN ('found', 'tracked', 'held'));"
            "ALTER TABLE frames ADD COLUMN floor_sigma_left_px REAL;ALTER TABLE frames ADD COLUMN floor_sigma_right_px "
            "REAL;ALTER TABLE frames ADD COLUMN motion_left_x_px REAL;ALTER TABLE frames ADD COLUMN motion_left_y_px "
            "REAL;ALTER TABLE frames ADD COLUMN motion_right_x_px REAL;ALTER TABLE frames ADD COLUMN "
            "motion_right_y_px REAL;");
  EXPECT_EQ(CreatedColumnsSql(ProcedureColumns(), 10),
            ", block INTEGER NOT NULL CHECK (block >= 0), block_name TEXT NOT NULL, procedure TEXT NOT NULL, "
            "variable TEXT NOT NULL, trials INTEGER NOT NULL CHECK (trials >= 1), guess REAL NOT NULL CHECK (guess "
            "BETWEEN 0 AND 1), parameters TEXT NOT NULL CHECK (json_valid(parameters))");
  // frames.csv: the join's columns, then the table's; the INSERT writes only the table's.
  EXPECT_EQ(CsvHeader(FrameColumns()).size(), 5 + KeptColumns(FrameColumns()).size());
  EXPECT_EQ(InsertSql("frames", "trial_id", FrameColumns()).rfind("INSERT INTO frames (trial_id, frame_index, ", 0),
            0u);
}

// A column added to a one-list table reaches its migration, INSERT, merge copy, CSV and codebook.
TEST(TableColumns, AColumnAddedReachesEveryGeneratedPart) {
  struct Row {
    double x = 1.5;
  };
  TableColumn<Row> c;
  static_cast<ColumnSpec&>(c) = {"x_mm", "number", "mm", "", "a test column"};
  c.sql = "REAL", c.since = 99, c.of = [](const Row& r) { return Value(r.x); };
  const std::vector<TableColumn<Row>> columns = WithCells(std::vector<TableColumn<Row>>{c});
  EXPECT_EQ(AddTableColumnsSql("t", columns, 99), "ALTER TABLE t ADD COLUMN x_mm REAL;");
  EXPECT_EQ(InsertSql("t", "k", columns), "INSERT INTO t (k, x_mm) VALUES (?, ?)");
  EXPECT_EQ(CopySelect(columns, 98), ", NULL");
  EXPECT_EQ(CopySelect(columns, 99), ", x_mm");
  EXPECT_EQ(CsvSelect(columns, "a"), "a.x_mm");
  EXPECT_EQ(CsvCodebook("t.csv", columns), "t.csv,x_mm,number,mm,,a test column,\r\n");
  Database db(":memory:");
  db.Exec("CREATE TABLE t (k INTEGER, x_mm REAL)");
  Statement insert(db, InsertSql("t", "k", columns));
  insert.Bind(1, int64_t(1));
  BindRow(columns, insert, 2, Row{});
  insert.Run();
  Statement read(db, "SELECT " + CsvSelect(columns, "a") + " FROM t a");
  ASSERT_TRUE(read.Step());
  EXPECT_EQ(CsvCells(columns, read), std::vector<std::string>{"1.5"});
}

}  // namespace
}  // namespace blurcue::store
