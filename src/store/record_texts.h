#pragma once
// Small helpers the record's source files share (record.cc, record_sessions.cc): how a session is named in messages,
// and two recorded-or-given JSON texts parsed for comparison. Internal to the store module.
#include <cstdint>
#include <string>

#include "core/json_io.h"

namespace blurcue::store::detail {

inline std::string SessionName(int64_t session) { return "session " + std::to_string(session); }

// Two recorded-or-given JSON texts, parsed; false when either is not JSON (a damaged record).
inline bool ParseBoth(const std::string& first, const std::string& second, Json* a, Json* b) {
  try {
    *a = Json::parse(first);
    *b = Json::parse(second);
    return true;
  } catch (const Json::exception&) {
    return false;
  }
}

}  // namespace blurcue::store::detail
