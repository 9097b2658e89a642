#include "store/sqlite.h"

#include <sqlite3.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <thread>
#include <utility>

#include "core/error.h"

namespace blurcue::store {
namespace {

// What is wrong with the file, in words an experimenter can act on; null for failures that are bugs (a bad
// statement, a constraint the code should have kept), which stay kInternal.
const char* FileProblem(int rc) {
  switch (rc & 0xff) {
    case SQLITE_NOTADB: return "not a SQLite database";
    case SQLITE_CORRUPT: return "the record is damaged (truncated or overwritten)";
    case SQLITE_CANTOPEN: return "cannot open the file";
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return "busy: another process kept the file locked past the timeout; try again";
    case SQLITE_READONLY: return "the file or its folder is read-only";
    case SQLITE_IOERR: return "cannot read or write the file";
    case SQLITE_FULL: return "the disk is full";
    case SQLITE_PERM:
    case SQLITE_AUTH: return "permission denied";
  }
  return nullptr;
}

// A file's problem is the user's input (exit 3, the file named, no SQL); anything else is unexpected.
[[noreturn]] void Throw(sqlite3* db, int rc, const std::string& what, const std::string& sql,
                        const std::string& path = {}) {
  const char* file = db ? sqlite3_db_filename(db, "main") : nullptr;
  std::string where = file && *file ? std::string(file) : path;
  const std::string detail = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  if (const char* problem = FileProblem(rc))
    throw Error(ErrorKind::kInput, (where.empty() ? std::string("sqlite") : where) + ": " + problem + " (sqlite: " +
                                       detail + ")");
  std::string message = "sqlite: " + what + " failed: " + detail;
  if (!where.empty()) message = where + ": " + message;
  if (!sql.empty()) message += " (SQL: " + sql + ")";
  throw Error(ErrorKind::kInternal, message);
}

// A path as a file: URI (RFC 3986 percent-encoding of everything but unreserved characters and '/').
std::string FileUri(const std::filesystem::path& path) {
  const std::string text = std::filesystem::absolute(path).string();
  std::string uri = "file:";
  for (unsigned char c : text) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') {
      uri += static_cast<char>(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      uri += hex;
    }
  }
  return uri;
}

}  // namespace

int SqliteVersionNumber() { return sqlite3_libversion_number(); }

// ---------------------------------------------------------------------------------------------- Database

Database::Database(const std::filesystem::path& path, OpenMode mode, int busy_timeout_ms)
    : path_(path.string()), busy_timeout_ms_(busy_timeout_ms) {
  const bool memory = path_ == ":memory:";
  if (!memory) {
    std::error_code error;
    const auto status = std::filesystem::status(path, error);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
      throw InputError(path_, std::string("not a record file (") +
                                  (std::filesystem::is_directory(status) ? "a folder" : "a device or pipe") +
                                  "); a record is one SQLite file");
  }
  auto open = [&](const std::string& name, int flags) {
    sqlite3* db = nullptr;
    const int rc = sqlite3_open_v2(name.c_str(), &db, flags | SQLITE_OPEN_NOMUTEX, nullptr);
    if (rc != SQLITE_OK) {
      const std::string text = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
      sqlite3_close(db);  // a handle is returned even on failure and must be released
      throw Error(ErrorKind::kInput, path_ + ": cannot open the record: " + text);
    }
    db_ = db;
    sqlite3_extended_result_codes(db_, 1);
    if (memory) return;
    const int busy = sqlite3_busy_timeout(db_, busy_timeout_ms);
    if (busy != SQLITE_OK) Throw(db_, busy, "busy_timeout", "");
    // The first read of the header: a file that is not a database, or is damaged, is reported here as kInput.
    QueryInt64("PRAGMA schema_version");
  };
  auto close = [&] {
    sqlite3_close(db_);
    db_ = nullptr;
  };
  try {
    open(path_, mode == OpenMode::kReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  } catch (const Error& e) {
    close();
    // A WAL record in a read-only folder (an archive, a read-only mount): SQLite cannot create the WAL index beside
    // it. Without a -wal file holding unmerged commits, the file alone is the whole record: open it as immutable.
    std::error_code error;
    const bool wal_pending = std::filesystem::file_size(path_ + "-wal", error) > 0 && !error;
    if (mode != OpenMode::kReadOnly || memory || e.kind() != ErrorKind::kInput) throw;
    if (wal_pending)
      throw InputError(path_, "read-only, and its write-ahead log " + path_ +
                                  "-wal holds commits not yet merged into it; copy both files to a writable folder "
                                  "and open the copy");
    try {
      open(FileUri(path_) + "?immutable=1", SQLITE_OPEN_READONLY | SQLITE_OPEN_URI);
    } catch (...) {
      close();
      throw e;
    }
  }
  try {
    Exec("PRAGMA foreign_keys=ON");
  } catch (...) {
    close();
    throw;
  }
}

void Database::UseWal(bool durable) {
  if (path_ == ":memory:") return;
  // Changing the journal mode needs the file to itself and does not wait on the busy handler: retry while another
  // connection (a second station starting at the same moment) holds it.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(busy_timeout_ms_);
  for (;;) {
    try {
      if (QueryText("PRAGMA journal_mode=WAL") != "wal") throw InputError(path_, "cannot switch the record to WAL "
                                                                                 "journaling (a read-only file?)");
      break;
    } catch (const Error& e) {
      const int code = sqlite3_errcode(db_) & 0xff;
      if ((code != SQLITE_BUSY && code != SQLITE_LOCKED) || std::chrono::steady_clock::now() >= deadline) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  Exec(durable ? "PRAGMA synchronous=FULL" : "PRAGMA synchronous=NORMAL");
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
  sqlite3_free(error);  // sqlite3_errmsg holds the same text
  if (rc != SQLITE_OK) Throw(db_, rc, "exec", sql, path_);
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
