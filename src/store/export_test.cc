#include "store/export.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

using testing::Rows;
using testing::ReadCsv;

size_t ColumnIndex(const Rows& rows, const std::string& name) {
  const auto& header = rows.at(0);
  const auto it = std::find(header.begin(), header.end(), name);
  EXPECT_NE(it, header.end()) << "no column " << name;
  return static_cast<size_t>(it - header.begin());
}

// One participant's session: `n` trials with the given factors JSON, the first `answered` answered.
void RunSession(Record& record, const std::string& participant, const std::string& factors_json, int n, int answered,
                const std::string& study = "test1") {
  const int64_t session =
      record.StartOrResumeSession(study, participant, R"({"study":")" + study + R"("})", 42, {}, false).session_id;
  std::vector<TrialRecord> trials;
  for (int i = 0; i < n; ++i) {
    TrialRecord t;
    t.index = i;
    t.block = i / 2;
    t.factors_json = factors_json;
    t.source_json[0] = R"("measured")";
    t.source_json[1] = R"({"screen_px":2.5})";
    trials.push_back(t);
  }
  record.SaveTrialList(session, trials);
  for (int i = 0; i < answered; ++i) {
    Response r;
    r.choice = i % 2 ? "left" : "right";
    r.rt_ms = 400.25 + i;
    record.RecordResponse(session, i, r);
  }
  record.FinishSession(session, SessionStatus::kCompleted);
}

TEST(Export, ColumnsAreTheSameForParticipantsWithDifferentFactors) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    RunSession(record, "P01", R"({"edge":3,"blur":"measured"})", 4, 4);
    RunSession(record, "P02", R"({"speed_cm_s":1.8,"blur":"none"})", 3, 2);
  }
  EXPECT_EQ(ExportCsv(dir / "r.sqlite", dir / "out"), 7);
  const Rows rows = ReadCsv(dir / "out" / "trials.csv");
  ASSERT_EQ(rows.size(), 8u);
  const std::vector<std::string> expected = {
      "study",       "protocol_hash", "protocol_version", "participant", "observer",    "observer_params", "window",
      "session_id",  "session_number", "session_status", "seed", "trial_index", "block",            "block_name",
      "task",        "practice",      "swapped",     "cell",        "blur",        "edge",               "speed_cm_s",
      "left_source", "left_fixed",    "right_source", "right_fixed", "status",            "chosen_side",
      "chose_more_blurred", "chosen_interval", "yes_no", "rating",   "adjusted_level",    "correct",
      "rt_ms",       "answered_at"};
  EXPECT_EQ(rows[0], expected);
  for (const auto& row : rows) EXPECT_EQ(row.size(), expected.size());
  EXPECT_EQ(rows[1][ColumnIndex(rows, "participant")], "P01");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "edge")], "3");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "speed_cm_s")], "");
  EXPECT_EQ(rows[5][ColumnIndex(rows, "participant")], "P02");
  EXPECT_EQ(rows[5][ColumnIndex(rows, "speed_cm_s")], "1.8");
  EXPECT_EQ(rows[5][ColumnIndex(rows, "edge")], "");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "rt_ms")], "400.25");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "seed")], "s42");  // never a number a spreadsheet could round
  EXPECT_EQ(rows[1][ColumnIndex(rows, "status")], "answered");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "chosen_side")], "right");
  EXPECT_EQ(rows[5][ColumnIndex(rows, "session_number")], "1");
  EXPECT_EQ(rows[5][ColumnIndex(rows, "session_status")], "completed");
  // Unanswered trials are rows with empty answers.
  EXPECT_EQ(rows[7][ColumnIndex(rows, "status")], "unanswered");
  EXPECT_EQ(rows[7][ColumnIndex(rows, "chosen_side")], "");
  EXPECT_EQ(rows[7][ColumnIndex(rows, "answered_at")], "");
  // Each side's source and fixed radius in columns of their own, no JSON.
  EXPECT_EQ(rows[1][ColumnIndex(rows, "left_source")], "measured");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "left_fixed")], "");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "right_source")], "fixed_screen_px");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "right_fixed")], "2.5");
  // The codebook names every column of trials.csv, in order.
  const Rows codebook = ReadCsv(dir / "out" / "codebook.csv");
  std::vector<std::string> named;
  for (const auto& row : codebook)
    if (row[0] == "trials.csv") named.push_back(row[1]);
  EXPECT_EQ(named, expected);
}

