#pragma once
// The columns a design's variables are recorded in, checked before anything runs. Here, in session, because it is
// the one module that sees both the protocol's design (protocol/) and the record's column table (store/columns,
// through the recording adapter's RecordedColumn): protocol/ may not include store/, and the rule must be the record's own, so that
// `blurcue validate` and `blurcue run` (both through PrepareStudy) refuse the same designs with the same words.
#include <string>
#include <vector>

#include "core/json_io.h"
#include "protocol/protocol.h"

namespace blurcue::procedure {

// Every design variable whose column in the record is not its own, one line each, "FILE: POINTER: what, got NAME":
// a level is recorded under RecordedColumn(name) (factor_NAME for a name trials.csv writes itself, such as
// status or correct), so a factor, an object level's key or a conditions table's column must not land in the column
// of another design variable (status and factor_status would both be factor_status: one of them stored nowhere),
// nor in a column of the record, nor be given twice in one block (a factor and an object level's key of the same
// name: the key's value was dropped); and a factor of object levels (named freely, analysed by the report) must have
// a name a model formula reads as one: letters, digits and _, not starting with a digit. Empty when every variable
// has its own column.
std::vector<std::string> RecordedNameProblems(const protocol::Protocol& protocol);

// Throws Error(kInput) listing RecordedNameProblems, when there are any.
void CheckRecordedNames(const protocol::Protocol& protocol);

}  // namespace blurcue::procedure
