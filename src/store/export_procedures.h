#pragma once
// procedures.csv, written by `blurcue export` beside trials.csv: each adaptive procedure's parameters, so the
// analysis can recompute a track's posterior or turning points from its answers (analysis/tracks.py).
#include <filesystem>
#include <string>

#include "store/export_table.h"
#include "store/procedures.h"
#include "store/sqlite.h"

namespace blurcue::store {

// OUT/procedures.csv: one row per study x protocol version (hash) x block with a procedure, read from the record's
// procedures table (procedures.h ProcedureColumns: the parameters as the protocol parser read them when the version's
// first session started, defaults filled in; a record of before schema 10 gets them, in its migrated copy, from its
// recorded texts). A version whose text the parser refused has no rows. Returns the codebook's rows.
std::string WriteProcedures(Database& db, const std::filesystem::path& out_dir);

}  // namespace blurcue::store
