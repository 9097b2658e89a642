#pragma once
// A simulated observer: answers trials through the same key path as a person, from a small model of blur
// perception, so demos, tests and power analyses run without a participant. Seeded; no global state.
//
// Forced choice. Each side's mismatch is how far its blur is from the blur the scene itself has at that depth,
// m = |r_side - r_scene|. The observer compares D = (m_right - m_left) + bias_px * sign(r_left - r_right) + noise,
// noise ~ N(0, jnd_px): D > criterion picks left, D < -criterion right, otherwise "can't tell" (criterion =
// jnd_px / 2). A positive bias favours the more blurred side. With probability `lapse` the answer is a uniform
// draw of the three instead.
//
// Adjustment. The observer wants the cut-off cutoff_1m * distance_m ^ slope * exp(N(0, sd_log)) (a straight line in
// log-log, the shape of the thesis's Fig. 3.3). It steps "next" through the levels as shown, accepting the first
// one within tolerance_log of its target in log units; after seeing them all it steps back the shorter way to
// the closest one seen and accepts it.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace blurcue::session {

struct ObserverParams {
  double jnd_px = 0.6;        // sd of the internal noise on the mismatch difference (px)
  double bias_px = 0.2;       // preference for the more blurred side (px)
  double lapse = 0.04;        // probability of a random answer
  double rt_ms = 900;         // median response time; log-normal with sd_log 0.3
  double step_ms = 350;       // median time between adjustment steps
  double cutoff_1m = 14;      // adjustment: preferred cut-off at 1 m (cycles per picture width)
  double slope = -0.8;        // adjustment: d log(cut-off) / d log(distance)
  double sd_log = 0.15;       // adjustment: sd of the target in natural-log units
  double tolerance_log = 0.1; // adjustment: accept a level this close to the target (natural-log units)
};

// "sim" or "sim:jnd=0.5,bias=0.2,lapse=0.02,rt=800,step=300,cutoff1m=14,slope=-0.8,sdlog=0.15,tol=0.1".
// Throws Error(kUsage) naming the parameter and the value for an unknown name or an impossible value.
ObserverParams ParseObserver(const std::string& spec);
std::string ToString(const ObserverParams& params);  // the canonical "sim:..." form, recorded with the session

// What the observer sees of a forced-choice trial.
struct PairView {
  double r_left_px = 0, r_right_px = 0, r_scene_px = 0;
};

// One key press, after_ms after the previous one (the first: after the observer starts looking).
struct KeyPress {
  std::string action;  // "left" | "right" | "cant_tell" | "previous" | "next" | "accept" | "yes" | "no" | "1".."9"
  double after_ms = 0;
};

class SimulatedObserver {
 public:
  SimulatedObserver(const ObserverParams& params, uint64_t seed) : params_(params), rng_(seed) {}

  // The single key press answering a forced-choice trial; without `cant_tell` (a strict 2AFC) it guesses instead:
  // the criterion is 0 and a lapse picks one of the two sides.
  KeyPress ChooseSide(const PairView& view, bool cant_tell = true);
  // "Which side is more blurred?" (an adaptive procedure's question): D = r_left - r_right + noise, noise ~
  // N(0, jnd_px); left when D > 0, else right - a forced guess, never can't tell; a lapse is a coin flip. Its
  // probability of choosing the more blurred side is Phi(|difference| / jnd_px) (1 - lapse) + lapse / 2.
  KeyPress ChooseBlurrier(const PairView& view);
  // Odd one out: each of `intervals` intervals seen as its radius + N(0, jnd_px) (interval `odd`, 1-based, shows
  // r_right_px, the others r_left_px); the answer ("1".."n") is the one farthest from the mean of the others. A lapse
  // names an interval at random. By guessing it is right 1/n of the time.
  KeyPress ChooseOdd(const PairView& view, int intervals, int odd);
  // One object (layout single), seen as its mismatch with the scene's blur, e = |r_left_px - r_scene_px| + N(0,
  // jnd_px): "yes" (it looks out of place) when e > jnd_px / 2, else "no"; a lapse is a coin flip.
  KeyPress SayYesNo(const PairView& view);
  // The same evidence on a scale of `points`: 1 + the number of criteria jnd_px / 2, 2 jnd_px / 2, ... (n - 1 of
  // them) that e exceeds ("1".."n"); a lapse is a uniform draw.
  KeyPress Rate(const PairView& view, int points);
  // The presses answering an adjustment trial: levels in the order the participant steps through them (cyclic),
  // the index shown first, the distance of the real object.
  std::vector<KeyPress> Adjust(const std::vector<double>& levels, int start_index, double distance_m);

  // The cut-off this observer aims at for a distance, before its per-trial noise.
  double TargetCutoff(double distance_m) const;
  const ObserverParams& params() const { return params_; }

 private:
  double Normal();   // standard normal from raw generator output (Box-Muller), the same on every library
  double Uniform();  // [0, 1) from the top 53 bits
  double ResponseTimeMs(double median_ms);

  ObserverParams params_;
  std::mt19937_64 rng_;
};

}  // namespace blurcue::session
