#include "plan/threshold.h"

#include <algorithm>
#include <cmath>

#include "protocol/trials.h"
#include "session/answer.h"

namespace blurcue::plan {

double DownRunFirst(double p, int up, int down) {
  const double q = 1 - p;
  const double a = std::pow(p, down - 1), b = std::pow(q, up - 1);
  const double denominator = a + b - a * b;
  return denominator > 0 ? a * (1 - std::pow(q, up)) / denominator : 0.5;
}

double TargetShare(const protocol::Procedure& procedure, double miss) {
  if (procedure.kind == protocol::Procedure::Kind::kQuestPlus)
    return procedure.guess + (1 - procedure.guess - miss) * (1 - std::exp(-1.0));
  // DownRunFirst rises from 0 at p = 0 to 1 at p = 1: bisection for its 1/2.
  double lo = 0, hi = 1;
  for (int i = 0; i < 100; ++i) {
    const double mid = (lo + hi) / 2;
    (DownRunFirst(mid, procedure.up, procedure.down) < 0.5 ? lo : hi) = mid;
  }
  return (lo + hi) / 2;
}

namespace {

std::string Text(double v) { return protocol::LevelText(v); }

}  // namespace

TrueThreshold ObserverThreshold(const session::ObserverParams& observer, const protocol::Procedure& procedure,
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
    return (1 - lapse) * session::ProbabilityCorrect2afc(observer, session::ViewOf(scene, presentation)) + lapse / 2;
  };
  if (!(target < 1 - lapse / 2)) {
    t.why = "never reached: with " + Text(lapse) + " lapses the observer is correct at most " +
            Text(1 - lapse / 2) + " of the time";
    return t;
  }
  if (share(range_hi) < target) {
    t.why = "above the tested range (" + Text(range_lo) + " to " + Text(range_hi) + ")";
    return t;
  }
  if (share(range_lo) > target) {
    t.why = "below the tested range (" + Text(range_lo) + " to " + Text(range_hi) + ")";
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
  return t;
}

std::optional<double> TrackEstimate(protocol::Procedure::Kind kind, const std::vector<double>& levels,
                                    std::optional<double> last_posterior) {
  if (levels.empty()) return std::nullopt;
  if (kind == protocol::Procedure::Kind::kQuestPlus && last_posterior) return *last_posterior;
  // The report's rule, step by step: the level after each change of level, and a reversal where a change goes the
  // other way than the one before it.
  std::vector<double> after;
  std::vector<int> moves;
  for (size_t i = 1; i < levels.size(); ++i)
    if (levels[i] != levels[i - 1]) after.push_back(levels[i]), moves.push_back(levels[i] > levels[i - 1] ? 1 : -1);
  std::vector<double> reversals;
  for (size_t j = 1; j < moves.size(); ++j)
    if (moves[j] != moves[j - 1]) reversals.push_back(after[j]);
  const std::vector<double>& from = reversals.size() >= 4 ? reversals : levels;
  const size_t take = std::min(from.size(), reversals.size() >= 4 ? size_t(6) : size_t(10));
  double sum = 0;
  for (size_t i = from.size() - take; i < from.size(); ++i) sum += from[i];
  return sum / double(take);
}

}  // namespace blurcue::plan
