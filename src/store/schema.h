#pragma once
// The record's schema: a list of migrations applied in order, the count kept in PRAGMA user_version.
#include <string>
#include <vector>

#include "store/sqlite.h"

namespace blurcue::store {

// The migrations, oldest first. A migration once shipped never changes: a new column is a new migration.
const std::vector<std::string>& Migrations();

// The schema version a fully migrated database reports (= Migrations().size()).
int CurrentSchemaVersion();

// PRAGMA user_version of `db`.
int SchemaVersion(Database& db);

// Applies the missing migrations in one transaction (nothing on an up-to-date database). Throws Error(kInput)
// for a database written by a newer blurcue (a version above CurrentSchemaVersion()).
void Migrate(Database& db);

// Throws Error(kInput) unless `db` is at CurrentSchemaVersion() (for readers that must not write).
void RequireCurrentSchema(Database& db);

// Get-or-insert by each table's natural key (the record and the merge share these rules); each returns the row id.
int64_t EnsureStudy(Database& db, const std::string& name, const std::string& created);
int64_t EnsureParticipant(Database& db, int64_t study_id, const std::string& code, const std::string& created);
// Protocol versions are keyed by (study, hash); `stored_json` receives the text stored under that key, which
// differs from `json` only on a hash collision - the caller decides how to refuse it.
int64_t EnsureProtocolVersion(Database& db, int64_t study_id, const std::string& json, const std::string& hash,
                              const std::string& created, std::string* stored_json);

}  // namespace blurcue::store
