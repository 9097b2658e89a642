#include "store/schema.h"

#include <gtest/gtest.h>

#include "core/error.h"
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

}  // namespace
}  // namespace blurcue::store
