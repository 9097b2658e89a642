#include "procedure/trial_logic.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.h"
#include "procedure/answer.h"

namespace blurcue::procedure {

using stimulus::ApplyLevel;
using stimulus::Presentation;
using stimulus::TrialScene;

using protocol::Task;

double StimulusEndS(const protocol::Timing& timing, const TrialScene& scene) {
  const int n = scene.intervals;
  return n > 0 ? (n * timing.interval_ms + (n - 1) * timing.isi_ms) / 1000 : scene.MotionS();
}

std::optional<bool> CorrectOf(const protocol::Trial& trial, const TrialScene& scene, const Choice& choice) {
  using protocol::Side;
  if (const std::optional<Side> side = protocol::TestSide(trial)) return choice == Choice::Of(*side);
  if (const int odd = protocol::TestInterval(trial); odd > 0)
    return choice == Choice::Numbered(Choice::Kind::kInterval, odd);
  if (!protocol::TraitsOf(trial.task).scored || scene.content == protocol::ContentType::kPicture) return std::nullopt;
  const double r_left = scene.side(Side::kLeft).r_px, r_right = scene.side(Side::kRight).r_px;
  if (std::abs(r_left - r_right) <= 1e-9) return choice == Choice::Of(Choice::Kind::kCantTell);
  return choice == Choice::Of(r_left > r_right ? Side::kLeft : Side::kRight);
}

PracticeRounds::PracticeRounds(const protocol::Protocol& protocol, const std::vector<protocol::Trial>& trials)
    : protocol_(protocol) {
  for (const auto& t : trials)
    if (t.round >= 0) ++size_[{t.block, t.round}];
}

int PracticeRounds::MetBefore(const protocol::Trial& trial) const {
  if (trial.round < 0) return -1;
  for (int r = 0; r < trial.round; ++r)
    if (Met(trial.block, r)) return r;
  return -1;
}

void PracticeRounds::Answer(const protocol::Trial& trial, bool correct) {
  auto& [right, answered] = counts_[{trial.block, trial.round}];
  right += correct, ++answered;
}

bool PracticeRounds::Met(const std::string& block, int round) const {
  const auto it = counts_.find({block, round});
  const auto size = size_.find({block, round});
  const protocol::Block* b = nullptr;
  for (const auto& candidate : protocol_.blocks)
    if (candidate.name == block) b = &candidate;
  return it != counts_.end() && size != size_.end() && b && b->criterion && it->second.second == size->second &&
         it->second.first >= b->criterion->correct * it->second.second - 1e-9;
}

namespace {

const protocol::Procedure& ProcedureOf(const protocol::Protocol& protocol, const protocol::Trial& trial) {
  if (const protocol::Block* b = protocol::BlockOf(protocol, trial); b && b->procedure) return *b->procedure;
  throw Error(ErrorKind::kInternal, "trial " + std::to_string(trial.index) + " belongs to no procedure block");
}

}  // namespace

SessionLogic::SessionLogic(const PreparedSession& prepared, SceneCache* cache)
    : prepared_(prepared), cache_(cache), adaptive_(prepared.protocol), rounds_(prepared.protocol, prepared.trials) {}

std::optional<Skip> SessionLogic::SkipReason(const protocol::Trial& trial) {
  if (trial.cell >= 0 && adaptive_.Stopped(trial)) return Skip{"stop rule", false, adaptive_.Reversals(trial)};
  if (const int met = rounds_.MetBefore(trial); met >= 0)
    return Skip{"criterion met in run " + std::to_string(met + 1), true, std::nullopt};
  return std::nullopt;
}

TrialScene SessionLogic::SceneOf(const protocol::Trial& trial, double* level) {
  TrialScene scene = prepared_.scenes[size_t(trial.index)];
  *level = 0;
  if (trial.cell >= 0) {
    *level = adaptive_.Level(trial);
    // The same trial at the same level plans the same scene: a plan's participants reuse it (PlanOnScreen is most
    // of a simulated trial's cost).
    const auto key = cache_ ? std::make_pair(SceneKey(trial), *level) : std::make_pair(std::string(), 0.0);
    if (cache_)
      if (const auto it = cache_->leveled.find(key); it != cache_->leveled.end()) return it->second;
    ApplyLevel(ProcedureOf(prepared_.protocol, trial), trial, *level, prepared_.presentation, &scene);
    PlanLeveled(prepared_, trial, &scene);
    if (cache_) cache_->leveled.emplace(key, scene);
  }
  return scene;
}

Scored SessionLogic::Answer(const protocol::Trial& trial, const TrialScene& shown, double level,
                            const Choice& choice) {
  Scored s;
  // Scored where the design defines a correct answer: a procedure's, an odd one out's, a practice run to a
  // criterion's ("which fits the scene better?" has none, whatever the radii).
  const bool scored = trial.cell >= 0 || !trial.test_side.empty() || trial.round >= 0;
  s.correct = scored ? CorrectOf(trial, shown, choice) : std::nullopt;
  const bool correct = s.correct.value_or(false);
  if (trial.cell >= 0) {
    if (ProcedureOf(prepared_.protocol, trial).kind == protocol::Procedure::Kind::kStaircase)
      s.reversals_before = adaptive_.Reversals(trial);
    adaptive_.Answer(trial, level, correct);
    s.posterior = adaptive_.Posterior(trial);
  }
  if (trial.round >= 0) rounds_.Answer(trial, correct);
  return s;
}

std::vector<KeyPress> ObserverPresses(const ObserverParams& params, uint64_t seed, const protocol::Protocol& protocol,
                                      const protocol::Trial& trial, const TrialScene& scene,
                                      const Presentation& presentation) {
  SimulatedObserver observer(params, TrialSeed(seed, trial.index));
  return AnswerTrial(observer, protocol, trial, scene, presentation);
}

int StepLevel(int level, Action::Kind action, int levels) {
  if (levels <= 0) return level;
  if (action == Action::Kind::kNext) return (level + 1) % levels;
  if (action == Action::Kind::kPrevious) return (level + levels - 1) % levels;
  return level;
}

std::pair<Choice, double> HeadlessAnswer(const protocol::Protocol& protocol, const protocol::Trial& trial,
                                              const TrialScene& scene, const std::vector<KeyPress>& presses) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Choice none = Choice::Of(Choice::Kind::kNone);
  if (protocol::TraitsOf(trial.task).answer != protocol::TaskAnswer::kLevel) {
    if (presses.empty()) return {none, nan};
    const protocol::Timing& timing = protocol::TimingOf(protocol, trial);
    const double t_ms = (StimulusEndS(timing, scene) + presses.front().after_ms / 1000) * 1000;
    if (timing.deadline_ms > 0 && t_ms >= timing.deadline_ms) return {none, nan};
    return {presses.front().action.choice, t_ms};
  }
  // The adjustment's steps through the levels (cyclic), as the runner applies them, to the one accepted.
  const int levels = static_cast<int>(trial.adjust_levels.size());
  int level = trial.start_index;
  double t_ms = 0;
  for (const KeyPress& press : presses) {
    t_ms += press.after_ms;
    if (levels == 0) break;
    const Action::Kind kind = press.action.kind;
    if (kind == Action::Kind::kNext || kind == Action::Kind::kPrevious) {
      level = StepLevel(level, kind, levels);
    } else if (kind == Action::Kind::kAccept) {
      return {Choice::Level(trial.adjust_levels[size_t(level)]), t_ms};
    }
  }
  return {none, nan};
}

}  // namespace blurcue::procedure
