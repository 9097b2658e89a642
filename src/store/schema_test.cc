#include "store/schema.h"

#include <climits>
#include <functional>

#include <gtest/gtest.h>

#include "core/error.h"
#include "store/export.h"
#include "store/record.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

TEST(Schema, MigratesAnEmptyFile) {
  testing::TempDir dir;
  Database db(dir / "r.sqlite");
  EXPECT_EQ(SchemaVersion(db), 0);
  Migrate(db);
  EXPECT_EQ(SchemaVersion(db), CurrentSchemaVersion());
  for (const char* table : {"studies", "protocol_versions", "participants", "sessions", "trials", "responses", "frames"}) {
    EXPECT_EQ(db.QueryInt64(std::string("SELECT COUNT(*) FROM sqlite_schema WHERE type = 'table' AND name = '") +
                            table + "'"),
              1)
        << table;
  }
}

TEST(Schema, ReopenAndMigrateAgainChangesNothing) {
  testing::TempDir dir;
  {
    Database db(dir / "r.sqlite");
    Migrate(db);
    db.Exec("INSERT INTO studies (name, created) VALUES ('s', 'now')");
  }
  Database db(dir / "r.sqlite");
  const std::string before = db.QueryText("SELECT group_concat(sql, ';') FROM sqlite_schema");
  Migrate(db);
  Migrate(db);
  EXPECT_EQ(SchemaVersion(db), CurrentSchemaVersion());
  EXPECT_EQ(db.QueryText("SELECT group_concat(sql, ';') FROM sqlite_schema"), before);
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM studies"), 1);
}

// A record of version 6 kept who answered in free text and a trial's variables in JSON texts: migrating it fills the
// typed columns of version 7 from them.
TEST(Schema, AVersionSixRecordGetsItsTypedColumns) {
  Database db(":memory:");
  for (int i = 0; i < 6; ++i) {
    const Migration& step = Migrations()[size_t(i)];
    if (!step.sql.empty()) db.Exec(step.sql);
    if (step.data) step.data(db);
  }
  db.Exec("PRAGMA user_version = 6");
  db.Exec("INSERT INTO studies (name, created) VALUES ('s', 'now');"
          "INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (1, '{}', 'h', 'now');"
          "INSERT INTO participants (study_id, code, created) VALUES (1, 'P1', 'now');"
          "INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, host, display, started, "
          "  status, display_profile, group_name, participant_info) VALUES (1, 1, 7, 'v', 'h', "
          "  'headless 1280x720; llvmpipe (LLVM 15); observer sim:jnd=0.6,bias=0.2', 'now', 'completed', "
          "  '{\"name\": \"lab\", \"width_mm\": 531.4, \"height_mm\": 298.9, \"distance_mm\": 600, "
          "\"px_per_deg\": 37.8}', 'a', '{\"age\": 31, \"hand\": \"left\"}'),"
          "  (1, 1, 8, 'v', 'h', 'window 1920x1080@60; Mesa', 'now', 'completed', '{}', '', '{}');"
          "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, right_shown) VALUES "
          "  (1, 0, 0, '{\"block_name\": \"b\", \"practice\": 1, \"swapped\": 0, \"r_left_px\": 1.25, "
          "\"r_right_px\": 0, \"r_scene_px\": 1.1}', '\"measured\"', '{\"screen_px\": 4}'),"
          "  (1, 1, 0, '{\"block_name\": \"b\", \"practice\": 0, \"swapped\": 1}', '2.5', '{\"arcmin\": 3}');"
          "INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at, shown) VALUES "
          "  (2, 'left', 800, '[]', 'now', '{\"level\": 0.5, \"correct\": 1, \"r_left_px\": 3.75}');");
  Migrate(db);
  EXPECT_EQ(SchemaVersion(db), CurrentSchemaVersion());
  EXPECT_EQ(db.QueryText("SELECT observer || '|' || observer_params || '|' || window || '|' || profile_name || '|' || "
                         "viewing_distance_mm FROM sessions WHERE id = 1"),
            "simulated|sim:jnd=0.6,bias=0.2|0|lab|600.0");
  EXPECT_EQ(db.QueryText("SELECT screen_width_mm || '|' || screen_height_mm || '|' || px_per_deg FROM sessions "
                         "WHERE id = 1"),
            "531.4|298.9|37.8");
  EXPECT_EQ(db.QueryText("SELECT observer || '|' || observer_params || '|' || window FROM sessions WHERE id = 2"),
            "person||1");
  EXPECT_EQ(db.QueryText("SELECT group_concat(key || '=' || value, ',') FROM (SELECT * FROM session_info ORDER BY key)"),
            "age=31,hand=left");
  EXPECT_EQ(db.QueryText("SELECT block_name || '|' || practice || '|' || swapped || '|' || left_source || '|' || "
                         "coalesce(left_fixed, '') || '|' || right_source || '|' || right_fixed || '|' || r_left_px "
                         "FROM trials WHERE trial_index = 0"),
            "b|1|0|measured||fixed_screen_px|4.0|1.25");
  EXPECT_EQ(db.QueryText("SELECT task || '|' || r_right_px || '|' || r_scene_px FROM trials WHERE trial_index = 0"),
            "forced_choice|0.0|1.1");
  EXPECT_EQ(db.QueryText("SELECT left_source || '|' || left_fixed || '|' || right_source || '|' || right_fixed || '|' || "
                         "swapped || '|' || coalesce(r_left_px, 'null') FROM trials WHERE trial_index = 1"),
            "fixed_px|2.5|fixed_arcmin|3.0|1|null");
  EXPECT_EQ(db.QueryText("SELECT level || '|' || correct || '|' || r_left_px || '|' || coalesce(r_right_px, 'null') "
                         "FROM responses"),
            "0.5|1|3.75|null");
}

