#include "store/record.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <chrono>
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <random>
#include <set>
#include <utility>

#include "core/error.h"
#include "core/typed.h"
#include "core/json_io.h"
#include "protocol/level.h"
#include "store/columns.h"
#include "store/procedures.h"
#include "store/record_texts.h"
#include "store/schema.h"

#ifndef BLURCUE_VERSION
#define BLURCUE_VERSION "unknown"
#endif

namespace blurcue::store {
namespace {

using detail::ParseBoth;
using detail::SessionName;

int64_t NowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string NewToken() {
  std::random_device device;
  const uint64_t bits = (static_cast<uint64_t>(device()) << 32) ^ device();
  char text[24];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(bits));
  return text;
}


// What a balanced assignment counts, per group: the participants of the study with a completed session in it, and
// those whose session is being run right now (a live lock: a station starting at the same moment must see it). An
// aborted session, and one stopped or killed before its end (running with no lock or a stale one), count for
// nothing: they would tilt the groups by people whose data the analysis leaves out. A participant counts once
// however many sessions they ran (an --again session stays in its group and is no new person).
std::map<std::string, int64_t> SessionsPerGroup(Database& db, const std::string& study, const RecordOptions& options) {
  Statement rows(db, "SELECT s.group_name, s.participant_id, s.status, s.lock_host, s.lock_pid, s.lock_heartbeat_ms "
                     "FROM sessions s JOIN participants p ON p.id = s.participant_id "
                     "JOIN studies st ON st.id = p.study_id WHERE st.name = ? AND s.status != 'aborted'");
  rows.Bind(1, study);
  std::map<std::string, std::set<int64_t>> people;
  while (rows.Step()) {
    const bool completed = rows.GetText(2) == "completed";
    const bool live = !completed && !rows.IsNull(3) && !rows.IsNull(5) &&
                      !JudgeLock(rows.GetText(3), rows.GetInt64(4), rows.GetInt64(5), options).stale;
    if (completed || live) people[rows.GetText(0)].insert(rows.GetInt64(1));
  }
  std::map<std::string, int64_t> counts;
  for (const auto& [group, ids] : people) counts[group] = static_cast<int64_t>(ids.size());
  return counts;
}

}  // namespace

std::string HostName() {
  char name[256] = {};
  if (gethostname(name, sizeof(name) - 1) != 0) return "unknown-host";
  return name;
}

// kill(pid, 0) says no such process; EPERM means the process exists under another user, so it is alive.
bool ProcessGone(int64_t pid) { return pid <= 0 || (kill(static_cast<pid_t>(pid), 0) == -1 && errno == ESRCH); }

const char* ToString(SessionStatus status) {
  switch (status) {
    case SessionStatus::kRunning: return "running";
    case SessionStatus::kCompleted: return "completed";
    case SessionStatus::kAborted: return "aborted";
  }
  return "running";
}

LockState JudgeLock(const std::string& host, int64_t pid, int64_t heartbeat_ms, const RecordOptions& options) {
  LockState lock;
  lock.held = true;
  const double age_s = static_cast<double>(NowMs() - heartbeat_ms) / 1000.0;
  const bool here = host == HostName();
  const bool gone = here && ProcessGone(pid);
  const double limit_s = here ? options.local_lock_stale_after_s : options.foreign_lock_stale_after_s;
  lock.stale = gone || age_s > limit_s;
  char beat[64];
  std::snprintf(beat, sizeof beat, "heartbeat %.0f s ago", std::max(0.0, age_s));
  lock.text = "pid " + std::to_string(pid) + " on host " + host + ", " + beat;
  if (gone)
    lock.text += " (gone: a stale lock, the next run takes it over)";
  else if (lock.stale)
    lock.text += here ? " (silent for over " + std::to_string(static_cast<int>(limit_s)) +
                            " s: a stale lock, its pid reused or the writer hung; the next run takes it over)"
                      : " (silent for over " + std::to_string(static_cast<int>(limit_s)) +
                            " s: a stale lock, the next run takes it over)";
  else
    lock.text += here ? " (alive)" : " (on another host; taken over when silent for " +
                                         std::to_string(static_cast<int>(limit_s)) + " s)";
  return lock;
}

