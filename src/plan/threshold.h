#pragma once
// What an adaptive procedure measures, for a plan: the threshold the simulated observer really has (from its model's
// closed-form psychometric function, never from the procedure's own estimator), and the estimate the report takes
// from one participant's track (analysis/any_study.py tracks_chart). No randomness here.
#include <optional>
#include <string>
#include <vector>

#include "procedure/threshold_fit.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "stimulus/stimulus.h"

namespace blurcue::plan {

// protocol::DownRunFirst: where an up/down rule converges (the protocol checks a staircase's target against it).
using protocol::DownRunFirst;

// The share of all answers (lapses included) at which a procedure's estimate sits for an observer who misses
// `miss` of the easiest trials: QUEST+ - its Weibull's threshold point guess + (1 - guess - miss) (1 - 1/e);
// an up/down staircase - where a down step is as likely as an up step (DownRunFirst = 1/2, Levitt 1971).
double TargetShare(const protocol::Procedure& procedure, double miss);

// The simulated observer's true threshold for one procedure cell, in the procedure's units (its level).
struct TrueThreshold {
  bool determined = false;
  double level = 0;     // when determined
  std::string why;      // when not: said in words ("beyond the tested range 0.25 to 6", ...)
  int beyond = 0;       // when not because it lies outside the range: -1 below it, +1 above it
  // The levels within which the procedure measures a threshold: a staircase's [min, max]; QUEST+'s threshold grid
  // where its stimuli span it too (a threshold no stimulus comes near is left to the prior). Empty (lo > hi) when
  // QUEST+'s stimuli lie wholly outside its threshold grid.
  double range_lo = 0, range_hi = 0;
  // QUEST+ (when determined): the slope of the Weibull that has the observer's threshold and the observer's slope
  // there on a log axis, dP / d ln x = (1 - guess - miss) slope / e - what QUEST+'s slope grid must hold.
  double weibull_slope = 0;
};

// The level at which the observer's probability of a correct answer (ProbabilityCorrect2afc on the pair as the trial
// shows it at that level, with its lapses: (1 - lapse) P + lapse / 2) reaches TargetShare, found by bisection on the
// level; `planned` is the trial's scene as planned (before any level). Not determined - with the reason - for a task
// the closed form does not cover (odd one out), an observer whose lapses keep it below the target share, or a level
// outside what the procedure can show (a staircase's [min, max], QUEST+'s threshold grid within its stimuli's span).
TrueThreshold ObserverThreshold(const procedure::ObserverParams& observer, const protocol::Procedure& procedure,
                                const protocol::Trial& trial, const stimulus::TrialScene& planned,
                                const stimulus::Presentation& presentation);

// Whether each QUEST+ cell's grid holds the observer it is planned with: the observer's threshold (ObserverThreshold)
// inside the threshold grid and within its stimuli, and its Weibull slope there (weibull_slope) inside the slope grid.
// One line per problem, naming the protocol file, the field's JSON pointer, the value and the grid; empty when every
// cell's grid holds the observer. A grid that misses the observer's slope misplaces the threshold (a Weibull of
// slope 1.5 fitted to an observer of slope 1.1 put QUEST+'s estimate 20 % high at 40 trials).
std::vector<std::string> QuestGridProblems(const procedure::PreparedSession& prepared,
                                           const procedure::ObserverParams& observer, const std::string& file);

// The procedure's turning points (procedure::Staircase::ReversalLevels: the level shown on the answer whose step goes
// the other way than the last) replayed from a staircase's answers, in order.
std::vector<double> TurningPoints(const protocol::Procedure& procedure, const std::vector<bool>& correct);

// One participant's threshold for one track (the levels shown and the answers, a missed deadline counted wrong as
// the procedure counts it), as the report takes it (analysis/tracks.py), with its 95 % interval and whether it is
// determined (the one rule of plan and report):
//   QUEST+: the median of the threshold's marginal posterior over the protocol's grid (the cumulative mass
//   interpolated linearly between grid points), its equal-tailed credible interval on the grid; not determined when
//   half the mass or more is on the grid's lowest or highest threshold, or the median lies beyond every stimulus;
//   staircase: procedure::StaircasePosterior, at the staircase's target (TargetShare, lapses included).
procedure::TrackThreshold TrackEstimate(const protocol::Procedure& procedure, const std::vector<double>& levels,
                                        const std::vector<bool>& correct);

}  // namespace blurcue::plan
