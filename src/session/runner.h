#pragma once
// Runs one participant's session of a protocol: builds the whole trial list up front (seeded), saves it, then per
// trial shows the stimulus, waits for the answer and commits it in its own transaction before the next trial
// starts. A person answers with keys (or the mouse for adjustment) in a GLFW window; a simulated observer answers
// through the same key mapping, headless on a simulated clock (or in a window on the real one). Resume continues
// at the first unanswered trial with the same order.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace blurcue::session {

struct RunOptions {
  std::filesystem::path protocol_file;
  std::filesystem::path db;
  std::filesystem::path display_profile;  // --display: overrides the protocol's display.profile
  std::string participant;
  std::optional<uint64_t> seed;  // unset: DefaultSessionSeed (record_meta.h) of the session's number
  std::string observer;          // empty: a person at the window; "sim[:params]": the simulated observer
  bool resume = false;
  bool again = false;            // allow another session for a participant who completed the study
  bool window = false;           // a simulated observer in a window, on the real clock (a person always has one)
  double sim_fps = 4;            // headless: frames rendered per second of simulated time
  std::filesystem::path capture_dir;      // --capture: each trial's first frame as shown, and what it shows
  // --info KEY=VALUE: the participant information the protocol asks for (participant_info). Missing required
  // fields are asked for in the terminal when stdin is one, else refused; a resumed session keeps what it recorded.
  std::vector<std::pair<std::string, std::string>> info;
  int stop_after = -1;           // >= 0: leave the session (running, resumable) after this many new answers
};

struct RunResult {
  int64_t session_id = 0;
  int64_t session_number = 0;    // the participant's n-th session of the study
  uint64_t seed = 0;
  int64_t trial_count = 0;
  int64_t answered_before = 0;   // answers the session already had (resume)
  int64_t answered_now = 0;
  int64_t skipped_now = 0;       // trials recorded as skipped, not shown: by a procedure's stop rule ...
  int64_t skipped_by_criterion_now = 0;  // ... or, these of them, as practice runs after the one that met its criterion
  bool completed = false;        // false: quit, window closed or stop_after reached; resume with --resume
  int64_t dropped_frames = 0;
};

// Throws Error: kInput for a bad protocol, a locked or mismatched session; kUsage for bad options.
RunResult RunSession(const RunOptions& options);

}  // namespace blurcue::session
