#pragma once
// What running a session did (RunSession, RunTrials).
#include <cstdint>
#include <string>

namespace blurcue::session {

struct RunResult {
  int64_t session_id = 0;
  int64_t session_number = 0;    // the participant's n-th session of the study
  uint64_t seed = 0;
  int64_t trial_count = 0;
  int64_t answered_before = 0;   // answers the session already had (resume)
  int64_t answered_now = 0;
  int64_t skipped_now = 0;       // trials recorded as skipped, not shown: by a procedure's stop rule ...
  int64_t skipped_by_criterion_now = 0;  // ... or, these of them, as practice runs after the one that met its criterion
  bool completed = false;
  int interrupted = 0;           // the signal (SIGINT, SIGTERM) that stopped the loop; 0: none        // false: quit, window closed or stop_after reached; resume with --resume
  // The session's recorded frames marked dropped, earlier sittings' included (Recording::DroppedFrames: the
  // record's count, as frames.csv and the report give it).
  int64_t dropped_frames = 0;
  // procedure::UndeterminedBlurNote of the trials run: fitted blur where the calibration's model is not determined
  // within 5 % ("" where none).
  std::string blur_note;
  // A participant's first session where the study holds codes differing from theirs only in case ("s1" beside "S1":
  // two people to the record, usually one typo): those codes ("" where none, or not a first session).
  std::string ids_like;
};

}  // namespace blurcue::session
