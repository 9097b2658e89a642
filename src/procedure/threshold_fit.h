#pragma once
// A staircase track's threshold, from the track's own answers: the posterior over a Weibull psychometric function
// whose threshold is stated at the staircase's target (its convergence point, lapses included). One implementation
// for `plan`, `bench` and `report` (analysis/tracks.py staircase_posterior is its twin, held to it by
// tests/data/staircase_posterior_golden.csv). Pure: no GL, no SQL, no randomness.
//
// The model: P(correct | x) = guess + (1 - guess - lapse) (1 - exp(-c (x / theta)^slope)), c = -ln(1 - q),
// q = (target - guess) / (1 - guess - lapse), so that P(theta) = target whatever the slope and lapse: theta is the
// level answered correctly `target` of the time, lapses included - the point an up/down rule converges to (Levitt
// 1971), the same quantity whatever the fit's slope. A uniform prior over the grid
//   theta   kThetaPoints log-spaced over [max(lo, hi / 1000), hi] (the procedure's min to max),
//   slope   kSlopePoints log-spaced over [kSlopeLow, kSlopeHigh],
//   lapse   kLapses (0 to 5 %, the share of trials a participant answers at random being twice that),
// the likelihood of the track's answers, and theta's marginal: the estimate is its median, the interval its
// equal-tailed 95 % credible interval (each quantile interpolated linearly in log theta between grid points).
// Why not the mean of the last turning points: with a shallow psychometric function and large steps it ran 48 %
// high and its t interval over 3 pairs covered the truth in 62 % of tracks; a maximum-likelihood fit with a free
// slope covered in 70 % (the slope runs steep on 20-50 answers). Integrating over the slope covers
// (docs/thresholds.md).
#include <string>
#include <vector>

namespace blurcue::procedure {

inline constexpr int kThetaPoints = 161;
inline constexpr int kSlopePoints = 17;
inline constexpr double kSlopeLow = 0.5, kSlopeHigh = 5;
inline constexpr double kLapses[] = {0, 0.025, 0.05};
inline constexpr double kCredible = 0.95;
// Fewer answers than this: not determined, whatever the posterior (six answers gave an interval 0.03 to 1.9 that the
// prior, not the answers, shaped).
inline constexpr int kMinAnswers = 10;

struct StaircaseFitSpec {
  double guess = 0.5;   // the task's guess rate
  double target = 0;    // the share correct the threshold stands for (lapses included), in (guess, 1 - 0.05)
  double lo = 0, hi = 0;  // the levels the procedure can show (min, max), 0 <= lo < hi
};

// What a track says about its threshold. `determined` false: `why` says so in words ("below the tested range ...");
// the numbers are then not a result. An interval end on the range's bound (the answers do not bound it there) is
// named in `at_bound` ("lower", "upper").
struct TrackThreshold {
  bool determined = false;
  double estimate = 0, low = 0, high = 0;
  std::string at_bound;
  std::string why;
};

// The threshold of one staircase track (levels shown, answers, a missed deadline counted wrong). The rule for
// "determined", the same in plan and report:
//   not determined   fewer than kMinAnswers answers; an interval that reaches both ends of the range ("spans the
//                    whole tested range");
//                    an interval that reaches one end with the median in the tenth of the (log) range next to it
//                    ("below/above the tested range": the answers put it there); an interval that reaches one end
//                    otherwise (the answers do not bound it there: an interval cut at the range never holds a
//                    threshold beyond it);
//   determined       otherwise: the whole interval inside the range (at_bound stays empty; QUEST+ uses it).
// Throws std::invalid_argument for a spec outside its bounds (target not above guess, lo >= hi, hi <= 0).
TrackThreshold StaircasePosterior(const StaircaseFitSpec& spec, const std::vector<double>& levels,
                                  const std::vector<bool>& correct);

}  // namespace blurcue::procedure
