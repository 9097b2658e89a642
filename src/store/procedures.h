#pragma once
// The procedures table (schema 10): each adaptive procedure a protocol version runs, one row per block with a
// procedure, with its parameters as the protocol parser read them (defaults filled in), recorded once per protocol
// version when its first session starts - from the protocol the session parsed, so that procedures.csv
// (export_procedures.h) is read from the record and no protocol text is parsed again. One list of columns
// (ProcedureColumns) gives the table, its INSERT, merge's copy, procedures.csv and its codebook rows.
//
// Why typed core columns plus one JSON column: the two kinds share procedure, variable, trials and guess (typed, for
// SQL over the record), and differ in the rest, mostly lists (a staircase's steps, QUEST+'s stimulus and parameter
// grids) that no typed column holds and that the analysis reads whole from procedures.csv's parameters column.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "store/table_columns.h"

namespace blurcue::protocol {
struct Block;
}

namespace blurcue::store {

class Database;

// One procedure block of a protocol version, as the record keeps it.
struct ProcedureRecord {
  int64_t block = 0;  // the block's index in the protocol's list of blocks (trials.csv's block)
  std::string block_name;
  std::string procedure;   // staircase | quest_plus
  std::string variable;    // the procedure's variable (relative_difference, difference_arcmin, ...)
  int64_t trials = 0;      // per crossing of the block's factors
  double guess = 0.5;      // the chance rate the procedure assumes
  std::string parameters;  // all of them as JSON text (ProcedureParameters), as procedures.csv gives them
};

using ProcedureColumn = TableColumn<ProcedureRecord>;
// The procedures table's and procedures.csv's columns, in order (the CSV's study and protocol_hash are joined).
const std::vector<ProcedureColumn>& ProcedureColumns();

// The blocks of `blocks` with a procedure, as the record keeps them: the one place a parsed procedure becomes a row.
std::vector<ProcedureRecord> ProcedureRecords(const std::vector<protocol::Block>& blocks);

// A recorded protocol text's procedures: the text parsed as it ran, its conditions tables read from the text's own
// "recorded_conditions" (protocol::RecordedText; no file is read or written); none when the parser refuses the text
// (an older blurcue's). For versions recorded without their procedures (before schema 10, or through a Record call
// that gave none).
std::vector<ProcedureRecord> RecordedProcedures(const std::string& text);

// Records a protocol version's procedures; a block the version has already recorded keeps its row (the first
// session's).
void SaveProcedures(Database& db, int64_t protocol_version_id, const std::vector<ProcedureRecord>& procedures);

// Every row of the record's procedures table checked as a reader trusts it (export, merge): its protocol version
// recorded, its procedure and variable words of the vocabulary, its parameters a JSON object that agrees with the
// typed columns and holds its kind's parameters with their types (a staircase's start within [min, max], whole up,
// down and stop_reversals, steps of positive numbers; QUEST+'s grids of numbers), the guess a rate in [0, 1).
// Throws Error(kInput) naming `file`, the row (version hash, block) and the field, for a hand-edited row. What it
// cannot tell: a value changed to another valid one (the record's text is not parsed again to compare).
void CheckProcedures(Database& db, const std::string& file);

// Schema 10's data step: every protocol version's procedures from its recorded text (RecordedProcedures). `where`:
// an SQL condition on protocol_versions (e.g. its ids), "" for every version.
void DeriveProcedures(Database& db, const std::string& where = "");

}  // namespace blurcue::store
