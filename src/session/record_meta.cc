#include "session/record_meta.h"

#include "core/hash.h"
#include "protocol/design.h"
#include "protocol/trials.h"
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

uint64_t DefaultSessionSeed(const std::string& study, const std::string& participant, int64_t session_number) {
  if (session_number <= 1) return protocol::DefaultSeed(study, participant);
  return Fnv1a64(study + "/" + participant + "#" + std::to_string(session_number));
}

}  // namespace blurcue::session
