#pragma once
// The crash-safe record a session runner writes: one transaction per answer, resume at the first unanswered
// trial, and one writer per running session (a lock row naming host, pid and a per-Record token).
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <map>
#include <string>
#include <vector>

#include "store/sqlite.h"

#include "store/frame_columns.h"
#include "store/procedures.h"

namespace blurcue::store {

// A column the design puts in trials.csv, as the record keeps it (design_columns, once per protocol version): the
// session fills it from protocol::DescribeDesign, so the store needs no protocol types.
struct DesignColumnRecord {
  std::string name;                 // as trials.csv names it (store::DesignColumn for a level)
  std::string role;                 // within | group | procedure_cell | label | practice
  std::string type;                 // integer | number | string | boolean
  std::string unit;
  std::vector<double> numbers;      // numeric levels, ascending
  std::vector<std::string> names;   // text levels or choices, in the protocol's order
  std::optional<double> min, max;   // a range: both set, or a lower bound alone
};
// The codebook's allowed values of `column`: the numbers ("2|6|10", shortest round-trip text), else the names
// ("a|b"), else the range ("1..7", ">= 0"); "" when none is known.
std::string AllowedText(const DesignColumnRecord& column);

// Describes the station; host empty = this machine's host name.
struct SessionMeta {
  std::string software_version;  // empty = this build's BLURCUE_VERSION
  std::string host;
  std::string display;  // e.g. "1920x1080@60 DELL U2412M"
  std::string display_profile = "{}";  // the display profile as JSON (display::ToJson)
  std::string group;                    // the between-subject group the session runs ("" without groups)
  // Set: a new session's group is decided by this from the study's sessions per group that were not aborted (as
  // GroupsSoFar::sessions), inside the transaction that inserts the session, replacing `group`; stations starting at
  // once then see each other's sessions. SessionStart::group says which it gave.
  std::function<std::string(const std::map<std::string, int64_t>&)> assign_group;
  std::string participant_info = "{}";  // the participant information given: a JSON object key -> value
  // Who answers and where (typed columns of schema 7): a person or a simulated observer (its canonical parameters,
  // procedure::ToString(ObserverParams)), in a real window on the real clock or headless on a simulated clock.
  bool simulated = false;
  std::string observer_params;
  // The canonical form of observer parameters as an older build recorded them (unset: compared as stored).
  std::function<std::string(const std::string&)> canonical_observer;
  bool window = true;
  // The protocol's declared "version" and its design (recorded once per protocol version; empty: none recorded).
  int64_t protocol_version = 1;
  std::vector<DesignColumnRecord> design;
  // The protocol's procedures (ProcedureRecords of its parsed blocks), recorded once per protocol version; unset: read
  // from the protocol text (RecordedProcedures).
  std::optional<std::vector<ProcedureRecord>> procedures;
  // The seed was given (--seed), not derived: one an earlier session of the participant used is refused as such.
  bool seed_given = false;
  // > 0: the seed was derived for this session number, and a new session given another number (a station started
  // one for the participant meanwhile) is refused; 0: not checked.
  int64_t seed_for_number = 0;
};

// What a record already says about a study's groups and a participant's unfinished session, read without writing
// (a missing file says nothing): how to assign the next group, and what a resumed session must keep.
struct GroupsSoFar {
  std::map<std::string, int64_t> sessions;  // group -> participants with a completed or live session
  bool unfinished = false;                  // the participant has a running session
  std::string unfinished_group, unfinished_info = "{}";
  // The group of the participant's latest session that was not aborted ("" for none): a session run again (--again)
  // stays in it - a between-subject participant who saw two groups' conditions would be in neither.
  std::string earlier_group;
};
GroupsSoFar PeekGroups(const std::filesystem::path& db, const std::string& study, const std::string& participant);

// What a record says of a participant's sessions, read without writing: the number a new session would get
// (StartOrResumeSession decides it again in its transaction), and the participant's running session's seed and
// number. A missing file, or one that is not a readable record (Record::Open refuses it, saying why), says nothing.
struct SessionsSoFar {
  int64_t next_number = 1;
  bool unfinished = false;
  uint64_t unfinished_seed = 0;
  int64_t unfinished_number = 0;
};
SessionsSoFar PeekSessions(const std::filesystem::path& db, const std::string& study, const std::string& participant);

// One planned trial, saved up front. JSON members are compact JSON text.
struct TrialRecord {
  int64_t index = 0;
  int64_t block = 0;
  std::string factors_json = "{}";  // object: factor name -> level, and the trial's other variables
  // What each side showed (its blur spec), indexed by protocol::Index(side): kept in left_shown, right_shown.
  std::array<std::string, 2> source_json = {"null", "null"};
  // Typed (schema 7): the block's name, practice (not scored), left and right exchanged against the design, and the
  // radii planned in photo px, each side's (indexed as source_json) and the scene's (none for a picture). Each side's
  // source and fixed radius are read from source_json by the record itself (SourceColumns).
  std::string block_name, task;  // task: forced_choice | adjustment | yes_no | rating
  bool practice = false, swapped = false;
  std::array<std::optional<double>, 2> r_px;
  std::optional<double> r_scene_px;
  std::string cell;  // a procedure trial's cell by its levels ("edge=9", "edge=9;speed_cm_s=3"); "" otherwise
};

// A side's source as typed columns: its name (a word of the blur-source vocabulary, or fixed_px, fixed_screen_px,
// fixed_arcmin for a fixed radius in photo px, screen px, arcmin; empty for null) and the fixed radius in that unit.
struct SourceColumns {
  std::string source;
  std::optional<double> fixed;
  static SourceColumns Of(const std::string& source_json);
  // Every name `source` may hold, "|"-separated (the codebook's allowed values), in the vocabulary's order.
  static std::string Names();
};

// The choices a record holds besides the answers themselves: no answer before the deadline, and a trial not shown
// (a procedure ended by its stop rule, a practice run after the one that met its criterion), so that the record
// stays one response per planned trial. Export calls them status timed_out and skipped.
inline constexpr const char* kChoiceNone = "none";
inline constexpr const char* kChoiceSkipped = "skipped";

struct Response {
  std::string choice;                // procedure::Name(Choice): the answer's word, kChoiceNone or kChoiceSkipped
  double rt_ms = 0;                  // NaN: none (recorded NULL)
  std::string adjustment_json = "[]";  // method of adjustment: the levels stepped through
  // What the trial showed as decided when it was shown (an adaptive procedure's level, the radii it made, whether
  // the answer was correct): a JSON object of trial variables that export lays over the planned ones.
  std::string shown_json = "{}";
  std::string answered_at;           // ISO 8601 UTC; empty = now
  // Typed (schema 7): an adaptive procedure's level shown and whether the answer was correct, and the radii shown
  // when they were decided at the trial (photo px, indexed by protocol::Index(side)); empty otherwise.
  std::optional<double> level;
  std::array<std::optional<double>, 2> r_px;
  std::optional<bool> correct;
};

enum class SessionStatus { kRunning, kCompleted, kAborted };
const char* ToString(SessionStatus status);

struct SessionStart {
  int64_t session_id = 0;
  int64_t first_unanswered_trial = 0;  // = trial_count when all are answered; 0 before SaveTrialList
  int64_t trial_count = 0;
  bool resumed = false;
  uint64_t seed = 0;
  std::string group;  // the session's group: as recorded (resumed), or as given or assigned (new)
  int64_t session_number = 0;  // the participant's n-th session of the study (1, 2, ...)
};

struct RecordOptions {
  // A lock of this host is stale when its process is gone, or when its heartbeat is older than this: a running
  // session beats every few seconds (RecordResponse and Heartbeat), so an old heartbeat under a live pid means the
  // pid was reused by another program after a crash (or the writer hangs).
  double local_lock_stale_after_s = 60;
  // A lock held from another host is taken over only when its heartbeat is older than this (a pid cannot be
  // checked across machines, and their clocks may differ).
  double foreign_lock_stale_after_s = 600;
  // true: synchronous=FULL, an answer once committed survives a power loss or an OS crash. false (NORMAL) only
  // survives a killed process; kept for `blurcue bench record`, which measures what FULL costs.
  bool durable = true;
};

// Who holds a session's lock, as the record names it, and whether it may be taken over.
struct LockState {
  bool held = false;   // false: nobody holds it
  bool stale = false;  // the holder is gone (or silent too long): the next start takes it over
  bool mine = false;   // held by the Record asking
  std::string text;    // e.g. "pid 412 on host lab-3, heartbeat 3 s ago (alive)"; empty when not held
};

class Record {
 public:
  // Opens or creates the record at `path` (":memory:" for tests) and migrates it to the current schema.
  static Record Open(const std::filesystem::path& path, RecordOptions options = {});

