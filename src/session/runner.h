#pragma once
// Runs one participant's session of a protocol: builds the whole trial list up front (seeded), saves it, then per
// trial shows the stimulus, waits for the answer and commits it in its own transaction before the next trial
// starts. A person answers with keys (or the mouse for adjustment) in a GLFW window; a simulated observer answers
// through the same key mapping, headless on a simulated clock (or in a window on the real one). Resume continues
// at the first unanswered trial with the same order.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "session/run_result.h"
#include "session/trial_loop.h"

namespace blurcue::session {

struct RunOptions {
  std::filesystem::path protocol_file;
  std::filesystem::path db;
  std::filesystem::path display_profile;  // --display: overrides the protocol's display.profile
  std::string participant;
  std::optional<uint64_t> seed;  // unset: protocol::DefaultSeed(study, participant), recorded like any seed
  std::string observer;          // empty: a person at the window; "sim[:params]": the simulated observer
  bool resume = false;
  bool again = false;            // allow another session for a participant who completed the study
  bool window = false;           // a simulated observer in a window, on the real clock (a person always has one)
  // Headless: frames rendered per second of simulated time; 0: 4, or on video the take's frame rate (every frame of
  // the take shown and recorded).
  double sim_fps = 0;
  std::filesystem::path capture_dir;      // --capture: each trial's first frame as shown, and what it shows
  // --info KEY=VALUE: the participant information the protocol asks for (participant_info). Missing required
  // fields are asked for in the terminal when stdin is one, else refused; a resumed session keeps what it recorded.
  std::vector<std::pair<std::string, std::string>> info;
  int stop_after = -1;           // >= 0: leave the session (running, resumable) after this many new answers
  // Asks for a missing required field of the participant's information: shows `prompt`, reads one line into
  // *answer; false at the end of input. Empty: nothing can be asked, and a missing field is refused (--info).
  std::function<bool(const std::string& prompt, std::string* answer)> ask;
  std::function<void(const TrialProgress&)> progress;  // after each answer (empty: nothing said)
};

// Throws Error: kInput for a bad protocol, a locked or mismatched session; kUsage for bad options.
RunResult RunSession(const RunOptions& options);

// --capture's folder, before a session starts (InputError naming it otherwise): not a symbolic link, made if missing,
// holding nothing but an earlier capture of `participant` in `study` (trial-NNNN.png/.json, no links), and writable.
void CheckCaptureFolder(const std::filesystem::path& dir, const std::string& study, const std::string& participant);

}  // namespace blurcue::session