TEST(Schema, NewerVersionIsRefused) {
  Database db(":memory:");
  Migrate(db);
  db.Exec("PRAGMA user_version = " + std::to_string(CurrentSchemaVersion() + 1));
  EXPECT_THROW(Migrate(db), Error);
}

TEST(Schema, StrictTablesRefuseTextInIntegerColumns) {
  if (SqliteVersionNumber() < 3037000) GTEST_SKIP() << "STRICT tables need SQLite 3.37";
  Database db(":memory:");
  Migrate(db);
  db.Exec("INSERT INTO studies (name, created) VALUES ('s', 'now')");
  EXPECT_THROW(db.Exec("INSERT INTO participants (study_id, code, created) VALUES ('one', 'p', 'now')"), Error);
}

TEST(Schema, ForeignKeysAreEnforced) {
  Database db(":memory:");
  Migrate(db);
  EXPECT_THROW(db.Exec("INSERT INTO participants (study_id, code, created) VALUES (99, 'p', 'now')"), Error);
}

TEST(Schema, ReadersRefuseAForeignDatabase) {
  Database db(":memory:");
  db.Exec("CREATE TABLE other (x)");
  try {
    RequireReadableRecord(db);
    FAIL() << "a foreign database read as a record";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("not a blurcue record: it holds 1 tables (other)"), std::string::npos)
        << e.what();
  }
}

// A current record of one study, then its schema number set to `number` by hand (as an adversary's sqlite3 would).
// `stamped`: with the application id every record has had since version 2 (without: an older record's).
void WriteRecordNumbered(const std::filesystem::path& path, int64_t number, bool stamped) {
  {
    Record record = Record::Open(path);
    record.StartOrResumeSession("s", "P1", R"({"study":"s"})", 7, {}, false);
  }
  Database db(path);
  db.Exec("PRAGMA journal_mode = DELETE; PRAGMA user_version = " + std::to_string(number));
  if (!stamped) db.Exec("PRAGMA application_id = 0");
}

