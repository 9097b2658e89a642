#pragma once
// The design as the record keeps it: protocol::DescribeDesign converted to the store's plain struct (the store knows
// no protocol types), each level under the name trials.csv gives it.
#include <vector>

#include "protocol/protocol.h"
#include "store/record.h"

namespace blurcue::session {

// protocol::DescribeDesign(protocol) as store::DesignColumnRecord, a level named store::DesignColumn(name).
std::vector<store::DesignColumnRecord> DesignRecord(const protocol::Protocol& protocol);

}  // namespace blurcue::session
