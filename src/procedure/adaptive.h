#pragma once
// Adaptive procedures' state (protocol::Procedure): an n-up/m-down staircase and QUEST+ (Watson 2017), and one of
// them per crossing of a procedure block's factors. Pure and deterministic: the same answers give the same levels,
// so a resumed session rebuilds its state by replaying the answers its record holds. No GL, no SQL.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "protocol/protocol.h"
#include "protocol/trials.h"

namespace blurcue::procedure {

// n-up/m-down: `down` correct answers in a row step the level down (harder), `up` wrong ones in a row step it up;
// a step in the other direction than the last one is a reversal; a move uses steps[min(reversals, n - 1)] (the
// reversal it makes counted); the level stays in [min, max].
class Staircase {
 public:
  explicit Staircase(const protocol::Procedure& procedure);
  double Level() const { return level_; }
  void Update(bool correct);
  int Reversals() const { return reversals_; }
  // The levels at the reversals so far (the usual threshold estimate is the mean of the last few).
  const std::vector<double>& ReversalLevels() const { return reversal_levels_; }

 private:
  protocol::Procedure p_;
  double level_;
  int correct_run_ = 0, wrong_run_ = 0, direction_ = 0, reversals_ = 0;
  std::vector<double> reversal_levels_;
};

// QUEST+ over the Weibull p(correct | x) = 1 - lapse - (1 - guess - lapse) exp(-(x / threshold)^slope), a uniform
// prior on the grid threshold x slope x lapse (in that order, lapse fastest), the next stimulus the one of least
// expected posterior entropy (the first of equals), estimates the posterior mean - python3-questplus's
// QuestPlusWeibull with stim_scale "linear", "min_entropy" and "mean".
class QuestPlus {
 public:
  explicit QuestPlus(const protocol::Procedure& procedure);
  double Next() const;
  // Throws Error(kInput) when `stimulus` is not one of the procedure's stimuli.
  void Update(double stimulus, bool correct);
  const std::vector<double>& Posterior() const { return posterior_; }
  // Posterior means of threshold, slope and lapse.
  double MeanThreshold() const { return Mean(0); }
  double MeanSlope() const { return Mean(1); }
  double MeanLapse() const { return Mean(2); }

 private:
  double Mean(int parameter) const;
  protocol::Procedure p_;
  std::vector<double> posterior_;              // per parameter point
  std::vector<std::vector<double>> p_correct_;  // [stimulus][parameter point]
};

// The procedures of a session: one per (block, crossing), each fed only by its own trials' answers.
class AdaptiveState {
 public:
  explicit AdaptiveState(const protocol::Protocol& protocol);
  // The level `trial` shows now (its procedure's next); the trial must belong to a procedure block.
  double Level(const protocol::Trial& trial);
  // Whether `trial`'s procedure has ended by its stop rule (a staircase's reversals): its remaining trials are not
  // shown but recorded as skipped. A pure function of the answers so far, so a resumed session skips the same ones.
  bool Stopped(const protocol::Trial& trial);
  // The reversals `trial`'s staircase has made so far (0 for QUEST+).
  int Reversals(const protocol::Trial& trial);
  // QUEST+'s posterior means of threshold and slope for `trial`'s crossing, from the answers so far (empty for a
  // staircase): its estimate, recorded with each answer.
  std::optional<std::pair<double, double>> Posterior(const protocol::Trial& trial);
  void Answer(const protocol::Trial& trial, double level, bool correct);

 private:
  using State = std::variant<Staircase, QuestPlus>;
  State& StateOf(const protocol::Trial& trial);
  const protocol::Protocol& protocol_;
  std::map<std::pair<std::string, int>, State> states_;
};

}  // namespace blurcue::procedure