// Every command's way into a record refuses a schema number this build does not know, or one its tables contradict,
// with one line naming the record and the number, exit 3 - before any work, the file byte for byte as it was. (-5
// and INT_MIN crashed export, run and report; -1 was std::bad_alloc; 0, 1 and 6 on a current record replayed the
// migrations and stopped with "duplicate column", exit 10.)
TEST(Schema, AnUnknownOrEditedSchemaNumberIsRefusedEverywhere) {
  testing::TempDir dir;
  const int current = CurrentSchemaVersion();
  const std::vector<int64_t> numbers = {-5, INT_MIN, -1, 0, 1, 6, current + 1};
  const std::vector<std::pair<std::string, std::function<void(const std::filesystem::path&)>>> readers = {
      {"open for a run", [](const std::filesystem::path& p) { Record::Open(p); }},
      {"export", [&](const std::filesystem::path& p) { ExportCsv(p, dir / "out"); }},
      {"sessions", [](const std::filesystem::path& p) { ListSessions(p); }},
      {"merge", [&](const std::filesystem::path& p) { MergeDatabases({p}, dir / "merged.sqlite"); }},
      {"peek groups", [](const std::filesystem::path& p) { PeekGroups(p, "s", "P1"); }},
  };
  for (const int64_t number : numbers) {
    for (const bool stamped : {true, false}) {
      const auto path = dir / ("n" + std::to_string(number) + (stamped ? "" : "-unstamped") + ".sqlite");
      WriteRecordNumbered(path, number, stamped);
      const std::string before = testing::FileBytes(path);
      for (const auto& [what, read] : readers) {
        try {
          read(path);
          ADD_FAILURE() << what << " read a record numbered " << number;
        } catch (const Error& e) {
          const std::string message = e.what();
          EXPECT_EQ(e.kind(), ErrorKind::kInput) << what << " " << number << ": " << message;
          EXPECT_EQ(message.rfind(path.string() + ": record schema number " + std::to_string(number) + " ", 0), 0u)
              << what << ": " << message;
          EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        }
        EXPECT_EQ(testing::FileBytes(path), before) << what << " " << number;
        EXPECT_FALSE(std::filesystem::exists(dir / "merged.sqlite")) << what;
      }
    }
  }
}

// What the refusal says: a number no version has, or the version whose tables the record holds.
TEST(Schema, AnEditedNumberIsToldFromTheTablesPresent) {
  Database db(":memory:");
  Migrate(db);
  db.Exec("PRAGMA user_version = 1");
  try {
    RequireKnownSchema(db);
    FAIL() << "a current record numbered 1 passed";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("record schema number 1 does not match its tables (it has "), std::string::npos) << message;
    EXPECT_NE(message.find("they are version " + std::to_string(CurrentSchemaVersion()) + "'s); was it edited?"),
              std::string::npos)
        << message;
  }
  db.Exec("PRAGMA user_version = -5");
  EXPECT_THROW(RequireKnownSchema(db), Error);
}

// Genuine records of every version pass the check (each as its own migrations made it), and a column or table of
// the experimenter's own is not held against it.
TEST(Schema, EveryGenuineVersionPassesTheCheck) {
  Database db(":memory:");
  RequireKnownSchema(db);  // an empty file: version 0
  for (int version = 1; version <= CurrentSchemaVersion(); ++version) {
    const Migration& step = Migrations()[size_t(version - 1)];
    if (!step.sql.empty()) db.Exec(step.sql);
    if (step.data) step.data(db);
    db.Exec("PRAGMA user_version = " + std::to_string(version));
    EXPECT_NO_THROW(RequireKnownSchema(db)) << version;
  }
  db.Exec("CREATE TABLE my_notes (x TEXT); ALTER TABLE studies ADD COLUMN my_label TEXT");
  EXPECT_NO_THROW(RequireKnownSchema(db));
}

// sessions reads an earlier version as export does, through a migrated copy (a schema-1 record has no group_name:
// "no such column: s.group_name", exit 10).
TEST(Schema, SessionsListsASchemaOneRecord) {
  testing::TempDir dir;
  const auto path = dir / "old.sqlite";
  {
    Database db(path);
    db.Exec(Migrations()[0].sql);
    db.Exec("PRAGMA user_version = 1;"
            "INSERT INTO studies (name, created) VALUES ('s', 'now');"
            "INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (1, '{}', 'h', 'now');"
            "INSERT INTO participants (study_id, code, created) VALUES (1, 'P1', 'now');"
            "INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, host, display, "
            "  started, status) VALUES (1, 1, 5, 'v', 'h', 'headless', 'now', 'completed');");
  }
  const std::string before = testing::FileBytes(path);
  const std::vector<SessionSummary> sessions = ListSessions(path);
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].study, "s");
  EXPECT_EQ(sessions[0].participant, "P1");
  EXPECT_EQ(sessions[0].number, 1);
  EXPECT_EQ(testing::FileBytes(path), before);
}

}  // namespace
}  // namespace blurcue::store
