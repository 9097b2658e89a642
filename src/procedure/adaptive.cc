#include "procedure/adaptive.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace blurcue::procedure {

Staircase::Staircase(const protocol::Procedure& procedure) : p_(procedure), level_(procedure.start) {}

void Staircase::Update(bool correct) {
  int move = 0;
  if (correct) {
    wrong_run_ = 0;
    if (++correct_run_ >= p_.down) move = -1, correct_run_ = 0;
  } else {
    correct_run_ = 0;
    if (++wrong_run_ >= p_.up) move = +1, wrong_run_ = 0;
  }
  if (move == 0) return;
  if (direction_ != 0 && move != direction_) {
    ++reversals_;
    reversal_levels_.push_back(level_);
  }
  direction_ = move;
  const double step = p_.steps.empty() ? 0 : p_.steps[std::min<size_t>(size_t(reversals_), p_.steps.size() - 1)];
  level_ = std::clamp(level_ + move * step, p_.min, p_.max);
}

QuestPlus::QuestPlus(const protocol::Procedure& procedure) : p_(procedure) {
  const size_t n = p_.thresholds.size() * p_.slopes.size() * p_.lapses.size();
  posterior_.assign(n, n > 0 ? 1.0 / double(n) : 0);
  for (double x : p_.stimuli) {
    std::vector<double> row;
    row.reserve(n);
    for (double t : p_.thresholds)
      for (double b : p_.slopes)
        for (double l : p_.lapses) row.push_back(1 - l - (1 - p_.guess - l) * std::exp(-std::pow(x / t, b)));
    p_correct_.push_back(std::move(row));
  }
}

double QuestPlus::Next() const {
  double best = 0, best_entropy = 0;
  bool first = true;
  std::vector<double> next(posterior_.size());
  for (size_t s = 0; s < p_.stimuli.size(); ++s) {
    double expected = 0;
    for (const bool correct : {true, false}) {
      // The outcome's probability and the entropy of the posterior it would leave (0 log 0 counts as 0).
      double pk = 0;
      for (size_t k = 0; k < posterior_.size(); ++k) {
        next[k] = posterior_[k] * (correct ? p_correct_[s][k] : 1 - p_correct_[s][k]);
        pk += next[k];
      }
      if (pk <= 0) continue;
      double h = 0;
      for (double v : next)
        if (v > 0) h -= v / pk * std::log(v / pk);
      expected += pk * h;
    }
    if (first || expected < best_entropy) best = p_.stimuli[s], best_entropy = expected, first = false;
  }
  return best;
}

void QuestPlus::Update(double stimulus, bool correct) {
  const auto it = std::find(p_.stimuli.begin(), p_.stimuli.end(), stimulus);
  if (it == p_.stimuli.end())
    throw Error(ErrorKind::kInput, "QUEST+: " + std::to_string(stimulus) + " is not one of the procedure's stimuli");
  const auto& pc = p_correct_[size_t(it - p_.stimuli.begin())];
  double sum = 0;
  for (size_t k = 0; k < posterior_.size(); ++k) sum += posterior_[k] *= correct ? pc[k] : 1 - pc[k];
  if (sum > 0)
    for (double& v : posterior_) v /= sum;
}

double QuestPlus::Mean(int parameter) const {
  const size_t ns = p_.slopes.size(), nl = p_.lapses.size();
  double mean = 0;
  for (size_t k = 0; k < posterior_.size(); ++k) {
    const size_t t = k / (ns * nl), b = (k / nl) % ns, l = k % nl;
    mean += posterior_[k] * (parameter == 0 ? p_.thresholds[t] : parameter == 1 ? p_.slopes[b] : p_.lapses[l]);
  }
  return mean;
}

AdaptiveState::AdaptiveState(const protocol::Protocol& protocol) : protocol_(protocol) {}

AdaptiveState::State& AdaptiveState::StateOf(const protocol::Trial& trial) {
  const auto key = std::make_pair(trial.block, trial.cell);
  auto it = states_.find(key);
  if (it != states_.end()) return it->second;
  const protocol::Block* b = protocol::BlockOf(protocol_, trial);
  if (b && b->procedure && trial.cell >= 0) {
    if (b->procedure->kind == protocol::Procedure::Kind::kQuestPlus)
      return states_.emplace(key, QuestPlus(*b->procedure)).first->second;
    return states_.emplace(key, Staircase(*b->procedure)).first->second;
  }
  throw Error(ErrorKind::kInternal, "trial " + std::to_string(trial.index) + " belongs to no procedure");
}

double AdaptiveState::Level(const protocol::Trial& trial) {
  const State& state = StateOf(trial);  // made on first use
  if (const auto* s = std::get_if<Staircase>(&state)) return s->Level();
  return std::get<QuestPlus>(state).Next();
}

bool AdaptiveState::Stopped(const protocol::Trial& trial) {
  const State& state = StateOf(trial);
  const protocol::Block* block = protocol::BlockOf(protocol_, trial);
  const int stop = block && block->procedure ? block->procedure->stop_reversals : 0;
  const auto* s = std::get_if<Staircase>(&state);
  return stop > 0 && s && s->Reversals() >= stop;
}

std::optional<std::pair<double, double>> AdaptiveState::Posterior(const protocol::Trial& trial) {
  const auto* q = std::get_if<QuestPlus>(&StateOf(trial));
  if (!q) return std::nullopt;
  return std::make_pair(q->MeanThreshold(), q->MeanSlope());
}

int AdaptiveState::Reversals(const protocol::Trial& trial) {
  const auto* s = std::get_if<Staircase>(&StateOf(trial));
  return s ? s->Reversals() : 0;
}

void AdaptiveState::Answer(const protocol::Trial& trial, double level, bool correct) {
  auto& state = StateOf(trial);
  if (auto* s = std::get_if<Staircase>(&state)) s->Update(correct);
  else std::get<QuestPlus>(state).Update(level, correct);
}

}  // namespace blurcue::procedure