// Each object's depth and its elevation reach trials.csv as the runner recorded them, and the codebook states their
// units (mm, deg) and what they are; a level the record holds as binary arithmetic left it (a staircase's
// 0.5 - 0.1 - 0.1 - 0.1, recorded so by an older runner) is written as the protocol gives it: 0.2.
TEST(Export, EachObjectsDepthAndElevationWithTheirUnitsAndLevelsAsGiven) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    const double level = 0.5 - 0.1 - 0.1 - 0.1;
    ASSERT_EQ(Json(level).dump(), "0.20000000000000004");
    const Json factors = {{"edge", 11}, {"u_left_mm", 538.51}, {"u_right_mm", 538.6},
                          {"elevation_left_deg", 4.2125}, {"elevation_right_deg", 4.25}, {"level", level},
                          {"procedure_cell", 0}};
    RunSession(record, "P01", factors.dump(), 1, 1);
  }
  ASSERT_EQ(ExportCsv(dir / "r.sqlite", dir / "out"), 1);
  const Rows rows = ReadCsv(dir / "out" / "trials.csv");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "u_left_mm")], "538.51");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "u_right_mm")], "538.6");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "elevation_left_deg")], "4.2125");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "elevation_right_deg")], "4.25");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "level")], "0.2");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "edge")], "11");
  std::map<std::string, std::vector<std::string>> book;
  for (const auto& row : ReadCsv(dir / "out" / "codebook.csv"))
    if (row[0] == "trials.csv") book[row[1]] = row;
  for (const char* name : {"u_left_mm", "u_right_mm", "elevation_left_deg", "elevation_right_deg"})
    ASSERT_TRUE(book.count(name)) << name;
  EXPECT_EQ(book["u_left_mm"][2], "number");
  EXPECT_EQ(book["u_left_mm"][3], "mm");
  EXPECT_NE(book["u_left_mm"][5].find("depth u"), std::string::npos) << book["u_left_mm"][5];
  EXPECT_NE(book["u_left_mm"][5].find("optical axis"), std::string::npos) << book["u_left_mm"][5];
  EXPECT_EQ(book["elevation_right_deg"][3], "deg");
  EXPECT_NE(book["elevation_right_deg"][5].find("not its angular size"), std::string::npos);
}

// Studies whose names differ only in what a file name cannot hold, or only in case, each keep their summary: "a<b",
// "a>b", "a b" and "A<B" used to be written to summary-a_b.csv (three of them, two overwritten) and summary-A_B.csv
// (one file with it on a case-insensitive file system). A plain name keeps its plain file; the codebook lists each
// summary's columns, naming its study.
TEST(Export, SummariesOfStudiesWhoseNamesCollideAsFileNamesAreEachKept) {
  testing::TempDir dir;
  const std::vector<std::string> studies = {"a<b", "a>b", "a b", "A<B", "test1-static-grids"};
  {
    Record record = Record::Open(dir / "r.sqlite");
    for (size_t i = 0; i < studies.size(); ++i)
      RunSession(record, "P1", R"({"edge":3})", int(i) + 1, int(i) + 1, studies[i]);
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  std::set<std::string> folded;
  for (size_t i = 0; i < studies.size(); ++i) {
    const std::string file = SummaryFileName(studies[i]);
    std::string lower = file;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    EXPECT_TRUE(folded.insert(lower).second) << file;
    const Rows rows = ReadCsv(dir / "out" / file);
    ASSERT_EQ(rows.size(), 2u) << file;
    EXPECT_EQ(rows[1][ColumnIndex(rows, "planned")], std::to_string(i + 1)) << file;  // its own study's session
  }
  EXPECT_EQ(SummaryFileName("test1-static-grids"), "summary-test1-static-grids.csv");
  EXPECT_EQ(SummaryFileName("a<b"), SummaryFileName("a<b"));  // the same in every export
  EXPECT_EQ(SummaryFileName("a<b").rfind("summary-a_b-", 0), 0u) << SummaryFileName("a<b");
  EXPECT_EQ(SummaryFileName("A<B").rfind("summary-A_B-", 0), 0u) << SummaryFileName("A<B");
  EXPECT_EQ(SummaryFileName("a<b").size(), std::string("summary-a_b-0123456789abcdef.csv").size());
  // A plain name that looks like a suffixed one gets a suffix too, so it cannot meet another study's file.
  const std::string suffixed = SummaryFileName("a<b").substr(8, 28);  // "a_b-" and the 16 hex digits
  EXPECT_NE(SummaryFileName(suffixed), SummaryFileName("a<b"));
  EXPECT_NE(SummaryFileName("Test"), SummaryFileName("test"));
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "out"))
    files += entry.path().filename().string().rfind("summary-", 0) == 0;
  EXPECT_EQ(files, studies.size());
  const Rows codebook = ReadCsv(dir / "out" / "codebook.csv");
  bool named = false;
  for (const auto& row : codebook)
    named = named || (row[0] == SummaryFileName("a b") && row[1] == "participant" &&
                      row[5].find("(study a b)") != std::string::npos);
  EXPECT_TRUE(named);
}