  // Releases the session locks this object holds (never throws).
  ~Record();
  Record(Record&& other) noexcept;
  Record& operator=(Record&&) = delete;
  Record(const Record&) = delete;
  Record& operator=(const Record&) = delete;

  // Starts a new running session and takes its lock, or with `resume` continues the participant's running
  // session of `study`. The protocol is recorded by its canonical text (CanonicalProtocolText). Throws
  // Error(kInput) when:
  //  - resume is false but the participant has a running session (resume it, or close it with AbortSession),
  //  - resume is true but there is no running session to continue (saying what the participant has instead),
  //  - the resumed session was started with another protocol (naming what changed) or seed, or with another
  //    observer (meta.simulated and meta.observer_params, compared as recorded: both named), or with another
  //    display profile (meta.display_profile but for the file it was read from: both named, and what differs),
  //  - another live process or Record holds the session,
  //  - a new session's protocol text differs from one the study recorded under the same or a higher declared version
  //    (meta.protocol_version; naming the first JSON pointer that differs),
  //  - a new session's seed is one an earlier session of the participant used, or it was derived for another session
  //    number than the one the record gives (meta.seed_for_number).
  // A new session gets the participant's next session number in the transaction that inserts it.
  SessionStart StartOrResumeSession(const std::string& study, const std::string& participant,
                                    const std::string& protocol_json, uint64_t seed, const SessionMeta& meta,
                                    bool resume);

