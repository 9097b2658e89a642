#include "store/sqlite.h"

#include <sqlite3.h>

#include <utility>

#include "core/error.h"

namespace blurcue::store {
namespace {

// A file that cannot be opened or is not a database is the user's input; anything else is unexpected.
ErrorKind KindOf(int rc) {
  const int primary = rc & 0xff;
  return (primary == SQLITE_NOTADB || primary == SQLITE_CANTOPEN) ? ErrorKind::kInput : ErrorKind::kInternal;
}

[[noreturn]] void Throw(sqlite3* db, int rc, const std::string& what, const std::string& sql) {
  std::string message = "sqlite: ";
  const char* file = db ? sqlite3_db_filename(db, "main") : nullptr;
  if (file && *file) message = std::string(file) + ": " + message;
  message += what + " failed: " + (db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
  if (!sql.empty()) message += " (SQL: " + sql + ")";
  throw Error(KindOf(rc), message);
}

}  // namespace

int SqliteVersionNumber() { return sqlite3_libversion_number(); }

// ---------------------------------------------------------------------------------------------- Database

Database::Database(const std::filesystem::path& path, OpenMode mode, int busy_timeout_ms) : path_(path.string()) {
  const bool memory = path_ == ":memory:";
  const int flags = (mode == OpenMode::kReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE) |
                    SQLITE_OPEN_NOMUTEX;
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(path_.c_str(), &db, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string text = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
    sqlite3_close(db);  // a handle is returned even on failure and must be released
    throw Error(ErrorKind::kInput, path_ + ": cannot open SQLite database: " + text);
  }
  db_ = db;
  sqlite3_extended_result_codes(db_, 1);
  try {
    if (!memory) {
      const int busy = sqlite3_busy_timeout(db_, busy_timeout_ms);
      if (busy != SQLITE_OK) Throw(db_, busy, "busy_timeout", "");
      // The first read of the header: a file that is not a database is reported here, as kInput.
      QueryInt64("PRAGMA schema_version");
      if (mode == OpenMode::kReadWrite) {
        if (QueryText("PRAGMA journal_mode=WAL") != "wal")
          throw Error(ErrorKind::kInternal, path_ + ": sqlite: could not switch to WAL journaling");
        Exec("PRAGMA synchronous=NORMAL");
      }
    }
    Exec("PRAGMA foreign_keys=ON");
  } catch (const Error& e) {
    sqlite3_close(db_);
    db_ = nullptr;
    if (e.kind() == ErrorKind::kInput) throw Error(ErrorKind::kInput, path_ + ": not a SQLite database (" + e.what() + ")");
    throw;
  }
}

Database::~Database() {
  // sqlite3_close_v2 defers the close until every statement is finalized; it never fails on a valid handle.
  if (db_) sqlite3_close_v2(db_);
}

Database::Database(Database&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)), path_(std::move(other.path_)) {}

Database& Database::operator=(Database&& other) noexcept {
  if (this != &other) {
    if (db_) sqlite3_close_v2(db_);
    db_ = std::exchange(other.db_, nullptr);
    path_ = std::move(other.path_);
  }
  return *this;
}

void Database::Exec(const std::string& sql) {
  char* error = nullptr;
  const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error);
  if (rc != SQLITE_OK) {
    std::string text = error ? error : sqlite3_errstr(rc);
    sqlite3_free(error);
    std::string message = "sqlite: exec failed: " + text + " (SQL: " + sql + ")";
    if (!path_.empty() && path_ != ":memory:") message = path_ + ": " + message;
    throw Error(KindOf(rc), message);
  }
}

int64_t Database::QueryInt64(const std::string& sql) {
  Statement statement(*this, sql);
  if (!statement.Step()) throw Error(ErrorKind::kInternal, "sqlite: query returned no row (SQL: " + sql + ")");
  return statement.GetInt64(0);
}

std::string Database::QueryText(const std::string& sql) {
  Statement statement(*this, sql);
  if (!statement.Step()) throw Error(ErrorKind::kInternal, "sqlite: query returned no row (SQL: " + sql + ")");
  return statement.GetText(0);
}

int64_t Database::LastInsertRowId() const { return sqlite3_last_insert_rowid(db_); }

int Database::Changes() const { return sqlite3_changes(db_); }

// ---------------------------------------------------------------------------------------------- Statement

