#pragma once
// The session's one door to the record (store): what a session records, in session terms. Nothing else in session/
// includes a store header. The record's own types are used as they are (aliased below); recording.cc turns the two
// that carry session types (Response's Choice, SessionInfo's design) into the record's.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/json_io.h"
#include "procedure/answer.h"
#include "protocol/design.h"
#include "protocol/trials.h"
#include "procedure/trial_logic.h"
#include "stimulus/stimulus.h"
#include "store/record.h"

namespace blurcue::procedure {
struct PreparedSession;
}

namespace blurcue::session {

using procedure::Choice;

// One trial's answer as recorded (store::Response, which holds the choice's Name): the choice (an answer, none or
// skipped), its response time (NaN: none), the adjustment's steps, and what a procedure's trial showed as decided
// then (shown_json, level, each side's radius, correct).
struct Response {
  Choice choice;
  double rt_ms = 0;
  std::string adjustment_json = "[]";
  std::string shown_json = "{}";
  std::optional<double> level;
  std::array<std::optional<double>, 2> r_px;  // photo px, indexed by protocol::Index(side)
  std::optional<bool> correct;
};

// One flip of a trial as the record keeps it (store/frame_columns.h, the one definition of a frame's values): its
// time from onset, whether a frame was dropped before it, what it showed of a pair and, on video, of the take.
using FrameRecord = store::FrameRecord;
using FrameSide = store::FrameSide;

// A started or resumed session (its id, first unanswered trial, trial count, whether resumed, its seed, group and
// number), a recorded answer as a resumed session replays it (the choice's text, KeyMap::Parse reads it for its
// trial), and what a record already says, read without writing, of a study's groups and a participant's sessions:
// the record's own (store/record.h).
using SessionStart = store::SessionStart;
using RecordedAnswer = store::Record::Answered;
using GroupsSoFar = store::GroupsSoFar;
using SessionsSoFar = store::SessionsSoFar;
using store::PeekGroups;
using store::PeekSessions;

// The station a session runs on, as the record states it (store::SessionMeta).
struct SessionInfo {
  std::string display;                  // "window 1280x720@60; llvmpipe ..." - what shows the frames
  std::string display_profile = "{}";   // the display profile as JSON
  std::string group;                    // the between-subject group ("" without groups)
  // Set: a new session's group is decided by this in the transaction that starts it (balanced assignment).
  std::function<std::string(const std::map<std::string, int64_t>&)> assign_group;
  std::string participant_info = "{}";
  bool simulated = false;               // answered by the simulated observer (observer_params), else a person
  std::string observer_params;
  bool window = true;                   // in a window on the real clock, else headless on a simulated one
  // The protocol's declared "version" and its design (protocol::DescribeDesign), recorded once per protocol version.
  int64_t protocol_version = 1;
  std::vector<protocol::DesignColumn> design;
  // The protocol's blocks as parsed: their procedures are recorded once per protocol version (no text parsed again).
  std::vector<protocol::Block> blocks;
  // The seed was given (--seed): refused when an earlier session of the participant used it. Else, for a new
  // session, the number its default seed was made for (DefaultSessionSeed): refused if the record numbers it
  // otherwise (another station started one meanwhile); 0: not checked.
  bool seed_given = false;
  int64_t seed_for_number = 0;
};





// The seed of a participant's session `session_number` when none is given: protocol::DefaultSeed(study,
// participant) for the first (records made before sessions were numbered keep their seeds), FNV-1a 64 of
// "STUDY/PARTICIPANT#K" for session K > 1, so a session run again is not a copy of the first.
uint64_t DefaultSessionSeed(const std::string& study, const std::string& participant, int64_t session_number);

// A session's record: one transaction per answer, resume at the first unanswered trial, one writer per session.
// Each call is the store::Record call of the same name (its errors too).
class Recording {
 public:
  // Opens (creating) the record at `db`; ":memory:" for one that lives as long as this object.
  static Recording Open(const std::filesystem::path& db);
  ~Recording();
  Recording(Recording&&) noexcept;
  Recording& operator=(Recording&&) = delete;

  std::vector<int64_t> CompletedSessions(const std::string& study, const std::string& participant);
  std::vector<std::string> CodesDifferingInCase(const std::string& study, const std::string& participant);
  SessionStart StartOrResumeSession(const std::string& study, const std::string& participant,
                                    const std::string& protocol_text, uint64_t seed, const SessionInfo& info,
                                    bool resume);
  // A new session saves the prepared trial list (one row per trial with its planned radii and variables); a resumed
  // one checks that the list it saved is this one.
  void SaveTrialList(int64_t session, const procedure::PreparedSession& prepared);
  void CheckTrialList(int64_t session, const procedure::PreparedSession& prepared);
  // Commits one answer with its trial's frames, before anything else happens.
  void RecordResponse(int64_t session, int64_t trial_index, const Response& response,
                      const std::vector<FrameRecord>& frames = {});
  void Heartbeat(int64_t session);
  // Marks the session completed and releases its lock.
  void CompleteSession(int64_t session);
  int64_t FirstUnansweredTrial(int64_t session);
  int64_t DroppedFrames(int64_t session);
  std::map<int64_t, RecordedAnswer> AnsweredTrials(int64_t session);

 private:
  explicit Recording(std::unique_ptr<store::Record> record);
  std::unique_ptr<store::Record> record_;
};

// The column of trials.csv a design variable `name` is recorded in (store::DesignColumn: factor_NAME for a name the
// record writes itself), and whether `column` is one the record writes itself (store::IsRecordedName): the record's
// rule, for checking a design before it runs (recorded_names.h).
std::string RecordedColumn(const std::string& name);
bool IsRecordColumn(const std::string& column);

// The variables recorded with a trial beside its factor levels: practice, block_name, swapped, and for pairs each
// radius in photo px, screen px and arcmin (r_left_px, r_left_screen_px, r_left_arcmin; the same for right and
// scene) with the presentation's screen_px_per_photo_px and the blur plan (blur_plan: one_radius | per_pixel,
// r_span_screen_px) and each object's floor, streak, place and size (size_left_deg, ...: store::SideVariables), or
// start_level and adjust_levels (adjustment; a picture: picture_width_arcmin, and the real picture's r_scene_* when
// content.real_camera names its camera).
// Each level is recorded under store::DesignColumn(name): factor_NAME for one named like any of those or like a
// column of trials.csv (store::IsRecordedName), so nothing recorded takes a level's place.
Json TrialVariables(const protocol::Trial& trial, const stimulus::TrialScene& scene,
                    const stimulus::Presentation& presentation);
// A procedure trial's variables as shown (the response's copy, as JSON text): TrialVariables at the level shown, with
// the answer as scored (correct: 1 | 0), a staircase's reversals before it and QUEST+'s posterior means after it.
std::string ShownVariables(const protocol::Trial& trial, const stimulus::TrialScene& scene,
                           const stimulus::Presentation& presentation, const procedure::Scored& scored);
// What a skipped trial's response records (JSON text): why (skipped) and a stop rule's reversals.
std::string SkippedVariables(const procedure::Skip& skip);

}  // namespace blurcue::session