  // Saves the whole planned trial list once, up front; throws Error(kInput) when the session already has one.
  void SaveTrialList(int64_t session, const std::vector<TrialRecord>& trials);

  // A resumed session's check: throws Error(kInput) naming the first trial whose saved factors or sides differ
  // from `trials` (e.g. the calibration changed between sittings), or when the counts differ.
  void CheckTrialList(int64_t session, const std::vector<TrialRecord>& trials);

  // The ids of the participant's completed sessions of `study`, oldest first.
  std::vector<int64_t> CompletedSessions(const std::string& study, const std::string& participant);
  // The other participant codes of `study` that differ from `participant` only in ASCII case ("S1" for "s1").
  std::vector<std::string> CodesDifferingInCase(const std::string& study, const std::string& participant);

  // Records one answer and the display flips of its trial in one transaction: both or neither. Throws
  // Error(kInput) when the trial does not exist or already has a response, or when this Record does not hold the
  // running session.
  void RecordResponse(int64_t session, int64_t trial_index, const Response& response,
                      const std::vector<FrameRecord>& frames = {});

  // Refreshes this Record's lock heartbeat (RecordResponse does it too).
  void Heartbeat(int64_t session);

  // Marks the session completed or aborted, stamps its end and releases its lock.
  void FinishSession(int64_t session, SessionStatus status);

  // The smallest trial index without a response (= trial count when all are answered).
  int64_t FirstUnansweredTrial(int64_t session);
  // The session's recorded flips marked dropped (frames.dropped): the count frames.csv and the report give. A trial
  // left unanswered (quit) recorded no frames, so its drops are in no count.
  int64_t DroppedFrames(int64_t session);
  // The answered trials' shown objects (Response::shown_json) and choices, by trial index: what a resumed adaptive
  // procedure replays.
  struct Answered {
    std::string choice;
    std::string shown_json;
  };
  std::map<int64_t, Answered> AnsweredTrials(int64_t session);

  // Closes a running session as aborted, keeping its answers (a session that can no longer be resumed, e.g. its
  // protocol changed). Refused, naming the holder, while a live writer holds it; a stale lock is taken over.
  void AbortSession(int64_t session);

  // Clears the session's lock whoever holds it (the experimenter's call, e.g. a station that died with the lock
  // within the foreign-host wait); a writer still running loses the session at its next answer or heartbeat.
  // Returns the lock as it was; throws Error(kInput) when the session does not exist or nobody holds it.
  LockState BreakLock(int64_t session);

  // The lock of a session as the record holds it, judged by this Record's options.
  LockState Lock(int64_t session);

  Database& database() { return db_; }

 private:
  Record(Database db, RecordOptions options);
  void TakeLock(int64_t session);
  void RequireLock(int64_t session);
  // Stamps the final status and end and releases the lock, inside the caller's transaction.
  void Close(int64_t session, SessionStatus status);
  int64_t TrialId(int64_t session, int64_t trial_index);
  // Inside StartOrResumeSession's transaction: refuses a new text under a recorded version (see there); records a
  // protocol version's declared version and design once (a later session of the version whose design differs - a
  // conditions table edited under an unchanged text - is refused); decides a new session's number and refuses a
  // used seed.
  void CheckProtocolVersion(int64_t study_id, const std::string& study, const std::string& canonical,
                            const std::string& hash, int64_t version);
  void SaveDesign(int64_t protocol_id, const std::string& study, int64_t version,
                  const std::vector<DesignColumnRecord>& design);
  int64_t NextSessionNumber(int64_t participant_id, const std::string& study, const std::string& participant,
                            uint64_t seed, const SessionMeta& meta);
  // Inserts a new running session, locked by this Record, with the group and number `start` gives it; its id.
  int64_t InsertSession(int64_t participant_id, int64_t protocol_id, uint64_t seed, const SessionMeta& meta,
                        const std::string& now, const SessionStart& start);

  Database db_;
  RecordOptions options_;
  std::string lock_host_;
  int64_t pid_ = 0;
  std::string token_;  // empty in a moved-from Record
};

// This machine's host name ("unknown-host" when it has none).
std::string HostName();

// True when process `pid` is certainly gone on this host.
bool ProcessGone(int64_t pid);

// Judges a lock row (host, pid, heartbeat time in ms since the epoch) against the staleness rules.
LockState JudgeLock(const std::string& host, int64_t pid, int64_t heartbeat_ms, const RecordOptions& options = {});

// Now as ISO 8601 UTC with milliseconds, e.g. "2024-05-01T12:00:00.123Z".
std::string NowIso8601();

}  // namespace blurcue::store
