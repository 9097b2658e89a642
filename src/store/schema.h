#pragma once
// The record's schema: a list of migrations applied in order, the count kept in PRAGMA user_version.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "store/sqlite.h"

namespace blurcue::store {

// One step of the schema: SQL, then (optionally) a data change that SQL alone cannot make.
struct Migration {
  std::string sql;
  void (*data)(Database& db) = nullptr;
};

// The migrations, oldest first. A migration once shipped never changes: a new column is a new migration. The typed
// record's columns (version 7 on) are generated from the column table (columns.h: a row's `since`), and a version
// whose rows need nothing more is generated whole.
const std::vector<Migration>& Migrations();

// PRAGMA application_id of every blurcue record ("BLcu"): SQLite's header field for telling file kinds apart.
inline constexpr int64_t kApplicationId = 0x424c6375;

// Refuses, before anything is written, a file that is neither empty nor a blurcue record (another program's
// database gets no tables and no WAL), naming what it holds. A record from before the application id is known by
// its tables.
void RequireRecordOrEmpty(Database& db);

// For readers (sessions, export, report, merge inputs): a blurcue record at a schema version this build reads,
// whose pages pass SQLite's quick_check (a truncated or overwritten file is refused, naming it, not half read).
void RequireReadableRecord(Database& db);

// The record's schema number (PRAGMA user_version) is one this build knows and its tables are that version's: a
// negative number, one above CurrentSchemaVersion(), or one whose tables are another version's (a number edited by
// hand: 1 on a current record, 0 where tables exist) is refused as one line naming the record and the number,
// Error(kInput). Columns or tables no version has (the experimenter's own) are not compared. Reads only.
// RequireRecordOrEmpty, RequireReadableRecord and Migrate all call it first.
void RequireKnownSchema(Database& db);

// For readers (sessions, export): the record at `path` opened read-only and checked (RequireReadableRecord); a record
// of an earlier version comes back as a migrated copy in memory, so every reader sees today's columns and the file
// is only read.
Database OpenRecordForReading(const std::filesystem::path& path);

// SQLite's quick_check of every page, refused as one line naming the file (a truncated or overwritten record).
void RequireIntactPages(Database& db);

// The schema version a fully migrated database reports (= Migrations().size()).
int CurrentSchemaVersion();

// Fills the typed columns of version 7 that are NULL (rows written before it, or merged from a record before it) from
// the texts earlier versions kept: the session's display text and profile JSON, the participant information JSON, a
// trial's factors and shown sides, a response's shown object. Rows written at version 7 have them already.
void DeriveTypedColumns(Database& db);

// Fills what version 8 added where it is NULL: a protocol version's declared "version" from its JSON (1 when it
// declares none), the session numbers of every participant with an unnumbered session (NumberSessions), and the
// correctness of an odd one out answered before it was recorded with the answer (choice = the trial's odd_interval).
void DeriveVersionsAndNumbers(Database& db);

// Numbers sessions 1, 2, ... per participant by order of start (then id): every session (`all`, as merge does), or
// only those of participants with an unnumbered session.
void NumberSessions(Database& db, bool all);

// PRAGMA user_version of `db`.
int SchemaVersion(Database& db);

// Applies the missing migrations in one transaction (nothing on an up-to-date database) and stamps the
// application id. Throws Error(kInput) for a database written by a newer blurcue (a version above
// CurrentSchemaVersion()).
void Migrate(Database& db);

// A protocol's version: FNV-1a-64 (16 hex digits) of its canonical text, the parsed JSON dumped compact with
// sorted keys, so an editor's newline, a CRLF checkout, indentation or key order do not make a new version.
// Throws Error(kInput) when `json` is not JSON.
std::string CanonicalProtocolText(const std::string& json);
std::string ProtocolHash(const std::string& canonical_text);

// Get-or-insert by each table's natural key (the record and the merge share these rules); each returns the row id.
int64_t EnsureStudy(Database& db, const std::string& name, const std::string& created);
int64_t EnsureParticipant(Database& db, int64_t study_id, const std::string& code, const std::string& created);
// Protocol versions are keyed by (study, hash); `stored_json` receives the text stored under that key, which
// differs from `json` only on a hash collision - the caller decides how to refuse it.
int64_t EnsureProtocolVersion(Database& db, int64_t study_id, const std::string& json, const std::string& hash,
                              const std::string& created, std::string* stored_json);

}  // namespace blurcue::store
