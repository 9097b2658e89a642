// blurcue sessions: every session of a record, as the experimenter sees it.
#include "core/error.h"
#include "store/export.h"
#include "store/record.h"
#include "store/schema.h"
#include "store/sqlite.h"

namespace blurcue::store {

std::vector<SessionSummary> ListSessions(const std::filesystem::path& db_path) {
  // Through a migrated copy for an earlier version, as export reads it (a schema-1 record has no group_name).
  Database db = OpenRecordForReading(db_path);
  Statement rows(db,
                 "SELECT s.id, st.name, p.code, s.status, s.started, coalesce(s.ended, ''), s.host, s.seed, "
                 "(SELECT count(*) FROM trials t WHERE t.session_id = s.id), "
                 "(SELECT count(*) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE t.session_id = s.id "
                 " AND r.choice NOT IN (?1, ?2)), "
                 "(SELECT count(*) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE t.session_id = s.id "
                 " AND r.choice = ?2), "
                 "(SELECT count(*) FROM trials t JOIN responses r ON r.trial_id = t.id WHERE t.session_id = s.id "
                 " AND r.choice = ?1), "
                 "s.lock_token IS NOT NULL, coalesce(s.lock_pid, 0), coalesce(s.lock_host, ''), "
                 "coalesce(s.lock_heartbeat_ms, 0), s.group_name, coalesce(s.observer, ''), coalesce(s.session_number, 0), "
                 "coalesce(pv.version, 0) "
                 "FROM sessions s JOIN participants p ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                 "JOIN protocol_versions pv ON pv.id = s.protocol_version_id "
                 "ORDER BY st.name, p.code, s.id");
  rows.Bind(1, std::string_view(kChoiceNone));
  rows.Bind(2, std::string_view(kChoiceSkipped));
  std::vector<SessionSummary> sessions;
  while (rows.Step()) {
    SessionSummary s;
    s.id = rows.GetInt64(0);
    s.study = rows.GetText(1);
    s.participant = rows.GetText(2);
    s.status = rows.GetText(3);
    s.started = rows.GetText(4);
    s.ended = rows.GetText(5);
    s.host = rows.GetText(6);
    s.seed = static_cast<uint64_t>(rows.GetInt64(7));
    s.planned = rows.GetInt64(8);
    s.answered = rows.GetInt64(9);
    s.skipped = rows.GetInt64(10);
    s.timed_out = rows.GetInt64(11);
    s.state = s.status;
    if (rows.GetInt64(12) != 0) {
      const LockState lock = JudgeLock(rows.GetText(14), rows.GetInt64(13), rows.GetInt64(15));
      s.writer = lock.text;
      if (s.status == "running" && lock.stale) s.state = "interrupted";
    } else if (s.status == "running") {
      s.state = "unfinished";
    }
    s.group = rows.GetText(16);
    s.observer = rows.GetText(17);
    s.number = rows.GetInt64(18);
    s.protocol_version = rows.GetInt64(19);
    sessions.push_back(std::move(s));
  }
  return sessions;
}
}  // namespace blurcue::store