// The one rule for file names from names, against the table its Python twin (analysis/common.py file_stem) reads.
TEST(Export, FileStemsAreTheGoldenTables) {
  const Rows rows = ReadCsv(BLURCUE_FILE_STEMS);
  ASSERT_GT(rows.size(), 30u);
  ASSERT_EQ(rows[0], (std::vector<std::string>{"name", "stem"}));
  std::set<std::string> stems;
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 2u) << i;
    EXPECT_EQ(FileStem(rows[i][0]), rows[i][1]) << rows[i][0];
    EXPECT_LE(rows[i][1].size(), 100u);
    EXPECT_TRUE(stems.insert(rows[i][1]).second) << rows[i][1];
  }
}

// Studies whose names share a safe form ("pilot 1", "pilot/1"), one of 72 CJK characters (216 bytes: its summary's
// name was too long for the file system, and every study's export stopped with exit 3) and one with a zero-width
// space each get a summary of their own, of at most 112 bytes.
TEST(Export, NamesSharingASafeFormOrTooLongGetSummariesOfTheirOwn) {
  testing::TempDir dir;
  std::string cjk;
  for (int i = 0; i < 72; ++i) cjk += "\xe6\xbc\xa2";  // U+6F22
  const std::vector<std::string> studies = {"pilot 1", "pilot/1", cjk, "a\xe2\x80\x8b" "b", "pilot_1"};
  {
    Record record = Record::Open(dir / "r.sqlite");
    for (size_t i = 0; i < studies.size(); ++i)
      RunSession(record, "P1", R"({"edge":3})", int(i) + 1, int(i) + 1, studies[i]);
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  std::set<std::string> files;
  for (size_t i = 0; i < studies.size(); ++i) {
    const std::string file = SummaryFileName(studies[i]);
    EXPECT_LE(file.size(), 112u) << file;
    EXPECT_TRUE(files.insert(file).second) << file;
    const Rows rows = ReadCsv(dir / "out" / file);
    ASSERT_EQ(rows.size(), 2u) << file;
    EXPECT_EQ(rows[1][ColumnIndex(rows, "planned")], std::to_string(i + 1)) << file;  // its own study's session
  }
}

// A record of schema 6, as that version wrote it: one simulated session, one answered trial.
void WriteVersionSixRecord(const std::filesystem::path& path) {
  Database db(path);
  for (int i = 0; i < 6; ++i) {
    const Migration& step = Migrations()[size_t(i)];
    if (!step.sql.empty()) db.Exec(step.sql);
    if (step.data) step.data(db);
  }
  db.Exec("PRAGMA user_version = 6; PRAGMA application_id = " + std::to_string(kApplicationId) + ";"
          "INSERT INTO studies (name, created) VALUES ('s', 'now');"
          "INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (1, '{}', 'h', 'now');"
          "INSERT INTO participants (study_id, code, created) VALUES (1, 'P1', 'now');"
          "INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, host, display, "
          "  started, status) VALUES (1, 1, -2, 'v', 'h', 'headless 1280x720; llvmpipe; observer sim:jnd=0.6', "
          "  'now', 'completed');"
          "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, right_shown) VALUES "
          "  (1, 0, 0, '{\"block_name\": \"b\", \"edge\": 3, \"r_left_px\": 2, \"r_right_px\": 1}', "
          "'\"measured\"', '\"none\"');"
          "INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at) VALUES "
          "  (1, 'left', 700, '[]', 'now');");
}

// Merged: a record of schema 6 and one of the current schema give one record whose typed columns hold both - the old
// one's derived from its texts, the new one's copied as written.
TEST(Merge, AnOlderAndANewRecordMergeWithTheirTypedColumns) {
  testing::TempDir dir;
  WriteVersionSixRecord(dir / "old.sqlite");
  {
    Record record = Record::Open(dir / "new.sqlite");
    SessionMeta meta;
    meta.simulated = false;
    meta.window = true;
    const int64_t session = record.StartOrResumeSession("s", "P2", "{}", 9, meta, false).session_id;
    std::vector<TrialRecord> trials(1);
    trials[0].block_name = "b";
    trials[0].r_px[0] = 1.23456789;
    trials[0].source_json[0] = R"("estimated")";
    record.SaveTrialList(session, trials);
  }
  MergeDatabases({dir / "old.sqlite", dir / "new.sqlite"}, dir / "all.sqlite");
  Database all(dir / "all.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(all.QueryText("SELECT group_concat(observer || ':' || window, ',') FROM (SELECT * FROM sessions "
                          "ORDER BY id)"),
            "simulated:0,person:1");
  EXPECT_EQ(all.QueryText("SELECT group_concat(left_source || ':' || printf('%.8f', r_left_px), ',') FROM "
                          "(SELECT * FROM trials ORDER BY id)"),
            "measured:2.00000000,estimated:1.23456789");
}

// A record of schema 1 as an early build wrote it (issue 24): the trial's variables were its levels as given - a
// pattern's speed_cm_s only inside the pattern object - and practice, block_name, swapped and the radii. Its export
// has a speed_cm_s column with each trial's pattern's speed, as today's runner records it (it used to be left out,
// and the report stopped with exit 10); the pattern's column names it by its id; its sides are no columns.
TEST(Export, ASchemaOneRecordsPatternGivesItsSpeedAColumn) {
  testing::TempDir dir;
  {
    Database db(dir / "old.sqlite");
    db.Exec(Migrations()[0].sql);
    db.Exec("PRAGMA user_version = 1;"
            "INSERT INTO studies (name, created) VALUES ('test2-moving-balls', 'now');"
            "INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (1, '{}', 'h', 'now');"
            "INSERT INTO participants (study_id, code, created) VALUES (1, 'P1', 'now');"
            "INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, host, display, "
            "  started, status) VALUES (1, 1, 5, 'v', 'h', 'headless 1280x720; llvmpipe; observer sim:jnd=0.6', "
            "  'now', 'completed');"
            "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, right_shown) VALUES "
            "  (1, 0, 0, '{\"pattern\":{\"id\":1,\"left\":\"measured\",\"right\":\"none\",\"speed_cm_s\":3},"
            "\"practice\":0,\"block_name\":\"task1\",\"swapped\":0,\"r_left_px\":2.5,\"r_right_px\":0,"
            "\"r_scene_px\":2.4}', '\"measured\"', '\"none\"'),"
            "  (1, 1, 0, '{\"pattern\":{\"id\":4,\"left\":\"estimated\",\"right\":\"none\",\"speed_cm_s\":1.8},"
            "\"practice\":0,\"block_name\":\"task1\",\"swapped\":1,\"r_left_px\":0,\"r_right_px\":3.1,"
            "\"r_scene_px\":2.4}', '\"none\"', '\"estimated\"');"
            "INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at) VALUES "
            "  (1, 'left', 700, '[]', 'now'), (2, 'cant_tell', 900, '[]', 'now');");
  }
  EXPECT_EQ(ExportCsv(dir / "old.sqlite", dir / "out"), 2);
  const Rows rows = ReadCsv(dir / "out" / "trials.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1][ColumnIndex(rows, "speed_cm_s")], "3");
  EXPECT_EQ(rows[2][ColumnIndex(rows, "speed_cm_s")], "1.8");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "pattern")], "1");
  EXPECT_EQ(rows[2][ColumnIndex(rows, "pattern")], "4");
  EXPECT_EQ(rows[2][ColumnIndex(rows, "r_right_px")], "3.1");
  EXPECT_EQ(rows[2][ColumnIndex(rows, "right_source")], "estimated");
  for (const char* side : {"left", "right"})
    for (const auto& name : rows[0]) EXPECT_NE(name, side);
}

