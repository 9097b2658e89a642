#pragma once
// The trial loop of a session: instructions and part screens, each trial shown over a presenter until a responder
// answers it, every answer committed through the recording before the next trial starts, breaks, feedback, and a
// resumed session's replay of what its answers decided. It sees no window, no GL and no SQL: RunSession gives it a
// window or headless presenter and the keys or the simulated observer; a test gives it fakes.
#include <filesystem>
#include <functional>

#include "session/presenter.h"
#include "procedure/prepare.h"
#include "session/recording.h"
#include "session/responder.h"
#include "session/run_result.h"

namespace blurcue::session {

// What the loop takes of RunOptions.
// Where a session stands after an answer: trials done of all, seconds since this run started, and an estimate of the
// seconds left at this run's pace.
struct TrialProgress {
  int64_t done = 0, total = 0;
  double elapsed_s = 0, remaining_s = 0;
};

struct LoopOptions {
  std::filesystem::path db;  // the record, as errors name it
  int stop_after = -1;       // >= 0: leave the session (running, resumable) after this many new answers
  std::function<void(const TrialProgress&)> progress;  // after each answer (empty: nothing said)
};

// Runs `prepared`'s trials of the session `start` (from its first unanswered trial) and returns what happened.
// Throws Error(kInput) when the record's answers so far cannot be replayed (a resumed session that does not fit the
// protocol any more).
RunResult RunTrials(const LoopOptions& options, const procedure::PreparedSession& prepared, Presenter& presenter,
                    Responder& responder, Recording& recording, const SessionStart& start);

}  // namespace blurcue::session
