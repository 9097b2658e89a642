#pragma once
// What a session gives the record beside its trials: the design, as protocol::DescribeDesign converted to the store's
// plain struct (the store knows no protocol types), and the seed of a participant's n-th session.
#include <cstdint>
#include <string>
#include <vector>

#include "protocol/protocol.h"
#include "store/record.h"

namespace blurcue::session {

// protocol::DescribeDesign(protocol) as store::DesignColumnRecord, a level named store::DesignColumn(name).
std::vector<store::DesignColumnRecord> DesignRecord(const protocol::Protocol& protocol);

// The seed of a participant's session `session_number` when none is given: protocol::DefaultSeed(study,
// participant) for the first (records made before sessions were numbered keep their seeds), FNV-1a 64 of
// "STUDY/PARTICIPANT#K" for session K > 1, so a session run again is not a copy of the first.
uint64_t DefaultSessionSeed(const std::string& study, const std::string& participant, int64_t session_number);

}  // namespace blurcue::session