// A record of schema 6 (its typed columns still in JSON texts and free text) exports the same tidy table from a
// migrated copy, and is itself left as it was.
TEST(Export, AnOlderRecordExportsFromAMigratedCopy) {
  testing::TempDir dir;
  WriteVersionSixRecord(dir / "old.sqlite");
  EXPECT_EQ(ExportCsv(dir / "old.sqlite", dir / "out"), 1);
  const Rows rows = ReadCsv(dir / "out" / "trials.csv");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "observer")], "simulated");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "observer_params")], "sim:jnd=0.6");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "window")], "0");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "seed")], "s18446744073709551614");  // 2^64 - 2, stored as -2
  EXPECT_EQ(rows[1][ColumnIndex(rows, "left_source")], "measured");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "chosen_side")], "left");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "chose_more_blurred")], "1");
  Database old(dir / "old.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(SchemaVersion(old), 6);  // the record itself is only read
}

// Every row says its session's status, so an analysis can tell an aborted session's answers from the study's.
TEST(Export, EveryRowCarriesItsSessionsStatusAbortedIncluded) {
  testing::TempDir dir;
  {
    Record record = Record::Open(dir / "r.sqlite");
    const int64_t first = record.StartOrResumeSession("test1", "P01", R"({"study":"test1"})", 1, {}, false).session_id;
    TrialRecord trial;
    record.SaveTrialList(first, {trial});
    Response r;
    r.choice = "left";
    record.RecordResponse(first, 0, r);
    record.AbortSession(first);
    RunSession(record, "P01", "{}", 2, 2);  // the same participant again, completed
    RunSession(record, "P02", "{}", 2, 1);
    const int64_t running = record.StartOrResumeSession("test1", "P03", R"({"study":"test1"})", 1, {}, false).session_id;
    record.SaveTrialList(running, {trial});
  }
  ExportCsv(dir / "r.sqlite", dir / "out");
  const Rows rows = ReadCsv(dir / "out" / "trials.csv");
  std::vector<std::string> got;
  for (size_t i = 1; i < rows.size(); ++i)
    got.push_back(rows[i][ColumnIndex(rows, "participant")] + ":" + rows[i][ColumnIndex(rows, "session_id")] + ":" +
                  rows[i][ColumnIndex(rows, "session_status")]);
  EXPECT_EQ(got, (std::vector<std::string>{"P01:1:aborted", "P01:2:completed", "P01:2:completed", "P02:3:completed",
                                           "P02:3:completed", "P03:4:running"}));
}