std::string NowIso8601() {
  const int64_t ms = NowMs();
  const std::time_t seconds = static_cast<std::time_t>(ms / 1000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[64];
  std::snprintf(text, sizeof(text), "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900, utc.tm_mon + 1,
                utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, static_cast<int>(ms % 1000));
  return text;
}

Record Record::Open(const std::filesystem::path& path, RecordOptions options) {
  Database db(path);
  // Another program's database is refused before anything is written to it (no tables, no WAL switch).
  RequireRecordOrEmpty(db);
  if (SchemaVersion(db) > 0) RequireIntactPages(db);
  db.UseWal(options.durable);
  Migrate(db);
  return Record(std::move(db), options);
}

Record::Record(Database db, RecordOptions options)
    : db_(std::move(db)), options_(options), lock_host_(HostName()), pid_(getpid()), token_(NewToken()) {}

Record::Record(Record&& other) noexcept
    : db_(std::move(other.db_)),
      options_(other.options_),
      lock_host_(std::move(other.lock_host_)),
      pid_(other.pid_),
      token_(std::exchange(other.token_, std::string())) {}

Record::~Record() {
  if (token_.empty() || !db_.handle()) return;
  try {
    Statement release(db_, "UPDATE sessions SET lock_host = NULL, lock_pid = NULL, lock_token = NULL, "
                           "lock_heartbeat_ms = NULL WHERE lock_token = ?");
    release.Bind(1, token_);
    release.Run();
  } catch (...) {
    // A lock left behind names a pid that is gone by the next start, so it is taken over as stale.
  }
}

void Record::TakeLock(int64_t session) {
  const LockState lock = Lock(session);
  if (lock.held && !lock.stale && !lock.mine) {
    std::string who = lock.text;
    if (lock.text.rfind("pid " + std::to_string(pid_) + " on host " + lock_host_ + ",", 0) == 0)
      who += " (this process, another Record)";
    throw InputError(db_.path(), SessionName(session) + " is being written by " + who +
                                     "; two stations cannot write one session (if that writer is dead: blurcue "
                                     "sessions --db " + db_.path() + " --break-lock " + std::to_string(session) + ")");
  }
  Statement take(db_, "UPDATE sessions SET lock_host = ?, lock_pid = ?, lock_token = ?, lock_heartbeat_ms = ? "
                      "WHERE id = ?");
  take.Bind(1, lock_host_);
  take.Bind(2, pid_);
  take.Bind(3, token_);
  take.Bind(4, NowMs());
  take.Bind(5, session);
  take.Run();
}

LockState Record::Lock(int64_t session) {
  Statement query(db_, "SELECT lock_host, lock_pid, lock_token, lock_heartbeat_ms FROM sessions WHERE id = ?");
  query.Bind(1, session);
  if (!query.Step()) throw InputError(db_.path(), SessionName(session) + " does not exist");
  if (query.IsNull(2)) return {};
  // Our own token is never stale to ourselves.
  if (query.GetText(2) == token_) return {true, false, true, "this writer"};
  return JudgeLock(query.GetText(0), query.GetInt64(1), query.GetInt64(3), options_);
}

void Record::AbortSession(int64_t session) {
  Transaction transaction(db_);
  Statement query(db_, "SELECT status FROM sessions WHERE id = ?");
  query.Bind(1, session);
  if (!query.Step()) throw InputError(db_.path(), SessionName(session) + " does not exist");
  const std::string status = query.GetText(0);
  if (status != "running")
    throw InputError(db_.path(), SessionName(session) + " is " + status + "; only a running session can be aborted");
  TakeLock(session);
  Close(session, SessionStatus::kAborted);
  transaction.Commit();
}

LockState Record::BreakLock(int64_t session) {
  Transaction transaction(db_);
  const LockState lock = Lock(session);
  if (!lock.held) throw InputError(db_.path(), SessionName(session) + " holds no lock; nothing to break");
  Statement release(db_, "UPDATE sessions SET lock_host = NULL, lock_pid = NULL, lock_token = NULL, "
                         "lock_heartbeat_ms = NULL WHERE id = ?");
  release.Bind(1, session);
  release.Run();
  transaction.Commit();
  return lock;
}

void Record::RequireLock(int64_t session) {
  Statement query(db_, "SELECT status, lock_token, lock_host, lock_pid FROM sessions WHERE id = ?");
  query.Bind(1, session);
  if (!query.Step()) throw InputError(db_.path(), SessionName(session) + " does not exist");
  const std::string status = query.GetText(0);
  if (status != "running") throw InputError(db_.path(), SessionName(session) + " is " + status + ", not running");
  if (query.IsNull(1) || query.GetText(1) != token_) {
    throw InputError(db_.path(), SessionName(session) + " is not held by this writer" +
                                     (query.IsNull(1) ? std::string(" (nobody holds it; start or resume it first)")
                                                      : " (held by pid " + std::to_string(query.GetInt64(3)) +
                                                            " on host " + query.GetText(2) + ")"));
  }
}

int64_t Record::TrialId(int64_t session, int64_t trial_index) {
  Statement query(db_, "SELECT id FROM trials WHERE session_id = ? AND trial_index = ?");
  query.Bind(1, session);
  query.Bind(2, trial_index);
  if (!query.Step())
    throw InputError(db_.path(), SessionName(session) + " has no trial " + std::to_string(trial_index));
  return query.GetInt64(0);
}

namespace {

// What differs between two JSON values, as JSON pointers with the old and new values.
std::string JsonChanges(const Json& a, const Json& b) {
  const Json patch = Json::diff(a, b);
  std::string text;
  int shown = 0;
  for (const Json& op : patch) {
    if (++shown > 4) {
      text += ", and " + std::to_string(patch.size() - 4) + " more";
      break;
    }
    const std::string path = op.at("path").get<std::string>();
    const std::string pointer = path.empty() ? "/" : path;
    auto value = [](const Json& v) {
      std::string t = v.dump();
      return t.size() > 40 ? t.substr(0, 37) + "..." : t;
    };
    const std::string kind = op.at("op").get<std::string>();
    if (!text.empty()) text += ", ";
    if (kind == "add")
      text += pointer + " added (" + value(op.at("value")) + ")";
    else if (kind == "remove")
      text += pointer + " removed (was " + value(a.at(Json::json_pointer(path))) + ")";
    else
      text += pointer + " " + value(a.at(Json::json_pointer(path))) + " -> " + value(op.at("value"));
  }
  return text;
}


// What differs between two protocol texts (canonical JSON).
std::string ProtocolChanges(const std::string& before, const std::string& after) {
  Json a, b;
  if (!ParseBoth(before, after, &a, &b)) return "the recorded text is not JSON";
  return JsonChanges(a, b);
}

// How the display profile a session recorded and the one given now (display::ToJson) differ: both names, then what
// changed ("default ..." -> "lab 1" (/distance_mm 600.0 -> 570.0, ...)), or "" when they are the same display. The
// file it was read from is not compared: the same profile may be named by another path (another working
// directory). A session from before display profiles were recorded ("{}") is not compared.
std::string DisplayChanges(const std::string& recorded, const std::string& given) {
  Json a, b;
  // A recorded profile that is not JSON is a damaged record: refused, not taken for the same display.
  if (!ParseBoth(recorded, given, &a, &b)) return "(unreadable: the record's display_profile is not JSON)";
  if (!a.is_object() || !b.is_object() || a.empty()) return "";
  a.erase("file");
  b.erase("file");
  if (a == b) return "";
  const Json name_a = a.value("name", Json()), name_b = b.value("name", Json());
  a.erase("name");
  b.erase("name");
  return name_a.dump() + ", got " + name_b.dump() + " (" + (a == b ? "the same values" : JsonChanges(a, b)) + ")";
}

// A participant's running session as the resume rules read it: its protocol version, seed, observer, clock and
// display (NULL in records from before they were recorded), and its group and number.
struct RunningSession {
  int64_t id = 0;
  uint64_t seed = 0;
  std::string hash, json;  // its protocol version's hash and canonical text
  std::optional<std::string> observer, observer_params, display_profile, group;
  std::optional<int64_t> window, number;
};

// The participant's latest running session, if any.
std::optional<RunningSession> FindRunning(Database& db, int64_t participant_id) {
  Statement running(db, "SELECT s.id, s.seed, p.hash, p.json, s.observer, s.observer_params, s.display_profile, "
                        "s.group_name, s.window, s.session_number "
                        "FROM sessions s "
                        "JOIN protocol_versions p "
                        "ON p.id = s.protocol_version_id WHERE s.participant_id = ? AND s.status = 'running' "
                        "ORDER BY s.id DESC LIMIT 1");
  running.Bind(1, participant_id);
  if (!running.Step()) return std::nullopt;
  auto text = [&](int i) { return running.IsNull(i) ? std::nullopt : std::optional<std::string>(running.GetText(i)); };
  auto number = [&](int i) { return running.IsNull(i) ? std::nullopt : std::optional<int64_t>(running.GetInt64(i)); };
  RunningSession r;
  r.id = running.GetInt64(0);
  r.seed = static_cast<uint64_t>(running.GetInt64(1));
  r.hash = running.GetText(2);
  r.json = running.GetText(3);
  r.observer = text(4), r.observer_params = text(5), r.display_profile = text(6), r.group = text(7);
  r.window = number(8), r.number = number(9);
  return r;
}

// The resume rules: a session continues only as it started - under the same protocol text, seed, observer, clock and
// display profile, or the trials it made and the times it recorded would be another session's. Throws Error(kInput)
// on `db`, naming what differs and how to resume or close it (`abort_hint` and the session's id).
void CheckResumesAsStarted(const std::string& db, const RunningSession& r, const std::string& canonical,
                           const std::string& hash, uint64_t seed, const SessionMeta& meta,
                           const std::string& abort_hint) {
  const std::string session = SessionName(r.id), close = abort_hint + std::to_string(r.id) + " (its answers are kept)";
  if (r.hash != hash)
    throw InputError(db, session + " was started with another version of the protocol (" +
                             ProtocolChanges(r.json, canonical) +
                             "); run it with the protocol it started with, or close it with " + close);
  if (r.seed != seed)
    throw InputError(db, session + " was started with seed " + std::to_string(r.seed) + ", got seed " +
                             std::to_string(seed));
  // The session row names one observer: a resumed session answered by another would be recorded as the first.
  // Parameters are compared in their canonical form (procedure::ToString), so an equivalent spec resumes.
  if (r.observer) {
    auto observer = [](bool simulated, const std::string& params) {
      return simulated ? "--observer " + params : std::string("a person (no --observer)");
    };
    const bool stored_simulated = *r.observer == "simulated";
    // A record from before model= holds sim:jnd=...: read in today's canonical form, so the spelling the message
    // suggests resumes it.
    std::string stored_params = r.observer_params.value_or("");
    if (stored_simulated && meta.canonical_observer) stored_params = meta.canonical_observer(stored_params);
    if (stored_simulated != meta.simulated || (meta.simulated && stored_params != meta.observer_params))
      throw InputError(db, session + " was started with " + observer(stored_simulated, stored_params) + ", got " +
                               observer(meta.simulated, meta.observer_params) +
                               "; resume it with the observer it started with, or close it with " + close);
  }
  // A simulated observer answers headless on a simulated clock or in a window on the real one: its times (rt_ms,
  // flips) are of one kind or the other, never both in one session.
  if (r.window && meta.simulated && (*r.window != 0) != meta.window) {
    auto where = [](bool window) { return window ? std::string("in a window (--window)") : std::string("headless"); };
    throw InputError(db, session + " was started " + where(*r.window != 0) + ", got " + where(meta.window) +
                             "; resume it the way it started, or close it with " + close);
  }
  // Every radius in screen px and arcmin follows the display profile: another one would make other trials.
  if (const std::string changes = DisplayChanges(r.display_profile.value_or("{}"), meta.display_profile);
      !changes.empty())
    throw InputError(db, session + " was started with display profile " + changes +
                             "; resume it with the --display (or the protocol's display.profile) it started with, "
                             "or close it with " + close);
}

// --resume with no running session: refused, saying what the participant has instead of starting a whole new
// session unasked.
[[noreturn]] void RefuseNothingToResume(Database& db, int64_t participant_id, const std::string& study,
                                        const std::string& participant) {
  Statement past(db, "SELECT status, count(*), max(id) FROM sessions WHERE participant_id = ? GROUP BY status");
  past.Bind(1, participant_id);
  std::string found;
  while (past.Step())
    found += std::string(found.empty() ? "" : ", ") + std::to_string(past.GetInt64(1)) + " " + past.GetText(0) +
             " (last: session " + std::to_string(past.GetInt64(2)) + ")";
  throw InputError(db.path(), "--resume: participant " + participant + " of study " + study +
                                  " has no unfinished session to continue (" +
                                  (found.empty() ? std::string("no sessions at all") : found) +
                                  "); leave out --resume to start a new session" +
                                  (found.find("completed") != std::string::npos ? ", with --again" : ""));
}

// A resumed session continues at its first unanswered trial; answers or frames past it mean the record was changed
// outside blurcue (a deleted answer leaves a gap), and resuming would write over them or beside them: refused.
void CheckNothingPastFirstUnanswered(Database& db, const SessionStart& start) {
  const std::string s = std::to_string(start.session_id), f = std::to_string(start.first_unanswered_trial);
  const int64_t past = db.QueryInt64(
      "SELECT (SELECT COUNT(*) FROM responses r JOIN trials t ON t.id = r.trial_id WHERE t.session_id = " + s +
      " AND t.trial_index >= " + f + ") + (SELECT COUNT(*) FROM frames fr JOIN trials t ON t.id = fr.trial_id "
      "WHERE t.session_id = " + s + " AND t.trial_index >= " + f + ")");
  if (past > 0)
    throw InputError(db.path(), SessionName(start.session_id) + ": its first unanswered trial is " + f +
                                    ", but the record holds answers or frames of trials after it (changed "
                                    "outside blurcue?); it cannot be resumed");
}

// The participant information, one row per key (text as given; numbers as JSON text).
void SaveParticipantInfo(Database& db, int64_t session, const std::string& participant_info) {
  const Json info = ParseJson(participant_info, "participant information");
  if (!info.is_object()) return;
  Statement row(db, "INSERT INTO session_info (session_id, key, value) VALUES (?, ?, ?)");
  for (const auto& [key, value] : info.items()) {
    row.Bind(1, session);
    row.Bind(2, key);
    row.Bind(3, value.is_string() ? value.get<std::string>() : value.dump());
    row.Run();
    row.Reset();
  }
}

}  // namespace

SessionStart Record::StartOrResumeSession(const std::string& study, const std::string& participant,
                                          const std::string& protocol_json, uint64_t seed, const SessionMeta& meta,
                                          bool resume) {
  const std::string now = NowIso8601();
  const std::string canonical = CanonicalProtocolText(protocol_json);
  const std::string hash = ProtocolHash(canonical);
  Transaction transaction(db_);

  const int64_t study_id = EnsureStudy(db_, study, now);
  const int64_t participant_id = EnsureParticipant(db_, study_id, participant, now);
  SessionStart start;
  start.seed = seed;
  const std::string abort_hint = "blurcue sessions --db " + db_.path() + " --abort ";
  if (const std::optional<RunningSession> running = FindRunning(db_, participant_id)) {
    const int64_t session = running->id;
    if (!resume) {
      // Another station starting the same participant a moment earlier holds it alive: --resume would only be
      // refused again, and --abort would close a session someone is answering.
      const LockState lock = Lock(session);
      if (lock.held && !lock.stale && !lock.mine)
        throw InputError(db_.path(), "participant " + participant + " of study " + study + " is being run right now "
                                         "in " + SessionName(session) + " by " + lock.text + "; check the participant "
                                         "id, or wait for that session to end");
      throw InputError(db_.path(), "participant " + participant + " of study " + study + " has an unfinished " +
                                       SessionName(session) + "; continue it with --resume, or close it with " +
                                       abort_hint + std::to_string(session) + " (its answers are kept)");
    }
    CheckResumesAsStarted(db_.path(), *running, canonical, hash, seed, meta, abort_hint);
    TakeLock(session);
    start.session_id = session;
    start.resumed = true;
    start.group = running->group.value_or("");
    start.session_number = running->number.value_or(1);
  } else if (resume) {
    RefuseNothingToResume(db_, participant_id, study, participant);
  } else {
    CheckProtocolVersion(study_id, study, canonical, hash, meta.protocol_version);
    std::string stored_json;
    const int64_t protocol_id = EnsureProtocolVersion(db_, study_id, canonical, hash, now, &stored_json);
    if (stored_json != canonical)  // the text stored under this hash is another: an edited record (or a collision)
      throw InputError(db_.path(), "the protocol text stored under hash " + hash + " is not the text that hashes to "
                                   "it (was the record edited?); refusing to record answers against it");
    SaveDesign(protocol_id, study, meta.protocol_version, meta.design);
    // Its procedures once per version, as the session parsed them (a caller that gives none: from the text).
    SaveProcedures(db_, protocol_id, meta.procedures ? *meta.procedures : RecordedProcedures(canonical));
    // Numbered in the transaction that inserts the session, as the balanced group is: two stations never give one
    // number twice.
    start.session_number = NextSessionNumber(participant_id, study, participant, seed, meta);
    // Counted and inserted in one transaction (BEGIN IMMEDIATE): a station starting at the same moment waits for
    // this one's session and counts it.
    start.group = meta.assign_group ? meta.assign_group(SessionsPerGroup(db_, study, options_)) : meta.group;
    start.session_id = InsertSession(participant_id, protocol_id, seed, meta, now, start);
    SaveParticipantInfo(db_, start.session_id, meta.participant_info);
  }
  transaction.Commit();
  start.trial_count = db_.QueryInt64("SELECT COUNT(*) FROM trials WHERE session_id = " +
                                     std::to_string(start.session_id));
  start.first_unanswered_trial = FirstUnansweredTrial(start.session_id);
  if (start.resumed) CheckNothingPastFirstUnanswered(db_, start);
  return start;
}

int64_t Record::InsertSession(int64_t participant_id, int64_t protocol_id, uint64_t seed, const SessionMeta& meta,
                              const std::string& now, const SessionStart& start) {
  // The typed columns (who answered, where, the display's geometry, the session's number) as the column table
  // reads them (columns.h) from the session's description and the display profile it records whole.
  Statement insert(db_, "INSERT INTO sessions (participant_id, protocol_version_id, seed, software_version, "
                        "host, display, started, status, lock_host, lock_pid, lock_token, lock_heartbeat_ms, "
                        "display_profile, group_name, participant_info" + InsertNames(RecordColumns(), "sessions") +
                        ") VALUES (?, ?, ?, ?, ?, ?, ?, 'running', ?, ?, ?, ?, ?, ?, ?" +
                        InsertPlaceholders(RecordColumns(), "sessions") + ")");
  insert.Bind(1, participant_id);
  insert.Bind(2, protocol_id);
  insert.Bind(3, static_cast<int64_t>(seed));
  insert.Bind(4, meta.software_version.empty() ? std::string(BLURCUE_VERSION) : meta.software_version);
  insert.Bind(5, meta.host.empty() ? lock_host_ : meta.host);
  insert.Bind(6, meta.display);
  insert.Bind(7, now);
  insert.Bind(8, lock_host_);
  insert.Bind(9, pid_);
  insert.Bind(10, token_);
  insert.Bind(11, NowMs());
  insert.Bind(12, meta.display_profile);
  insert.Bind(13, start.group);
  insert.Bind(14, meta.participant_info);
  const Json profile = ParseJson(meta.display_profile, "display profile");
  BindTyped(RecordColumns(), insert, 15, SessionValues{meta, profile, start.session_number});
  insert.Run();
  return db_.LastInsertRowId();
}

namespace {

// The record's name of a source: its word, or for a fixed radius fixed_ and its unit (photo px as records have always
// written it, fixed_px).
std::string SourceName(protocol::BlurSource source, protocol::RadiusUnit unit) {
  if (source != protocol::BlurSource::kFixed) return protocol::ToString(source);
  switch (unit) {
    case protocol::RadiusUnit::kPhotoPx: return "fixed_px";
    case protocol::RadiusUnit::kScreenPx:
    case protocol::RadiusUnit::kArcmin: return "fixed_" + protocol::ToString(unit);
  }
  return "";
}

}  // namespace

SourceColumns SourceColumns::Of(const std::string& source_json) {
  const Json v = ParseJson(source_json, "a side's source");
  if (v.is_null()) return {};
  try {
    const protocol::BlurSpec spec = protocol::BlurSpecOf(v);
    if (spec.source != protocol::BlurSource::kFixed) return {SourceName(spec.source, spec.unit), std::nullopt};
    return {SourceName(spec.source, spec.unit), spec.radius.number};
  } catch (const Error&) {
    // Not a side this build reads: a text kept as written (the typed column says what the record says).
    if (v.is_string()) return {v.get<std::string>(), std::nullopt};
    return {};
  }
}

std::string SourceColumns::Names() {
  std::string names;
  for (const protocol::BlurSource source : protocol::Vocabulary<protocol::BlurSource>::values) {
    if (source != protocol::BlurSource::kFixed) {
      names += (names.empty() ? "" : "|") + SourceName(source, protocol::RadiusUnit::kPhotoPx);
      continue;
    }
    for (const protocol::RadiusUnit unit : protocol::Vocabulary<protocol::RadiusUnit>::values)
      names += (names.empty() ? "" : "|") + SourceName(source, unit);
  }
  return names;
}

void Record::SaveTrialList(int64_t session, const std::vector<TrialRecord>& trials) {
  Transaction transaction(db_);
  RequireLock(session);
  if (db_.QueryInt64("SELECT COUNT(*) FROM trials WHERE session_id = " + std::to_string(session)) > 0)
    throw InputError(db_.path(), SessionName(session) + " already has its trial list");
  // The typed columns (block name, task, flags, each side's source, the planned radii, the cell) as the column table
  // reads them (columns.h).
  Statement insert(db_, "INSERT INTO trials (session_id, trial_index, block, factors, left_shown, right_shown" +
                        InsertNames(RecordColumns(), "trials") + ") VALUES (?, ?, ?, ?, ?, ?" +
                        InsertPlaceholders(RecordColumns(), "trials") + ")");
  for (const TrialRecord& trial : trials) {
    insert.Bind(1, session);
    insert.Bind(2, trial.index);
    insert.Bind(3, trial.block);
    insert.Bind(4, trial.factors_json);
    insert.Bind(5, trial.source_json[0]);
    insert.Bind(6, trial.source_json[1]);
    BindTyped(RecordColumns(), insert, 7, trial);
    insert.Run();
    insert.Reset();
  }
  transaction.Commit();
}

void Record::CheckTrialList(int64_t session, const std::vector<TrialRecord>& trials) {
  const std::string abort_hint = "blurcue sessions --db " + db_.path() + " --abort " + std::to_string(session);
  Statement saved(db_, "SELECT trial_index, block, factors, left_shown, right_shown FROM trials "
                       "WHERE session_id = ? ORDER BY trial_index");
  saved.Bind(1, session);
  size_t n = 0;
  for (; saved.Step(); ++n) {
    const size_t i = static_cast<size_t>(saved.GetInt64(0));
    // The same values dumped the same way are the same text (JSON object keys are sorted).
    if (i >= trials.size()) break;
    // What differs, saved against made now: the first of the trial's parts that does.
    std::string change;
    if (saved.GetInt64(1) != trials[i].block)
      change = "block " + std::to_string(saved.GetInt64(1)) + " saved, " + std::to_string(trials[i].block) + " now";
    else if (saved.GetText(2) != trials[i].factors_json)
      change = "levels " + saved.GetText(2) + " saved, " + trials[i].factors_json + " now";
    else
      for (const protocol::Side side : protocol::Vocabulary<protocol::Side>::values) {
        const std::string& now = trials[i].source_json[protocol::Index(side)];
        const std::string was = saved.GetText(3 + int(protocol::Index(side)));
        if (was != now) {
          change = protocol::ToString(side) + " side " + was + " saved, " + now + " now";
          break;
        }
      }
    if (!change.empty())
      throw InputError(db_.path(), SessionName(session) + " trial " + std::to_string(i) + " differs from the one made "
                                       "now (" + OneLine(change) + "): a file it reads (the calibration, a picture, a "
                                       "conditions table) or blurcue changed since it started; resume it with those it "
                                       "started with, or close it with " + abort_hint + " (its answers are kept)");
  }
  if (n != trials.size())
    throw InputError(db_.path(), SessionName(session) + " has " + std::to_string(n) + " trials saved, " +
                                     std::to_string(trials.size()) + " were made now: a file it reads or blurcue "
                                     "changed since it started; resume it with those it started with, or close it "
                                     "with " + abort_hint + " (its answers are kept)");
}

std::vector<int64_t> Record::CompletedSessions(const std::string& study, const std::string& participant) {
  Statement done(db_, "SELECT s.id FROM sessions s JOIN participants p ON p.id = s.participant_id "
                      "JOIN studies st ON st.id = p.study_id "
                      "WHERE st.name = ? AND p.code = ? AND s.status = 'completed' ORDER BY s.id");
  done.Bind(1, study);
  done.Bind(2, participant);
  std::vector<int64_t> ids;
  while (done.Step()) ids.push_back(done.GetInt64(0));
  return ids;
}

std::vector<std::string> Record::CodesDifferingInCase(const std::string& study, const std::string& participant) {
  Statement like(db_, "SELECT p.code FROM participants p JOIN studies st ON st.id = p.study_id "
                      "WHERE st.name = ? AND p.code = ? COLLATE NOCASE AND p.code != ? ORDER BY p.code");
  like.Bind(1, study);
  like.Bind(2, participant);
  like.Bind(3, participant);
  std::vector<std::string> codes;
  while (like.Step()) codes.push_back(like.GetText(0));
  return codes;
}

std::map<int64_t, Record::Answered> Record::AnsweredTrials(int64_t session) {
  Statement rows(db_, "SELECT t.trial_index, r.choice, r.shown FROM responses r JOIN trials t ON t.id = r.trial_id "
                      "WHERE t.session_id = ? ORDER BY t.trial_index");
  rows.Bind(1, session);
  std::map<int64_t, Answered> answered;
  while (rows.Step()) answered[rows.GetInt64(0)] = {rows.GetText(1), rows.GetText(2)};
  return answered;
}

void Record::RecordResponse(int64_t session, int64_t trial_index, const Response& response,
                            const std::vector<FrameRecord>& frames) {
  Transaction transaction(db_);
  RequireLock(session);
  const int64_t trial_id = TrialId(session, trial_index);
  Statement existing(db_, "SELECT answered_at FROM responses WHERE trial_id = ?");
  existing.Bind(1, trial_id);
  if (existing.Step())
    throw InputError(db_.path(), SessionName(session) + " trial " + std::to_string(trial_index) +
                                     " already has a response (answered at " + existing.GetText(0) + ")");
  Statement insert(db_, "INSERT INTO responses (trial_id, choice, rt_ms, adjustment, answered_at, shown" +
                        InsertNames(RecordColumns(), "responses") + ") VALUES (?, ?, ?, ?, ?, ?" +
                        InsertPlaceholders(RecordColumns(), "responses") + ")");
  insert.Bind(1, trial_id);
  insert.Bind(2, response.choice);
  if (std::isnan(response.rt_ms)) insert.BindNull(3);  // no answer before the deadline: no response time
  else insert.Bind(3, response.rt_ms);
  insert.Bind(4, response.adjustment_json);
  insert.Bind(5, response.answered_at.empty() ? NowIso8601() : response.answered_at);
  insert.Bind(6, response.shown_json);
  BindTyped(RecordColumns(), insert, 7, response);  // the level, correctness and radii decided at the trial
  insert.Run();
  Statement frame(db_, InsertSql("frames", "trial_id", FrameColumns()));
  for (const FrameRecord& f : frames) {
    frame.Bind(1, trial_id);
    BindRow(FrameColumns(), frame, 2, f);
    frame.Run();
    frame.Reset();
  }
  Statement beat(db_, "UPDATE sessions SET lock_heartbeat_ms = ? WHERE id = ?");
  beat.Bind(1, NowMs());
  beat.Bind(2, session);
  beat.Run();
  transaction.Commit();
}

void Record::Heartbeat(int64_t session) {
  Transaction transaction(db_);
  RequireLock(session);
  Statement beat(db_, "UPDATE sessions SET lock_heartbeat_ms = ? WHERE id = ?");
  beat.Bind(1, NowMs());
  beat.Bind(2, session);
  beat.Run();
  transaction.Commit();
}

void Record::FinishSession(int64_t session, SessionStatus status) {
  if (status == SessionStatus::kRunning)
    throw Error(ErrorKind::kInternal, "FinishSession: the final status must be completed or aborted");
  Transaction transaction(db_);
  RequireLock(session);
  Close(session, status);
  transaction.Commit();
}

void Record::Close(int64_t session, SessionStatus status) {
  Statement finish(db_, "UPDATE sessions SET status = ?, ended = ?, lock_host = NULL, lock_pid = NULL, "
                        "lock_token = NULL, lock_heartbeat_ms = NULL WHERE id = ?");
  finish.Bind(1, ToString(status));
  finish.Bind(2, NowIso8601());
  finish.Bind(3, session);
  finish.Run();
}

int64_t Record::FirstUnansweredTrial(int64_t session) {
  Statement query(db_, "SELECT MIN(t.trial_index) FROM trials t LEFT JOIN responses r ON r.trial_id = t.id "
                       "WHERE t.session_id = ? AND r.id IS NULL");
  query.Bind(1, session);
  query.Step();
  if (!query.IsNull(0)) return query.GetInt64(0);
  return db_.QueryInt64("SELECT COUNT(*) FROM trials WHERE session_id = " + std::to_string(session));
}

int64_t Record::DroppedFrames(int64_t session) {
  Statement query(db_, "SELECT COUNT(*) FROM frames f JOIN trials t ON t.id = f.trial_id "
                       "WHERE t.session_id = ? AND f.dropped = 1");
  query.Bind(1, session);
  query.Step();
  return query.GetInt64(0);
}

GroupsSoFar PeekGroups(const std::filesystem::path& db_path, const std::string& study, const std::string& participant) {
  GroupsSoFar so_far;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(db_path, ec) || std::filesystem::file_size(db_path, ec) == 0) return so_far;
  Database db(db_path, OpenMode::kReadOnly);
  // Nothing in it yet: a station starting at the same moment is making it (its schema not yet committed).
  if (db.QueryInt64("SELECT count(*) FROM sqlite_schema") == 0) return so_far;
  RequireReadableRecord(db);
  if (SchemaVersion(db) < 6) return so_far;  // no groups recorded before version 6
  so_far.sessions = SessionsPerGroup(db, study, RecordOptions{});
  Statement running(db, "SELECT s.group_name, s.participant_info FROM sessions s JOIN participants p "
                        "ON p.id = s.participant_id JOIN studies st ON st.id = p.study_id "
                        "WHERE st.name = ? AND p.code = ? AND s.status = 'running' ORDER BY s.id DESC LIMIT 1");
  running.Bind(1, study);
  running.Bind(2, participant);
  if (running.Step()) {
    so_far.unfinished = true;
    so_far.unfinished_group = running.GetText(0);
    so_far.unfinished_info = running.GetText(1);
  }
  Statement earlier(db, "SELECT s.group_name FROM sessions s JOIN participants p ON p.id = s.participant_id JOIN "
                        "studies st ON st.id = p.study_id WHERE st.name = ? AND p.code = ? AND s.status <> 'aborted' "
                        "AND coalesce(s.group_name, '') <> '' ORDER BY s.id DESC LIMIT 1");
  earlier.Bind(1, study);
  earlier.Bind(2, participant);
  if (earlier.Step()) so_far.earlier_group = earlier.GetText(0);
  return so_far;
}

}  // namespace blurcue::store
