#include "store/schema.h"

#include <sqlite3.h>

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <set>

#include "core/error.h"
#include "core/hash.h"
#include "core/json_io.h"
#include "store/columns.h"
#include "store/frame_columns.h"
#include "store/procedures.h"

namespace blurcue::store {
namespace {

// STRICT tables (SQLite >= 3.37; Debian 12 ships 3.40) refuse a text in an INTEGER column instead of storing
// it quietly. On an older library the same schema is created without the keyword.
std::string Strict() { return SqliteVersionNumber() >= 3037000 ? " STRICT" : ""; }

// Version 2: a protocol's hash is that of its canonical text (it was the raw file's bytes). Versions whose texts
// differ only in formatting become one; their sessions then share it.
void CanonicalProtocolHashes(Database& db) {
  Statement rows(db, "SELECT id, study_id, json FROM protocol_versions ORDER BY id");
  Statement same(db, "SELECT id FROM protocol_versions WHERE study_id = ? AND hash = ? AND id <> ?");
  Statement repoint(db, "UPDATE sessions SET protocol_version_id = ? WHERE protocol_version_id = ?");
  Statement drop(db, "DELETE FROM protocol_versions WHERE id = ?");
  Statement update(db, "UPDATE protocol_versions SET json = ?, hash = ? WHERE id = ?");
  struct Row {
    int64_t id, study;
    std::string json;
  };
  std::vector<Row> all;
  while (rows.Step()) all.push_back({rows.GetInt64(0), rows.GetInt64(1), rows.GetText(2)});
  for (const Row& row : all) {
    std::string canonical;
    try {
      canonical = CanonicalProtocolText(row.json);
    } catch (const Error&) {
      continue;  // a text that is not JSON keeps its old hash: nothing can resume it anyway
    }
    const std::string hash = ProtocolHash(canonical);
    same.Bind(1, row.study);
    same.Bind(2, hash);
    same.Bind(3, row.id);
    if (same.Step()) {
      repoint.Bind(1, same.GetInt64(0));
      repoint.Bind(2, row.id);
      repoint.Run();
      repoint.Reset();
      drop.Bind(1, row.id);
      drop.Run();
      drop.Reset();
    } else {
      update.Bind(1, canonical);
      update.Bind(2, hash);
      update.Bind(3, row.id);
      update.Run();
      update.Reset();
    }
    same.Reset();
  }
}

// 10: each protocol version's adaptive procedures, one row per block with a procedure (procedures.h: its columns are
// ProcedureColumns' since 10), recorded when the version's first session starts; a record of before gets them from
// its recorded texts (DeriveProcedures), which export used to parse at every export.
Migration ProceduresStep(const std::string& strict) {
  return {"CREATE TABLE procedures ("
          "  protocol_version_id INTEGER NOT NULL REFERENCES protocol_versions(id)" +
              CreatedColumnsSql(ProcedureColumns(), 10) + ", PRIMARY KEY (protocol_version_id, block))" + strict + ";",
          [](Database& db) { DeriveProcedures(db); }};
}

std::vector<Migration> MakeMigrations() {
  const std::string strict = Strict();
  std::vector<Migration> steps;
  // 1: the whole record. Times are ISO 8601 UTC text; JSON columns hold compact JSON text.
  steps.push_back({
      "CREATE TABLE studies ("
      "  id INTEGER PRIMARY KEY,"
      "  name TEXT NOT NULL UNIQUE,"
      "  created TEXT NOT NULL)" + strict + ";"
      "CREATE TABLE protocol_versions ("
      "  id INTEGER PRIMARY KEY,"
      "  study_id INTEGER NOT NULL REFERENCES studies(id),"
      "  json TEXT NOT NULL,"
      "  hash TEXT NOT NULL,"  // FNV-1a-64 of the JSON text, 16 hex digits (version 2: of its canonical text)
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
      "  UNIQUE (trial_id, frame_index))" + strict + ";"});
  steps.push_back({"", &CanonicalProtocolHashes});
  // 3: the display profile each session ran with (display/profile.h ToJson); '{}' for sessions from before.
  steps.push_back({"ALTER TABLE sessions ADD COLUMN display_profile TEXT NOT NULL DEFAULT '{}';"});
  // 4: what each frame showed of a pair (moving balls change radius from frame to frame): each side's radius in
  // photo px and the objects' place along the board's y in mm; NULL where nothing was shown and before version 4.
  // (frame_columns.h's columns that say since 4: r_left_px, r_right_px, y_mm).
  steps.push_back({AddTableColumnsSql("frames", FrameColumns(), 4)});
  // 5: what a trial showed as decided when it was shown (an adaptive procedure's level and the radii it made, the
  // answer's correctness): a JSON object of trial variables export lays over the planned ones; '{}' otherwise.
  steps.push_back({"ALTER TABLE responses ADD COLUMN shown TEXT NOT NULL DEFAULT '{}';"});
  // 6: the between-subject group a session ran ('' without groups) and the participant information given (JSON).
  steps.push_back({"ALTER TABLE sessions ADD COLUMN group_name TEXT NOT NULL DEFAULT '';"
                   "ALTER TABLE sessions ADD COLUMN participant_info TEXT NOT NULL DEFAULT '{}';"});
  // 7: the typed record - what earlier versions kept only in JSON texts or free text, in columns of one type each
  // (NULL where a record of an earlier version did not say; DeriveTypedColumns fills them from those texts).
  //  sessions: who answered (observer: person | simulated, and the simulated observer's parameters), where (window:
  //  1 a real window on the real clock, 0 headless on a simulated one), and the display profile's geometry;
  //  session_info: the participant information given, one row per key;
  //  trials: the block's name and task (forced_choice, adjustment, yes_no, rating), practice and swapped flags, each side's source (none, measured, measured_section,
  //  estimated, fitted, fixed_px, fixed_screen_px, fixed_arcmin) and fixed radius, the radii planned (photo px);
  //  responses: what an adaptive procedure showed and scored (level, correct) and the radii shown (photo px).
  // Its columns are the column table's (columns.h) that say since 7; then the participant information's table.
  steps.push_back({AddColumnsSql(RecordColumns(), 7) +
                       "CREATE TABLE session_info ("
                       "  session_id INTEGER NOT NULL REFERENCES sessions(id),"
                       "  key TEXT NOT NULL,"
                       "  value TEXT NOT NULL,"
                       "  PRIMARY KEY (session_id, key))" + strict + ";",
                   &DeriveTypedColumns});
  // 8: the design reaches the record. protocol_versions: the protocol's declared "version" (a study's texts differ
  // only under distinct versions from here on); sessions: the participant's n-th session of the study (decided with
  // the insert, in its transaction); trials: a procedure trial's cell by its levels ("edge=9"); design_columns: per
  // protocol version, every column the design puts in trials.csv with its role and the values the protocol allows.
  // The columns (protocol_versions.version, sessions.session_number, trials.cell) are the column table's since 8.
  steps.push_back({AddColumnsSql(RecordColumns(), 8) +
                   "CREATE UNIQUE INDEX sessions_number ON sessions (participant_id, session_number);"
                   "CREATE TABLE design_columns ("
                   "  protocol_version_id INTEGER NOT NULL REFERENCES protocol_versions(id),"
                   "  position INTEGER NOT NULL,"
                   "  name TEXT NOT NULL,"
                   "  role TEXT NOT NULL CHECK (role IN ('within', 'group', 'procedure_cell', 'label', 'practice')),"
                   "  type TEXT NOT NULL CHECK (type IN ('integer', 'number', 'string', 'boolean')),"
                   "  unit TEXT NOT NULL,"
                   "  allowed TEXT NOT NULL,"
                   "  PRIMARY KEY (protocol_version_id, name))" + strict + ";",
                   &DeriveVersionsAndNumbers});
  // 9: a study on video - what each frame showed of the take (frame_columns.h: the take's frame and status, each
  // side's lens floor and motion streak); NULL for photos and before version 9.
  steps.push_back({AddColumnsSql(RecordColumns(), 9) + AddTableColumnsSql("frames", FrameColumns(), 9)});
  steps.push_back(ProceduresStep(strict));
  // 11 on: a typed column the column table adds with `since` N is migration N (NULL in the rows already there). A
  // version that needs more (a table, a derivation from older texts) is written above as its own step.
  int last = 0;
  for (const Column& c : RecordColumns()) last = std::max({last, c.at.since, c.shown.since});
  for (int version = int(steps.size()) + 1; version <= last; ++version)
    steps.push_back({AddColumnsSql(RecordColumns(), version)});
  return steps;
}

}  // namespace

void DeriveTypedColumns(Database& db) {
  // Sessions: the free-text display said "window ..." or "headless ..." and, for a simulated observer, "; observer
  // sim:..." at its end.
  // Each column as the table derives it (columns.h Stored::derive).
  db.Exec("UPDATE sessions SET " + DerivedColumnsSql(RecordColumns(), "sessions") + " WHERE observer IS NULL");
  db.Exec("INSERT OR IGNORE INTO session_info (session_id, key, value) "
          "SELECT s.id, j.key, CASE j.type WHEN 'text' THEN j.value ELSE json_quote(j.value) END "
          "FROM sessions s, json_each(s.participant_info) j "
          "WHERE json_valid(s.participant_info) AND json_type(s.participant_info) = 'object'");
  // Trials: the variables the runner wrote into the factors text, and each side's source from what was shown.
  db.Exec("UPDATE trials SET " + DerivedColumnsSql(RecordColumns(), "trials") + " "
          "WHERE block_name IS NULL AND json_valid(factors) AND json_valid(left_shown) AND json_valid(right_shown)");
  db.Exec("UPDATE responses SET " + DerivedColumnsSql(RecordColumns(), "responses") + " "
          "WHERE json_valid(shown) AND shown <> '{}' AND level IS NULL AND correct IS NULL");
}

void DeriveVersionsAndNumbers(Database& db) {
  // A protocol without "version" is version 1 (the parser's default); a text that is not JSON cannot be run again.
  db.Exec("UPDATE protocol_versions SET version = CASE WHEN json_valid(json) AND json_type(json, '$.version') = "
          "'integer' AND json_extract(json, '$.version') >= 1 THEN json_extract(json, '$.version') ELSE 1 END "
          "WHERE version IS NULL");
  NumberSessions(db, false);
  // An answer is scored once, when it is given (Response::correct); an odd one out answered before the runner
  // recorded it is scored here from its trial's odd interval, so that export reads every correct and scores none.
  db.Exec("UPDATE responses SET correct = (choice = (SELECT CAST(json_extract(t.factors, '$.odd_interval') AS TEXT) "
          "FROM trials t WHERE t.id = responses.trial_id)) "
          "WHERE correct IS NULL AND choice <> '' AND choice NOT GLOB '*[^0-9]*' AND (SELECT json_extract(t.factors, "
          "'$.odd_interval') FROM trials t WHERE t.id = responses.trial_id AND json_valid(t.factors)) IS NOT NULL");
}

void NumberSessions(Database& db, bool all) {
  // Cleared first: the unique (participant, number) index is checked row by row while the numbers move.
  const std::string which = all ? std::string("1") : "participant_id IN (SELECT participant_id FROM sessions WHERE "
                                                     "session_number IS NULL)";
  db.Exec("UPDATE sessions SET session_number = NULL WHERE " + which);
  db.Exec("UPDATE sessions SET session_number = (SELECT n FROM (SELECT id, row_number() OVER (PARTITION BY "
          "participant_id ORDER BY started, id) AS n FROM sessions) x WHERE x.id = sessions.id) "
          "WHERE session_number IS NULL");
}

const std::vector<Migration>& Migrations() {
  static const std::vector<Migration> steps = MakeMigrations();
  return steps;
}

int CurrentSchemaVersion() { return static_cast<int>(Migrations().size()); }

int SchemaVersion(Database& db) { return static_cast<int>(db.QueryInt64("PRAGMA user_version")); }

void Migrate(Database& db) {
  if (SchemaVersion(db) == CurrentSchemaVersion()) return;  // the common case takes no write lock
  Transaction transaction(db);
  // Read again under the write lock: another process may have migrated in between. A number this build does not
  // know, or one its tables contradict, is refused before a step runs (a negative one indexed past the steps and
  // crashed; a current record stamped 1 replayed version 2 on and stopped with "duplicate column").
  RequireKnownSchema(db);
  const int version = SchemaVersion(db);
  for (int i = version; i < CurrentSchemaVersion(); ++i) {
    const Migration& step = Migrations()[static_cast<size_t>(i)];
    if (!step.sql.empty()) db.Exec(step.sql);
    if (step.data) step.data(db);
  }
  db.Exec("PRAGMA user_version = " + std::to_string(CurrentSchemaVersion()));
  db.Exec("PRAGMA application_id = " + std::to_string(kApplicationId));
  transaction.Commit();
}

namespace {

// What the file holds, for the message that refuses it: its application id and its first tables.
std::string Contents(Database& db) {
  std::string tables = db.QueryText("SELECT coalesce(group_concat(name, ', '), '') FROM (SELECT name FROM "
                                    "sqlite_schema WHERE type = 'table' ORDER BY name LIMIT 6)");
  const int64_t count = db.QueryInt64("SELECT count(*) FROM sqlite_schema WHERE type = 'table'");
  if (count > 6) tables += ", ...";
  const int64_t id = db.QueryInt64("PRAGMA application_id");
  char text[32];
  std::snprintf(text, sizeof text, "%08llx", static_cast<unsigned long long>(static_cast<uint32_t>(id)));
  return std::to_string(count) + " tables (" + tables + ")" + (id != 0 ? ", application id 0x" + std::string(text) : "");
}

// A record written before the application id was stamped: the record's own tables. (Its schema number is judged by
// RequireKnownSchema, which names it: an edited 0 or -5 used to be called "not a blurcue record".)
bool IsUnstampedRecord(Database& db) {
  return db.QueryInt64("SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND name IN ('studies', "
                       "'protocol_versions', 'participants', 'sessions', 'trials', 'responses', 'frames')") == 7;
}

// Each version's columns ("table.column"), index = version: the shipped steps applied one by one to an empty
// database in memory, so they are what a genuine record of that version holds.
const std::vector<std::set<std::string>>& ColumnsByVersion() {
  static const std::vector<std::set<std::string>> by_version = [] {
    Database db(":memory:");
    std::vector<std::set<std::string>> out;
    for (size_t version = 0;; ++version) {
      std::set<std::string> columns;
      Statement all(db, "SELECT t.name || '.' || c.name FROM sqlite_schema t, pragma_table_info(t.name) c "
                        "WHERE t.type = 'table' AND t.name NOT LIKE 'sqlite_%'");
      while (all.Step()) columns.insert(all.GetText(0));
      out.push_back(std::move(columns));
      if (version == Migrations().size()) break;
      const Migration& step = Migrations()[version];
      if (!step.sql.empty()) db.Exec(step.sql);
      if (step.data) step.data(db);
    }
    return out;
  }();
  return by_version;
}

// The columns of `db` that some version of this build knows (a column or table of the experimenter's own is no
// version's and is left out of the comparison).
std::set<std::string> KnownColumnsOf(Database& db) {
  const std::set<std::string>& known = ColumnsByVersion().back();
  std::set<std::string> present;
  Statement all(db, "SELECT t.name || '.' || c.name FROM sqlite_schema t, pragma_table_info(t.name) c "
                    "WHERE t.type = 'table' AND t.name NOT LIKE 'sqlite_%'");
  while (all.Step())
    if (std::string name = all.GetText(0); known.count(name)) present.insert(std::move(name));
  return present;
}

// Up to three names of `names`, for a message.
std::string FewOf(const std::vector<std::string>& names) {
  std::string text;
  for (size_t i = 0; i < names.size() && i < 3; ++i) text += (i ? ", " : "") + names[i];
  if (names.size() > 3) text += ", ... (" + std::to_string(names.size()) + " in all)";
  return text;
}

}  // namespace

void RequireKnownSchema(Database& db) {
  const int64_t version = db.QueryInt64("PRAGMA user_version");  // 32-bit signed in the file's header
  const int current = CurrentSchemaVersion();
  const std::string number = "record schema number " + std::to_string(version);
  if (version > current)
    throw InputError(db.path(), number + " is newer than this blurcue reads (" + std::to_string(current) +
                                    "); update blurcue");
  if (version < 0)
    throw InputError(db.path(), number + " is no version (this blurcue knows 1 to " + std::to_string(current) +
                                    "); was it edited? The record was left untouched");
  const std::set<std::string>& expected = ColumnsByVersion()[static_cast<size_t>(version)];
  const std::set<std::string> present = KnownColumnsOf(db);
  if (present == expected) return;
  std::vector<std::string> extra, missing;
  std::set_difference(present.begin(), present.end(), expected.begin(), expected.end(), std::back_inserter(extra));
  std::set_difference(expected.begin(), expected.end(), present.begin(), present.end(), std::back_inserter(missing));
  std::string whose;
  for (int v = current; v >= 0; --v)
    if (ColumnsByVersion()[static_cast<size_t>(v)] == present) {
      whose = "; they are version " + std::to_string(v) + "'s";
      break;
    }
  std::string what;
  if (!extra.empty()) what = "it has " + FewOf(extra) + ", which version " + std::to_string(version) + " has not";
  if (!missing.empty())
    what += (what.empty() ? "it lacks " : ", and lacks ") + FewOf(missing) + ", which version " +
            std::to_string(version) + " has";
  throw InputError(db.path(), number + " does not match its tables (" + what + whose +
                                  "); was it edited? The record was left untouched");
}

Database OpenRecordForReading(const std::filesystem::path& path) {
  Database source(path, OpenMode::kReadOnly);
  RequireReadableRecord(source);
  if (SchemaVersion(source) == CurrentSchemaVersion()) return source;
  // An earlier version is read from a migrated copy in memory: the record itself is only read (it may be a read-only
  // archive, and a killed reader leaves no copy behind). SQLite's backup copies it, the migration derives its typed
  // columns.
  Database copy(":memory:");
  sqlite3_backup* backup = sqlite3_backup_init(copy.handle(), "main", source.handle(), "main");
  const int step = backup ? sqlite3_backup_step(backup, -1) : SQLITE_ERROR;
  const int finish = backup ? sqlite3_backup_finish(backup) : SQLITE_ERROR;
  if (step != SQLITE_DONE || finish != SQLITE_OK)
    throw InputError(path.string(), std::string("cannot copy the record to read it at this version: ") +
                                        sqlite3_errmsg(copy.handle()));
  Migrate(copy);
  return copy;
}

void RequireRecordOrEmpty(Database& db) {
  const int64_t id = db.QueryInt64("PRAGMA application_id");
  const int64_t objects = db.QueryInt64("SELECT count(*) FROM sqlite_schema");
  if (id == 0 && objects == 0 && SchemaVersion(db) == 0) return;  // new or empty: it becomes a record
  if (id != kApplicationId && !(id == 0 && IsUnstampedRecord(db)))
    throw InputError(db.path(), "not a blurcue record: it holds " + Contents(db) +
                                    "; it was left untouched (give a new file or an existing record)");
  RequireKnownSchema(db);  // before the writer switches it to WAL: an edited number leaves the file as it was
}

void RequireReadableRecord(Database& db) {
  const int64_t id = db.QueryInt64("PRAGMA application_id");
  if (id != kApplicationId && !(id == 0 && IsUnstampedRecord(db))) {
    const bool empty = db.QueryInt64("SELECT count(*) FROM sqlite_schema") == 0;
    throw InputError(db.path(), empty ? std::string("not a blurcue record: the database is empty")
                                      : "not a blurcue record: it holds " + Contents(db));
  }
  RequireKnownSchema(db);
  if (SchemaVersion(db) == 0)
    throw InputError(db.path(), "record schema number 0 is an empty record: nothing was ever recorded in it");
  // Older versions lack only columns added since (readers take them where present), so a read-only archive of any
  // version up to this one reads.
  RequireIntactPages(db);
}

void RequireIntactPages(Database& db) {
  std::string check = db.QueryText("PRAGMA quick_check(1)");
  if (check == "ok") return;
  for (size_t at = check.find('\n'); at != std::string::npos; at = check.find('\n', at)) check.replace(at, 1, "; ");
  throw InputError(db.path(), "the record is damaged (SQLite's quick_check: " + check + ")");
}

std::string CanonicalProtocolText(const std::string& json) {
  // ParseJson scans the nesting first: a hand-edited record's text nested 100000 deep crashed merge (SIGSEGV).
  return ParseJson(json, "protocol").dump();
}

std::string ProtocolHash(const std::string& canonical_text) { return HashHex(Fnv1a64(canonical_text)); }

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