TEST(Export, ReadsARecordAWriterStillHasOpen) {
  testing::TempDir dir;
  Record record = Record::Open(dir / "r.sqlite");
  RunSession(record, "P01", R"({"block":1})", 2, 1);  // a factor named like a fixed column
  EXPECT_EQ(ExportCsv(dir / "r.sqlite", dir / "out"), 2);
  const Rows rows = ReadCsv(dir / "out" / "trials.csv");
  EXPECT_EQ(rows[1][ColumnIndex(rows, "factor_block")], "1");
}

TEST(Export, QuotesFieldsThatNeedIt) {
  EXPECT_EQ(CsvField("plain"), "plain");
  EXPECT_EQ(CsvField("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(CsvField("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(CsvField(" padded"), "\" padded\"");
}

TEST(Export, ForeignDatabaseIsInputError) {
  testing::TempDir dir;
  { Database(dir / "other.sqlite").Exec("CREATE TABLE x (y)"); }
  try {
    ExportCsv(dir / "other.sqlite", dir / "out");
    FAIL() << "exported a database that is not a record";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
  }
}

TEST(Merge, KeepsAllRowsAndIdsStayConsistent) {
  testing::TempDir dir;
  {
    Record a = Record::Open(dir / "a.sqlite");
    RunSession(a, "P01", R"({"edge":1})", 4, 4);
    RunSession(a, "P02", R"({"edge":2})", 3, 3);
    Record b = Record::Open(dir / "b.sqlite");
    RunSession(b, "P03", R"({"edge":3})", 5, 2);
    RunSession(b, "P01", R"({"edge":4})", 2, 1);  // the same participant at a second station
    RunSession(b, "Q01", R"({"edge":5})", 2, 2, "test2");
  }
  MergeOptions one_person;
  one_person.same_person = {"P01"};  // one person ran at both stations
  MergeDatabases({dir / "a.sqlite", dir / "b.sqlite"}, dir / "merged.sqlite", {}, one_person);

  Database db(dir / "merged.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(db.QueryText("PRAGMA integrity_check"), "ok");
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM pragma_foreign_key_check"), 0);
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM studies"), 2);
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM protocol_versions"), 2);  // same text shared by hash
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM participants"), 4);       // P01 once
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM sessions"), 5);
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM trials"), 16);
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM responses"), 12);
  // Each response still belongs to the trial and participant it was given for: the factor says which session.
  EXPECT_EQ(db.QueryText("SELECT group_concat(n, ' ') FROM (SELECT p.code || ':' || t.factors || ':' || COUNT(r.id) AS n "
                         "FROM trials t JOIN sessions s ON s.id = t.session_id "
                         "JOIN participants p ON p.id = s.participant_id LEFT JOIN responses r ON r.trial_id = t.id "
                         "GROUP BY s.id ORDER BY p.code, t.factors)"),
            R"(P01:{"edge":1}:4 P01:{"edge":4}:1 P02:{"edge":2}:3 P03:{"edge":3}:2 Q01:{"edge":5}:2)");
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM sessions s JOIN participants p ON p.id = s.participant_id "
                          "JOIN protocol_versions v ON v.id = s.protocol_version_id WHERE v.study_id != p.study_id"),
            0);
}

// Every session field survives a merge, the display profile it ran with included.
TEST(Merge, KeepsEachSessionsDisplayProfile) {
  testing::TempDir dir;
  {
    Record a = Record::Open(dir / "a.sqlite");
    SessionMeta meta;
    meta.display_profile = R"({"name":"booth 2"})";
    a.StartOrResumeSession("test1", "P01", "{}", 1, meta, false);
  }
  MergeDatabases({dir / "a.sqlite"}, dir / "merged.sqlite");
  Database db(dir / "merged.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(db.QueryText("SELECT display_profile FROM sessions"), R"({"name":"booth 2"})");
}

TEST(Merge, RefusesToOverwriteAnExistingOutput) {
  testing::TempDir dir;
  { Record a = Record::Open(dir / "a.sqlite"); RunSession(a, "P01", "{}", 1, 1); }
  std::ofstream(dir / "merged.sqlite") << "keep me";
  EXPECT_THROW(MergeDatabases({dir / "a.sqlite"}, dir / "merged.sqlite"), Error);
  std::ifstream in(dir / "merged.sqlite");
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "keep me");
}

TEST(Merge, TheSameSessionTwiceIsRefusedAndLeavesNoOutput) {
  testing::TempDir dir;
  { Record a = Record::Open(dir / "a.sqlite"); RunSession(a, "P01", "{}", 1, 1); }
  std::filesystem::copy_file(dir / "a.sqlite", dir / "copy.sqlite");
  EXPECT_THROW(MergeDatabases({dir / "a.sqlite", dir / "copy.sqlite"}, dir / "merged.sqlite"), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "merged.sqlite"));
  EXPECT_THROW(MergeDatabases({dir / "a.sqlite", dir / "a.sqlite"}, dir / "merged.sqlite"), Error);
}

