#pragma once
// procedures.csv, written by `blurcue export` beside trials.csv: each adaptive procedure's parameters, so the
// analysis can recompute a track's posterior or turning points from its answers (analysis/tracks.py).
#include <filesystem>
#include <string>
#include <vector>

#include "store/export_table.h"
#include "store/sqlite.h"

namespace blurcue::store {

// The columns of procedures.csv, for its writer and the codebook.
const std::vector<ColumnDef>& ProcedureColumns();

// OUT/procedures.csv: one row per study x protocol version (hash) x block with a procedure, its parameters as the
// protocol parser reads them from the protocol text the record keeps (defaults filled in: a QUEST+ guess rate left
// out is chance; conditions tables as the version recorded them). A version whose text the current parser refuses
// (an older blurcue's) gets no rows. Returns the codebook's rows.
std::string WriteProcedures(Database& db, const std::filesystem::path& out_dir);

}  // namespace blurcue::store
