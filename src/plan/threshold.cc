#include "plan/threshold.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "protocol/design.h"
#include "protocol/trials.h"
#include "procedure/adaptive.h"
#include "procedure/observer.h"

namespace blurcue::plan {

double TargetShare(const protocol::Procedure& procedure, double miss) {
  if (procedure.kind == protocol::Procedure::Kind::kQuestPlus)
    return procedure.guess + (1 - procedure.guess - miss) * (1 - std::exp(-1.0));
  return protocol::StaircaseTarget(procedure.up, procedure.down);
}

namespace {

std::string Text(double v) { return protocol::LevelText(v); }

// Three significant digits: a derived quantity, not a level the protocol names.
std::string Short(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

}  // namespace

TrueThreshold ObserverThreshold(const procedure::ObserverParams& observer, const protocol::Procedure& procedure,
                                const protocol::Trial& trial, const stimulus::TrialScene& planned,
                                const stimulus::Presentation& presentation) {
  TrueThreshold t;
  if (planned.intervals > 2) {
    t.why = "not worked out for an odd one out (the observer's closed form is for two sides)";
    return t;
  }
  double range_lo = procedure.min, range_hi = procedure.max;
  if (procedure.kind == protocol::Procedure::Kind::kQuestPlus && !procedure.thresholds.empty()) {
    const auto [lo, hi] = std::minmax_element(procedure.thresholds.begin(), procedure.thresholds.end());
    range_lo = *lo, range_hi = *hi;
    // QUEST+ shows only its stimuli: a threshold below the smallest or above the largest is never near what it shows,
    // so its answers say little about it and the estimate is its prior's (the plan found sds of 0.02 arcmin and
    // "power 1.000 at N = 2" for stimuli 0.01 to 0.03 over a threshold grid 0.25 to 6).
    if (!procedure.stimuli.empty()) {
      const auto [slo, shi] = std::minmax_element(procedure.stimuli.begin(), procedure.stimuli.end());
      if (*slo > range_hi || *shi < range_lo) {
        t.range_lo = *slo, t.range_hi = range_hi;  // empty
        t.why = "not measured: QUEST+'s stimuli (" + Text(*slo) + " to " + Text(*shi) +
                ") lie outside its threshold grid (" + Text(range_lo) + " to " + Text(range_hi) + ")";
        return t;
      }
      range_lo = std::max(range_lo, *slo), range_hi = std::min(range_hi, *shi);
    }
  }
  t.range_lo = range_lo, t.range_hi = range_hi;
  // A lapse is a coin flip between the two sides: the observer misses lapse / 2 of even the easiest trials, which
  // is the Weibull's lapse parameter for this observer.
  const double lapse = observer.lapse;
  const double target = TargetShare(procedure, lapse / 2);
  // The probability of a correct answer at a level, from the model's closed form on the pair the trial would show.
  auto share = [&](double level) {
    stimulus::TrialScene scene = planned;
    stimulus::ApplyLevel(procedure, trial, level, presentation, &scene);
    return (1 - lapse) * procedure::ProbabilityCorrect2afc(observer, procedure::ViewOf(scene, presentation)) + lapse / 2;
  };
  if (!(target < 1 - lapse / 2)) {
    t.why = "never reached: with " + Text(lapse) + " lapses the observer is correct at most " +
            Text(1 - lapse / 2) + " of the time";
    return t;
  }
  if (share(range_hi) < target) {
    t.why = "above the tested range (" + Text(range_lo) + " to " + Text(range_hi) + ")";
    t.beyond = +1;
    return t;
  }
  if (share(range_lo) > target) {
    t.why = "below the tested range (" + Text(range_lo) + " to " + Text(range_hi) + ")";
    t.beyond = -1;
    return t;
  }
  // The share grows with the level (the test side only gets blurrier): bisection to far below any level step.
  double lo = range_lo, hi = range_hi;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
    const double mid = (lo + hi) / 2;
    (share(mid) < target ? lo : hi) = mid;
  }
  t.determined = true;
  t.level = (lo + hi) / 2;
  if (procedure.kind == protocol::Procedure::Kind::kQuestPlus) {
    // The observer's slope on a log axis at its threshold, by a central difference of +-0.1 % in the level; a
    // Weibull's there is (1 - guess - miss) slope / e.
    const double h = 1e-3;
    const double dp = (share(t.level * (1 + h)) - share(t.level * (1 - h))) / (std::log1p(h) - std::log1p(-h));
    t.weibull_slope = dp * std::exp(1.0) / (1 - procedure.guess - lapse / 2);
  }
  return t;
}

std::vector<std::string> QuestGridProblems(const procedure::PreparedSession& prepared,
                                           const procedure::ObserverParams& observer, const std::string& file) {
  std::vector<std::string> problems;
  std::set<std::pair<std::string, int>> seen;
  for (const protocol::Trial& trial : prepared.trials) {
    const protocol::Block* block = protocol::BlockOf(prepared.protocol, trial);
    if (trial.cell < 0 || !block || !block->procedure || !seen.insert({trial.block, trial.cell}).second) continue;
    const protocol::Procedure& procedure = *block->procedure;
    if (procedure.kind != protocol::Procedure::Kind::kQuestPlus) continue;
    const TrueThreshold truth =
        ObserverThreshold(observer, procedure, trial, prepared.scenes[size_t(trial.index)], prepared.presentation);
    const std::string cell = protocol::CellLevels(prepared.protocol, trial);
    const std::string at = file + ": " + block->pointer + "/procedure/";
    const std::string who = " (cell " + cell + ", observer " + procedure::ToString(observer) + ")";
    if (!truth.determined) {
      if (truth.why.rfind("never reached", 0) != 0 && truth.why.rfind("not worked out", 0) != 0)
        problems.push_back(at + "threshold: the observer's threshold is " + truth.why + who +
                           ": widen the threshold grid and the stimuli to hold it");
      continue;
    }
    const auto [lo, hi] = std::minmax_element(procedure.slopes.begin(), procedure.slopes.end());
    if (lo != procedure.slopes.end() && (truth.weibull_slope < *lo || truth.weibull_slope > *hi))
      problems.push_back(at + "slope: the observer's Weibull slope at its threshold (" + Short(truth.level) + ") is " +
                         Short(truth.weibull_slope) + ", outside the slope grid " + Text(*lo) + " to " + Text(*hi) +
                         who + ": QUEST+ would fit the wrong shape and misplace the threshold");
  }
  return problems;
}

std::vector<double> TurningPoints(const protocol::Procedure& procedure, const std::vector<bool>& correct) {
  procedure::Staircase staircase(procedure);
  for (const bool answer : correct) staircase.Update(answer);
  return staircase.ReversalLevels();
}

procedure::TrackThreshold TrackEstimate(const protocol::Procedure& procedure, const std::vector<double>& levels,
                                        const std::vector<bool>& correct) {
  procedure::TrackThreshold out;
  if (levels.empty() || levels.size() != correct.size()) {
    out.why = "not determined: no answers";
    return out;
  }
  if (procedure.kind != protocol::Procedure::Kind::kQuestPlus) {
    const double target = TargetShare(procedure, 0);
    // A rule that converges on guessing (1-up/1-down in a 2AFC) or above what a lapsing participant reaches has no
    // threshold to fit (StaircasePosterior refuses such a spec).
    if (!(target > procedure.guess + 0.01) || !(target < 0.94)) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "not determined: a %d-up/%d-down staircase converges on %.1f %% correct, %s", procedure.up,
                    procedure.down, 100 * target,
                    target <= procedure.guess + 0.01 ? "at or below what guessing gives" : "beyond what its fit can place");
      out.why = text;
      return out;
    }
    return procedure::StaircasePosterior({procedure.guess, target, procedure.min, procedure.max}, levels, correct);
  }
  procedure::QuestPlus quest(procedure);
  for (size_t i = 0; i < levels.size(); ++i) quest.Update(levels[i], correct[i]);
  // The threshold's marginal: the posterior runs threshold x slope x lapse, lapse fastest.
  const size_t per_threshold = procedure.slopes.size() * procedure.lapses.size();
  const std::vector<double>& posterior = quest.Posterior();
  std::vector<double> cumulative(procedure.thresholds.size(), 0);
  double sum = 0;
  for (size_t t = 0; t < procedure.thresholds.size(); ++t) {
    for (size_t k = 0; k < per_threshold; ++k) sum += posterior[t * per_threshold + k];
    cumulative[t] = sum;
  }
  if (!(sum > 0) || cumulative.size() < 2) {
    out.why = "not determined: the posterior is empty";
    return out;
  }
  for (double& c : cumulative) c /= sum;
  const std::vector<double>& grid = procedure.thresholds;
  // Half the mass on an end of the grid: the threshold lies at or beyond what the grid tested.
  if (cumulative.front() >= 0.5 || 1 - cumulative[cumulative.size() - 2] >= 0.5) {
    out.why = std::string("not determined: ") + (cumulative.front() >= 0.5 ? "below" : "above") +
              " the tested range (half the posterior on the grid's end)";
    return out;
  }
  size_t k = 0;
  while (cumulative[k] < 0.5) ++k;
  out.estimate =
      grid[k - 1] + (0.5 - cumulative[k - 1]) / (cumulative[k] - cumulative[k - 1]) * (grid[k] - grid[k - 1]);
  // The equal-tailed interval on the grid: the first grid point where the cumulative mass reaches each tail
  // (analysis/tracks.py credible).
  const double tail = (1 - procedure::kCredible) / 2;
  auto first_reaching = [&](double p) {
    size_t j = 0;
    while (j + 1 < cumulative.size() && cumulative[j] < p - 1e-12) ++j;
    return j;
  };
  const size_t lo_i = first_reaching(tail), hi_i = first_reaching(1 - tail);
  out.low = grid[lo_i], out.high = grid[hi_i];
  double range_lo = grid.front(), range_hi = grid.back();
  if (!procedure.stimuli.empty()) {
    const auto [slo, shi] = std::minmax_element(procedure.stimuli.begin(), procedure.stimuli.end());
    // Beyond every stimulus shown: the answers never came near it (ObserverThreshold's range).
    if (out.estimate < *slo || out.estimate > *shi) {
      out.why = std::string("not determined: ") + (out.estimate < *slo ? "below" : "above") +
                " every stimulus shown";
      return out;
    }
    range_lo = std::max(range_lo, *slo), range_hi = std::min(range_hi, *shi);
  }
  const size_t last = cumulative.size() - 1;
  const bool lower = lo_i == 0 || out.low < range_lo;
  const bool upper = (hi_i == last && 1 - cumulative[last - 1] >= tail) || out.high > range_hi;
  out.low = std::max(out.low, range_lo), out.high = std::min(out.high, range_hi);
  out.at_bound = lower && upper ? "lower and upper" : lower ? "lower" : upper ? "upper" : "";
  out.determined = true;
  return out;
}

}  // namespace blurcue::plan