// Starts participant P01's session of 4 trials in `db` and answers 2 of them, leaving it running.
int64_t StartHalfASession(Record& record) {
  const int64_t session = record.StartOrResumeSession("test1", "P01", R"({"study":"test1"})", 42, {}, false).session_id;
  std::vector<TrialRecord> trials(4);
  for (int i = 0; i < 4; ++i) {
    trials[i].index = i;
    trials[i].factors_json = "{}";
    trials[i].source_json[0] = R"("measured")";
    trials[i].source_json[1] = R"("none")";
  }
  record.SaveTrialList(session, trials);
  for (int i = 0; i < 2; ++i) {
    Response r;
    r.choice = "left";
    record.RecordResponse(session, i, r);
  }
  return session;
}

// A session a live writer holds is refused, naming the file, the session and the writer: a copy taken now would
// miss the answers still coming, and both copies could be resumed and never merged again.
TEST(Merge, ASessionALiveWriterHoldsIsRefusedNamingItsWriter) {
  testing::TempDir dir;
  Record writer = Record::Open(dir / "a.sqlite");
  StartHalfASession(writer);
  try {
    MergeDatabases({dir / "a.sqlite"}, dir / "merged.sqlite");
    FAIL() << "merged a session that is still being written";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    const std::string message = e.what();
    EXPECT_NE(message.find((dir / "a.sqlite").string() + ": session 1 (study test1, participant P01, 2 of 4 trials "
                           "answered) is being written by pid " + std::to_string(getpid())),
              std::string::npos) << message;
    EXPECT_NE(message.find("(alive)"), std::string::npos) << message;
    EXPECT_NE(message.find("--abort 1"), std::string::npos) << message;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "merged.sqlite"));
}

