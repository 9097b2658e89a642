#include "store/schema.h"

#include "core/error.h"

namespace blurcue::store {
namespace {

// STRICT tables (SQLite >= 3.37; Debian 12 ships 3.40) refuse a text in an INTEGER column instead of storing
// it quietly. On an older library the same schema is created without the keyword.
std::string Strict() { return SqliteVersionNumber() >= 3037000 ? " STRICT" : ""; }

std::vector<std::string> MakeMigrations() {
  const std::string strict = Strict();
  std::vector<std::string> steps;
  // 1: the whole record. Times are ISO 8601 UTC text; JSON columns hold compact JSON text.
  steps.push_back(
      "CREATE TABLE studies ("
      "  id INTEGER PRIMARY KEY,"
      "  name TEXT NOT NULL UNIQUE,"
      "  created TEXT NOT NULL)" + strict + ";"
      "CREATE TABLE protocol_versions ("
      "  id INTEGER PRIMARY KEY,"
      "  study_id INTEGER NOT NULL REFERENCES studies(id),"
      "  json TEXT NOT NULL,"
      "  hash TEXT NOT NULL,"  // FNV-1a-64 of the JSON text, 16 hex digits
      "  created TEXT NOT NULL,"
      "  UNIQUE (study_id, hash))" + strict + ";"
      "CREATE TABLE participants ("
      "  id INTEGER PRIMARY KEY,"
      "  study_id INTEGER NOT NULL REFERENCES studies(id),"
      "  code TEXT NOT NULL,"
      "  created TEXT NOT NULL,"
      "  UNIQUE (study_id, code))" + strict + ";"
      "CREATE TABLE sessions ("
      "  id INTEGER PRIMARY KEY,"
      "  participant_id INTEGER NOT NULL REFERENCES participants(id),"
      "  protocol_version_id INTEGER NOT NULL REFERENCES protocol_versions(id),"
      "  seed INTEGER NOT NULL,"  // the uint64 seed's bits as int64
      "  software_version TEXT NOT NULL,"
      "  host TEXT NOT NULL,"
      "  display TEXT NOT NULL,"
      "  started TEXT NOT NULL,"
      "  ended TEXT,"
      "  status TEXT NOT NULL CHECK (status IN ('running', 'completed', 'aborted')),"
      "  lock_host TEXT,"  // single writer: who holds the session (NULL = nobody)
      "  lock_pid INTEGER,"
      "  lock_token TEXT,"
      "  lock_heartbeat_ms INTEGER)" + strict + ";"
      "CREATE INDEX sessions_participant ON sessions (participant_id);"
      "CREATE TABLE trials ("
      "  id INTEGER PRIMARY KEY,"
      "  session_id INTEGER NOT NULL REFERENCES sessions(id),"
      "  trial_index INTEGER NOT NULL,"
      "  block INTEGER NOT NULL,"
      "  factors TEXT NOT NULL,"  // JSON object: factor name -> level
      "  left_shown TEXT NOT NULL,"  // JSON: what was shown on the left
      "  right_shown TEXT NOT NULL,"
      "  UNIQUE (session_id, trial_index))" + strict + ";"
      "CREATE TABLE responses ("
      "  id INTEGER PRIMARY KEY,"
      "  trial_id INTEGER NOT NULL UNIQUE REFERENCES trials(id),"
      "  choice TEXT NOT NULL,"
      "  rt_ms REAL,"
      "  adjustment TEXT NOT NULL,"  // JSON array: the levels stepped through (method of adjustment)
      "  answered_at TEXT NOT NULL)" + strict + ";"
      "CREATE TABLE frames ("
      "  id INTEGER PRIMARY KEY,"
      "  trial_id INTEGER NOT NULL REFERENCES trials(id),"
      "  frame_index INTEGER NOT NULL,"
      "  flip_time_s REAL NOT NULL,"
      "  dropped INTEGER NOT NULL CHECK (dropped IN (0, 1)),"
      "  UNIQUE (trial_id, frame_index))" + strict + ";");
  return steps;
}

}  // namespace

const std::vector<std::string>& Migrations() {
  static const std::vector<std::string> steps = MakeMigrations();
  return steps;
}

int CurrentSchemaVersion() { return static_cast<int>(Migrations().size()); }

int SchemaVersion(Database& db) { return static_cast<int>(db.QueryInt64("PRAGMA user_version")); }

void Migrate(Database& db) {
  if (SchemaVersion(db) == CurrentSchemaVersion()) return;  // the common case takes no write lock
  Transaction transaction(db);
  // Read again under the write lock: another process may have migrated in between.
  const int version = SchemaVersion(db);
  if (version > CurrentSchemaVersion())
    throw InputError(db.path(), "record schema version " + std::to_string(version) +
                                    " is newer than this blurcue understands (" +
                                    std::to_string(CurrentSchemaVersion()) + ")");
  for (int i = version; i < CurrentSchemaVersion(); ++i) db.Exec(Migrations()[static_cast<size_t>(i)]);
  db.Exec("PRAGMA user_version = " + std::to_string(CurrentSchemaVersion()));
  transaction.Commit();
}

void RequireCurrentSchema(Database& db) {
  const int version = SchemaVersion(db);
  if (version != CurrentSchemaVersion())
    throw InputError(db.path(), "not a blurcue record at schema version " + std::to_string(CurrentSchemaVersion()) +
                                    ", got version " + std::to_string(version) +
                                    (version == 0 ? " (an empty or foreign database)" : ""));
}

int64_t EnsureStudy(Database& db, const std::string& name, const std::string& created) {
  Statement insert(db, "INSERT INTO studies (name, created) VALUES (?, ?) ON CONFLICT (name) DO NOTHING");
  insert.Bind(1, name);
  insert.Bind(2, created);
  insert.Run();
  Statement find(db, "SELECT id FROM studies WHERE name = ?");
  find.Bind(1, name);
  find.Step();
  return find.GetInt64(0);
}

int64_t EnsureParticipant(Database& db, int64_t study_id, const std::string& code, const std::string& created) {
  Statement insert(db, "INSERT INTO participants (study_id, code, created) VALUES (?, ?, ?) "
                       "ON CONFLICT (study_id, code) DO NOTHING");
  insert.Bind(1, study_id);
  insert.Bind(2, code);
  insert.Bind(3, created);
  insert.Run();
  Statement find(db, "SELECT id FROM participants WHERE study_id = ? AND code = ?");
  find.Bind(1, study_id);
  find.Bind(2, code);
  find.Step();
  return find.GetInt64(0);
}

int64_t EnsureProtocolVersion(Database& db, int64_t study_id, const std::string& json, const std::string& hash,
                              const std::string& created, std::string* stored_json) {
  Statement insert(db, "INSERT INTO protocol_versions (study_id, json, hash, created) VALUES (?, ?, ?, ?) "
                       "ON CONFLICT (study_id, hash) DO NOTHING");
  insert.Bind(1, study_id);
  insert.Bind(2, json);
  insert.Bind(3, hash);
  insert.Bind(4, created);
  insert.Run();
  Statement find(db, "SELECT id, json FROM protocol_versions WHERE study_id = ? AND hash = ?");
  find.Bind(1, study_id);
  find.Bind(2, hash);
  find.Step();
  if (stored_json) *stored_json = find.GetText(1);
  return find.GetInt64(0);
}

}  // namespace blurcue::store
