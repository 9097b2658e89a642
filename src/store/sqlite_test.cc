#include "store/sqlite.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "core/error.h"
#include "store/test_util.h"

namespace blurcue::store {
namespace {

static_assert(!std::is_copy_assignable_v<Database>);
static_assert(!std::is_copy_assignable_v<Statement>);
static_assert(!std::is_copy_assignable_v<Transaction>);

TEST(Database, MemoryDatabaseRunsStatements) {
  Database db(":memory:");
  db.Exec("CREATE TABLE t (x INTEGER)");
  db.Exec("INSERT INTO t VALUES (1), (2)");
  EXPECT_EQ(db.QueryInt64("SELECT SUM(x) FROM t"), 3);
  EXPECT_EQ(db.QueryInt64("PRAGMA foreign_keys"), 1);
}

TEST(Database, OpeningWritesNothingAWriterUsesWalAndFullSync) {
  testing::TempDir dir;
  Database db(dir / "a.sqlite");
  EXPECT_EQ(db.QueryText("PRAGMA journal_mode"), "delete");
  db.UseWal();
  EXPECT_EQ(db.QueryText("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(db.QueryInt64("PRAGMA synchronous"), 2);  // FULL: a commit survives a power loss
  EXPECT_EQ(db.QueryInt64("PRAGMA foreign_keys"), 1);
}

TEST(Database, NotADatabaseIsInputError) {
  testing::TempDir dir;
  const auto path = dir / "garbage.sqlite";
  std::ofstream(path) << "this is not a database, just some text that is long enough to have a header";
  try {
    Database db(path);
    FAIL() << "opened a text file as a database";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("garbage.sqlite"), std::string::npos) << e.what();
  }
}

TEST(Database, MissingFolderIsInputError) {
  testing::TempDir dir;
  try {
    Database db(dir / "no" / "such" / "folder.sqlite");
    FAIL() << "opened a file in a missing folder";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
  }
}

TEST(Database, ReadOnlyOfMissingFileIsInputError) {
  testing::TempDir dir;
  try {
    Database db(dir / "missing.sqlite", OpenMode::kReadOnly);
    FAIL() << "opened a missing file read-only";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
  }
}

TEST(Statement, BindsAndReadsEveryTypeByIndex) {
  Database db(":memory:");
  db.Exec("CREATE TABLE t (i INTEGER, d REAL, s TEXT, n TEXT)");
  Statement insert(db, "INSERT INTO t VALUES (?, ?, ?, ?)");
  insert.Bind(1, int64_t{-9007199254740993});
  insert.Bind(2, 0.125);
  insert.Bind(3, std::string("a'b,\"c\"\n"));
  insert.BindNull(4);
  insert.Run();
  Statement select(db, "SELECT i, d, s, n FROM t");
  ASSERT_TRUE(select.Step());
  EXPECT_EQ(select.GetInt64(0), -9007199254740993);
  EXPECT_EQ(select.GetDouble(1), 0.125);
  EXPECT_EQ(select.GetText(2), "a'b,\"c\"\n");
  EXPECT_TRUE(select.IsNull(3));
  EXPECT_EQ(select.GetText(3), "");
  EXPECT_FALSE(select.Step());
}

TEST(Statement, BindsByNameAndResets) {
  Database db(":memory:");
  db.Exec("CREATE TABLE t (k TEXT, v INTEGER)");
  Statement insert(db, "INSERT INTO t VALUES (:key, :value)");
  for (int i = 0; i < 3; ++i) {
    std::string key = "k";
    key += std::to_string(i);  // not "k" + ...: GCC 12 warns falsely (-Wrestrict) on that form
    insert.Bind(":key", key);
    insert.Bind(":value", i);
    insert.Run();
    insert.Reset();
  }
  EXPECT_EQ(db.QueryInt64("SELECT SUM(v) FROM t"), 3);
  EXPECT_EQ(db.QueryText("SELECT k FROM t WHERE v = 2"), "k2");
}

TEST(Statement, ErrorCarriesSqlAndSqliteText) {
  Database db(":memory:");
  try {
    Statement bad(db, "SELECT * FROM no_such_table");
    FAIL() << "prepared a query of a missing table";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.kind(), ErrorKind::kInternal);
    EXPECT_NE(what.find("SELECT * FROM no_such_table"), std::string::npos) << what;
    EXPECT_NE(what.find("no such table"), std::string::npos) << what;
  }
}

TEST(Statement, ConstraintFailureThrowsAtStep) {
  Database db(":memory:");
  db.Exec("CREATE TABLE t (x INTEGER UNIQUE)");
  db.Exec("INSERT INTO t VALUES (1)");
  Statement insert(db, "INSERT INTO t VALUES (1)");
  EXPECT_THROW(insert.Run(), Error);
}

TEST(Statement, UnknownParameterNameThrows) {
  Database db(":memory:");
  Statement select(db, "SELECT :a");
  EXPECT_THROW(select.Bind(":b", 1), Error);
}

TEST(Statement, MovedStatementStillSteps) {
  Database db(":memory:");
  Statement first(db, "SELECT 42");
  Statement second(std::move(first));
  ASSERT_TRUE(second.Step());
  EXPECT_EQ(second.GetInt64(0), 42);
}

TEST(Transaction, RollsBackWhenAnExceptionLeavesTheScope) {
  testing::TempDir dir;
  Database db(dir / "t.sqlite");
  db.Exec("CREATE TABLE t (x INTEGER)");
  try {
    Transaction transaction(db);
    db.Exec("INSERT INTO t VALUES (1)");
    throw std::runtime_error("interrupted");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM t"), 0);
  Database other(dir / "t.sqlite");
  EXPECT_EQ(other.QueryInt64("SELECT COUNT(*) FROM t"), 0);
}

TEST(Transaction, CommitKeepsTheRows) {
  testing::TempDir dir;
  {
    Database db(dir / "t.sqlite");
    db.Exec("CREATE TABLE t (x INTEGER)");
    Transaction transaction(db);
    db.Exec("INSERT INTO t VALUES (1)");
    transaction.Commit();
  }
  Database db(dir / "t.sqlite");
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM t"), 1);
}

TEST(Transaction, FailedStatementInsideRollsBackTheEarlierOnes) {
  Database db(":memory:");
  db.Exec("CREATE TABLE t (x INTEGER UNIQUE)");
  EXPECT_THROW(
      {
        Transaction transaction(db);
        db.Exec("INSERT INTO t VALUES (1)");
        db.Exec("INSERT INTO t VALUES (1)");
        transaction.Commit();
      },
      Error);
  EXPECT_EQ(db.QueryInt64("SELECT COUNT(*) FROM t"), 0);
}

TEST(Transaction, SecondWriterWaitsThenFailsBusyWithMessage) {
  testing::TempDir dir;
  Database a(dir / "t.sqlite");
  a.Exec("CREATE TABLE t (x INTEGER)");
  Database b(dir / "t.sqlite", OpenMode::kReadWrite, /*busy_timeout_ms=*/10);
  Transaction first(a);
  try {
    Transaction second(b);
    FAIL() << "two write transactions at once";
  } catch (const Error& e) {
    // The file's problem, named with the file: an input error (exit 3), not an internal one.
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("t.sqlite: busy: another process kept the file locked"), std::string::npos)
        << e.what();
  }
}

// Two stations opening the same new file at the same moment both switch it to WAL: the switch does not wait on the
// busy handler (both hold a shared lock and want it exclusive), so UseWal retries. Without the retry about 1 round
// in 10 failed here with "database is locked".
TEST(Database, TwoProcessesSwitchingANewFileToWalAtOnceBothSucceed) {
  testing::TempDir dir;
  int failures = 0;
  for (int round = 0; round < 150; ++round) {
    const auto path = dir / ("new-" + std::to_string(round) + ".sqlite");
    int go[2];
    ASSERT_EQ(pipe(go), 0);
    pid_t children[2];
    for (pid_t& child : children) {
      child = fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        char byte;
        if (read(go[0], &byte, 1) != 1) _exit(5);
        try {
          Database db(path);
          db.UseWal();
        } catch (const Error& e) {
          std::fprintf(stderr, "round %d: %s\n", round, e.what());
          _exit(e.exit_code());
        }
        _exit(0);
      }
    }
    ASSERT_EQ(write(go[1], "gg", 2), 2);
    for (pid_t child : children) {
      int status = 0;
      ASSERT_EQ(waitpid(child, &status, 0), child);
      failures += !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    close(go[0]);
    close(go[1]);
  }
  EXPECT_EQ(failures, 0);
}

}  // namespace
}  // namespace blurcue::store
