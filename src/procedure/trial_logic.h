#pragma once
// What a session decides between its trials, apart from how anything is shown or stored: which trials are skipped
// (a procedure's stop rule, a practice criterion met), what a procedure's trial shows now, how an answer is scored
// and fed to the procedures and practice runs, and - for a simulated observer - which answer its key presses give.
// Pure and deterministic: `blurcue run` presents and records around it, `blurcue plan` simulates whole studies
// with it, so a planned participant answers exactly as the same participant run through the runner. No GL, no SQL.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/json_io.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "procedure/adaptive.h"
#include "procedure/answer.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "stimulus/stimulus.h"

namespace blurcue::procedure {

// When a trial's stimulus has run its course, in seconds after onset: the end of its motion, or of its last interval
// (timed by the trial's block's `timing`: protocol::TimingOf).
double StimulusEndS(const protocol::Timing& timing, const stimulus::TrialScene& scene);

// Whether `choice` answered `trial` correctly, where a trial has a correct answer: a procedure's test side or an odd
// one out's interval; for a practice pair, the side showing the larger radius (equal radii: can't tell). Empty
// where nothing is correct (yes/no, rating, adjustment).
std::optional<bool> CorrectOf(const protocol::Trial& trial, const stimulus::TrialScene& scene, const Choice& choice);

// Practice blocks run until a criterion: per block, per run of its design, the answers and the correct ones; a run
// is over when all its trials are answered. A pure function of the answers, so a resumed session decides the same.
class PracticeRounds {
 public:
  PracticeRounds(const protocol::Protocol& protocol, const std::vector<protocol::Trial>& trials);
  // The run in which `trial`'s block met its criterion before `trial`'s run (-1: not yet): its trial is skipped.
  int MetBefore(const protocol::Trial& trial) const;
  void Answer(const protocol::Trial& trial, bool correct);
  // Whether run `round` of `block` is over and its share of correct answers reached the criterion.
  bool Met(const std::string& block, int round) const;

 private:
  const protocol::Protocol& protocol_;
  std::map<std::pair<std::string, int>, int> size_;
  std::map<std::pair<std::string, int>, std::pair<int, int>> counts_;  // (block, run) -> (correct, answered)
};

// An answer as scored: whether it was correct (where the design defines a correct answer), a staircase's reversals
// before it and QUEST+'s posterior means of threshold and slope after it (procedure trials).
struct Scored {
  std::optional<bool> correct;
  std::optional<int> reversals_before;
  std::optional<std::pair<double, double>> posterior;
};

// Why a trial is not shown but recorded as skipped: its procedure's stop rule (with the reversals it stopped at), or
// its practice block's criterion, met in an earlier run.
struct Skip {
  std::string why;                // "stop rule" | "criterion met in run K"
  bool criterion = false;         // the practice criterion's
  std::optional<int> reversals;   // a stop rule's
};

// The decisions of one session, trial by trial in order. Holds references into `prepared`, which must outlive it.
class SessionLogic {
 public:
  // `cache`: procedure trials' scenes at their levels from earlier participants of the same study (blurcue plan).
  explicit SessionLogic(const PreparedSession& prepared, SceneCache* cache = nullptr);
  // Why `trial` is not shown but recorded as skipped; nullopt when it is shown.
  std::optional<Skip> SkipReason(const protocol::Trial& trial);
  // The scene `trial` shows now: its planned scene, with a procedure's level from the answers so far applied and
  // planned on the screen (`*level`: that level, 0 for a trial without one).
  stimulus::TrialScene SceneOf(const protocol::Trial& trial, double* level);
  // Scores `choice` (an answer, or none: a deadline passed) to `trial` shown as `shown` at `level`, and feeds it to
  // the trial's procedure and practice run.
  Scored Answer(const protocol::Trial& trial, const stimulus::TrialScene& shown, double level, const Choice& choice);

 private:
  const PreparedSession& prepared_;
  SceneCache* cache_;
  AdaptiveState adaptive_;
  PracticeRounds rounds_;
};

// The key presses the simulated observer `params` makes for `trial` showing `scene` in a session seeded `seed`: its
// observer seeded TrialSeed(seed, trial.index), answering through AnswerTrial (one press for an answer; the steps and
// the accept of an adjustment), each after_ms after the previous one. An
// answer's press counts from the end of the stimulus (StimulusEndS: a moving stimulus is watched to its end, intervals
// too), an adjustment's first step from onset.
std::vector<KeyPress> ObserverPresses(const ObserverParams& params, uint64_t seed, const protocol::Protocol& protocol,
                                      const protocol::Trial& trial, const stimulus::TrialScene& scene,
                                      const stimulus::Presentation& presentation);

// An adjustment's level after a next or previous step (any other action leaves it): cyclic over `levels`.
int StepLevel(int level, Action::Kind action, int levels);

// What a headless session records for those presses (the answer pressed, the adjustment's accepted level), and its
// response time in ms from onset; none (response time NaN) when the answer comes at or after the protocol's deadline.
std::pair<Choice, double> HeadlessAnswer(const protocol::Protocol& protocol, const protocol::Trial& trial,
                                              const stimulus::TrialScene& scene, const std::vector<KeyPress>& presses);

}  // namespace blurcue::procedure
