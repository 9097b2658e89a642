#include "session/record_design.h"

#include "protocol/design.h"
#include "store/export.h"

namespace blurcue::session {

std::vector<store::DesignColumnRecord> DesignRecord(const protocol::Protocol& protocol) {
  std::vector<store::DesignColumnRecord> out;
  for (const protocol::DesignColumn& c : protocol::DescribeDesign(protocol)) {
    store::DesignColumnRecord r;
    // A level named like a column of trials.csv is recorded as factor_NAME (session/stimulus.cc TrialVariables).
    r.name = c.level ? store::DesignColumn(c.name) : c.name;
    r.role = protocol::ToString(c.role);
    r.type = protocol::ToString(c.type);
    r.unit = c.unit;
    r.numbers = c.numbers;
    r.names = c.names;
    r.min = c.min;
    r.max = c.max;
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace blurcue::session