// A session whose writer was killed (its lock names a pid that is gone) is copied as running, and one line says it
// is unfinished and must be resumed in one record only.
TEST(Merge, AKilledWritersSessionIsCopiedAndNamedAsUnfinished) {
  testing::TempDir dir;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Dies holding the lock, as a killed run does: _exit runs no destructor to release it.
    try {
      Record writer = Record::Open(dir / "a.sqlite");
      StartHalfASession(writer);
      _exit(0);
    } catch (...) {
      _exit(1);
    }
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  {
    Database a(dir / "a.sqlite", OpenMode::kReadOnly);
    ASSERT_EQ(a.QueryInt64("SELECT lock_pid FROM sessions"), child);  // the lock outlived its writer
  }
  std::vector<std::string> notes;
  MergeDatabases({dir / "a.sqlite"}, dir / "merged.sqlite", [&](const std::string& line) { notes.push_back(line); });
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].rfind((dir / "a.sqlite").string() + ": session 1 (study test1, participant P01, 2 of 4 trials "
                           "answered) is unfinished, with no live writer: copied as running; resume it in one record "
                           "only", 0), 0u) << notes[0];
  Database db(dir / "merged.sqlite", OpenMode::kReadOnly);
  EXPECT_EQ(db.QueryText("SELECT status FROM sessions"), "running");
  EXPECT_EQ(db.QueryInt64("SELECT count(*) FROM responses"), 2);
  EXPECT_EQ(db.QueryInt64("SELECT count(*) FROM sessions WHERE lock_token IS NOT NULL"), 0);
}

// Completed sessions are merged without a word.
TEST(Merge, CompletedSessionsSayNothing) {
  testing::TempDir dir;
  { Record a = Record::Open(dir / "a.sqlite"); RunSession(a, "P01", "{}", 2, 2); }
  std::vector<std::string> notes;
  MergeDatabases({dir / "a.sqlite"}, dir / "merged.sqlite", [&](const std::string& line) { notes.push_back(line); });
  EXPECT_TRUE(notes.empty());
}

}  // namespace
}  // namespace blurcue::store