Statement::Statement(Database& db, std::string sql) : db_(db.handle()), sql_(std::move(sql)) {
  if (!db_) throw Error(ErrorKind::kInternal, "sqlite: prepare on a closed database (SQL: " + sql_ + ")");
  const char* tail = nullptr;
  const int rc = sqlite3_prepare_v2(db_, sql_.c_str(), static_cast<int>(sql_.size() + 1), &stmt_, &tail);
  if (rc != SQLITE_OK) Throw(db_, rc, "prepare", sql_);
  if (!stmt_) throw Error(ErrorKind::kInternal, "sqlite: prepare of an empty statement (SQL: " + sql_ + ")");
  for (; tail && *tail; ++tail) {
    if (*tail != ' ' && *tail != '\n' && *tail != '\t' && *tail != ';') {
      sqlite3_finalize(stmt_);
      throw Error(ErrorKind::kInternal, "sqlite: a Statement holds one statement, got more (SQL: " + sql_ + ")");
    }
  }
}

Statement::~Statement() {
  if (stmt_) sqlite3_finalize(stmt_);
}

Statement::Statement(Statement&& other) noexcept
    : db_(other.db_), stmt_(std::exchange(other.stmt_, nullptr)), sql_(std::move(other.sql_)) {}

Statement& Statement::operator=(Statement&& other) noexcept {
  if (this != &other) {
    if (stmt_) sqlite3_finalize(stmt_);
    db_ = other.db_;
    stmt_ = std::exchange(other.stmt_, nullptr);
    sql_ = std::move(other.sql_);
  }
  return *this;
}

void Statement::CheckBind(int rc, int index) const {
  if (rc != SQLITE_OK) Throw(db_, rc, "bind of parameter " + std::to_string(index), sql_);
}

void Statement::Bind(int index, int64_t value) { CheckBind(sqlite3_bind_int64(stmt_, index, value), index); }

void Statement::Bind(int index, double value) { CheckBind(sqlite3_bind_double(stmt_, index, value), index); }

void Statement::Bind(int index, std::string_view text) {
  CheckBind(sqlite3_bind_text64(stmt_, index, text.data(), text.size(), SQLITE_TRANSIENT, SQLITE_UTF8), index);
}

void Statement::BindNull(int index) { CheckBind(sqlite3_bind_null(stmt_, index), index); }

int Statement::IndexOf(const char* name) const {
  const int index = sqlite3_bind_parameter_index(stmt_, name);
  if (index == 0)
    throw Error(ErrorKind::kInternal, std::string("sqlite: no parameter named ") + name + " (SQL: " + sql_ + ")");
  return index;
}

bool Statement::Step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  Throw(db_, rc, "step", sql_);
}

void Statement::Run() {
  if (Step()) throw Error(ErrorKind::kInternal, "sqlite: statement returned rows where none were expected (SQL: " + sql_ + ")");
}

void Statement::Reset() {
  // sqlite3_reset repeats the last step's error, which Step() has already reported; bindings are cleared after.
  sqlite3_reset(stmt_);
  const int rc = sqlite3_clear_bindings(stmt_);
  if (rc != SQLITE_OK) Throw(db_, rc, "clear_bindings", sql_);
}

int Statement::ColumnCount() const { return sqlite3_column_count(stmt_); }

void Statement::CheckColumn(int column) const {
  if (column < 0 || column >= sqlite3_column_count(stmt_))
    throw Error(ErrorKind::kInternal, "sqlite: column " + std::to_string(column) + " out of range (SQL: " + sql_ + ")");
}

bool Statement::IsNull(int column) const {
  CheckColumn(column);
  return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

int64_t Statement::GetInt64(int column) const {
  CheckColumn(column);
  return sqlite3_column_int64(stmt_, column);
}

double Statement::GetDouble(int column) const {
  CheckColumn(column);
  return sqlite3_column_double(stmt_, column);
}

std::string Statement::GetText(int column) const {
  CheckColumn(column);
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
  if (!text) {
    if (sqlite3_errcode(db_) == SQLITE_NOMEM) Throw(db_, SQLITE_NOMEM, "column_text", sql_);
    return {};
  }
  return std::string(text, static_cast<size_t>(sqlite3_column_bytes(stmt_, column)));
}

// ---------------------------------------------------------------------------------------------- Transaction

Transaction::Transaction(Database& db) : db_(&db) { db_->Exec("BEGIN IMMEDIATE"); }

Transaction::~Transaction() {
  if (db_ && !done_ && db_->handle()) {
    // Destructors never throw: a failed rollback leaves the transaction to be rolled back when the connection
    // closes, which SQLite does by itself.
    sqlite3_exec(db_->handle(), "ROLLBACK", nullptr, nullptr, nullptr);
  }
}

Transaction::Transaction(Transaction&& other) noexcept
    : db_(std::exchange(other.db_, nullptr)), done_(other.done_) {}

void Transaction::Commit() {
  if (!db_ || done_) throw Error(ErrorKind::kInternal, "sqlite: commit of a finished transaction");
  db_->Exec("COMMIT");
  done_ = true;
}

}  // namespace blurcue::store
