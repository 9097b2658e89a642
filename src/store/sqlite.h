#pragma once
// Move-only RAII handles over the SQLite C API, after SQLiteCpp. Every sqlite3_* result is checked; a failure
// throws blurcue::Error whose message carries the SQL and SQLite's own error text. Destructors never throw.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>

struct sqlite3;
struct sqlite3_stmt;

namespace blurcue::store {

enum class OpenMode { kReadWrite, kReadOnly };

// One connection with a busy timeout and foreign_keys=ON; ":memory:" opens a private in-memory database. Opening
// only reads the header: a writer switches the file to WAL with UseWal() once it knows the file is its own.
// Read-only opening works on a read-only folder or mount too (an archived record): when SQLite cannot make the WAL
// index beside the file, the file is opened as immutable, unless an unmerged -wal file lies beside it (its answers
// would be missed silently), which is refused.
// Throws Error(kInput) for a file that cannot be opened, is not a database, or stays busy past the timeout.
class Database {
 public:
  explicit Database(const std::filesystem::path& path, OpenMode mode = OpenMode::kReadWrite,
                    int busy_timeout_ms = 5000);
  ~Database();
  Database(Database&& other) noexcept;
  Database& operator=(Database&& other) noexcept;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  // WAL journaling with synchronous=FULL (`durable`): a commit, once returned, survives a killed process, an OS
  // crash and a power loss; NORMAL in WAL mode survives only the first. Retries while another connection holds the
  // file (two first starts at once), up to the busy timeout.
  void UseWal(bool durable = true);

  // Runs one or more statements that return no rows.
  void Exec(const std::string& sql);
  // First column of the first row of a query as an integer (throws if there is no row).
  int64_t QueryInt64(const std::string& sql);
  // First column of the first row as text (throws if there is no row).
  std::string QueryText(const std::string& sql);

  int64_t LastInsertRowId() const;
  int Changes() const;
  const std::string& path() const { return path_; }
  sqlite3* handle() const { return db_; }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
  int busy_timeout_ms_ = 0;
};

// A prepared statement; finalizes itself. Indices are 1-based for Bind and 0-based for columns, as in SQLite.
class Statement {
 public:
  Statement(Database& db, std::string sql);
  ~Statement();
  Statement(Statement&& other) noexcept;
  Statement& operator=(Statement&& other) noexcept;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void Bind(int index, int64_t value);
  void Bind(int index, int value) { Bind(index, static_cast<int64_t>(value)); }
  void Bind(int index, double value);
  void Bind(int index, std::string_view text);
  void Bind(int index, const char* text) { Bind(index, std::string_view(text)); }
  void Bind(int index, const std::string& text) { Bind(index, std::string_view(text)); }
  void BindNull(int index);
  // By parameter name including its prefix, e.g. ":study".
  template <typename T>
  void Bind(const char* name, const T& value) { Bind(IndexOf(name), value); }
  void BindNull(const char* name) { BindNull(IndexOf(name)); }

  // Advances; true when a row is available, false when the statement is done.
  bool Step();
  // Steps a statement that must not return rows (INSERT, UPDATE, ...).
  void Run();
  // Rewinds for another run and clears the bindings.
  void Reset();

  int ColumnCount() const;
  bool IsNull(int column) const;
  int64_t GetInt64(int column) const;
  double GetDouble(int column) const;
  std::string GetText(int column) const;  // "" for NULL

  const std::string& sql() const { return sql_; }

 private:
  int IndexOf(const char* name) const;
  void CheckColumn(int column) const;
  void CheckBind(int rc, int index) const;

  sqlite3* db_ = nullptr;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
};

// BEGIN IMMEDIATE (takes the write lock up front, so two writers never deadlock half-way); rolls back in its
// destructor unless Commit() was called.
class Transaction {
 public:
  explicit Transaction(Database& db);
  ~Transaction();
  Transaction(Transaction&& other) noexcept;
  Transaction& operator=(Transaction&&) = delete;
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;

  void Commit();

 private:
  Database* db_ = nullptr;
  bool done_ = false;
};

static_assert(!std::is_copy_constructible_v<Database> && std::is_nothrow_move_constructible_v<Database>);
static_assert(!std::is_copy_constructible_v<Statement> && std::is_nothrow_move_constructible_v<Statement>);
static_assert(!std::is_copy_constructible_v<Transaction> && std::is_nothrow_move_constructible_v<Transaction>);

// The linked library's version number, e.g. 3040001 (STRICT tables need 3037000).
int SqliteVersionNumber();

}  // namespace blurcue::store
