#pragma once
// A simulated observer: answers trials through the same key path as a person, from a small model of blur
// perception, so demos, tests and power analyses run without a participant. Seeded; no global state.
//
// Two models, named by `model`:
//
// model=arcmin (the default): blur discrimination in visual angle, the "dipper" of the blur-discrimination
// literature that Watson & Ahumada 2011 ("Blur clarified: a review and synthesis of blur discrimination", J. Vision
// 11(5):10) review, with data such as Mather & Smith 2002 ("Blur discrimination and its relation to blur-mediated
// depth perception", Perception 31:1211-1219). The form used is the classic equivalent-intrinsic-blur account of
// the dipper (intrinsic blur plus Weber's law), not W&A's own contrast-energy model (ViCE), which needs the image
// and is not implemented here. The literature states blur as the standard deviation s of a Gaussian (arcmin); blurcue's
// radius r is 2 x the std of the line-spread function (DESIGN.md), so s = r / 2. The eye adds its own equivalent
// (intrinsic) blur s_i; a blur is seen as
//     E(s) = (s^p + s_i^p)^(1/p)                     (p = exponent; 2: the two add in quadrature)
// and two blurs are told apart by Weber's law on E: each look at a blur gives ln E(s) + N(0, sigma), with sigma set so
// that a 2AFC "which is more blurred?" is 75 % correct when E(b) / E(a) = 1 + weber:
//     P(correct) = Phi(z75 |ln E(s_a) - ln E(s_b)| / ln(1 + weber)),   z75 = Phi^-1(0.75),   sigma = ln(1+w) / (sqrt 2 z75)
// The 75 % threshold against a reference s is ((1+w)^p (s^p + s_i^p) - s_i^p)^(1/p) - s: it falls from
// s_i sqrt((1+w)^2 - 1) at s = 0 to a dip (for p = 2: at s = s_i / (1 + w), depth s_i ((1+w) - 1/(1+w))) and then
// rises with slope -> w: the dipper. Biases are in units of the noise sd of one comparison (sqrt 2 sigma): `side`
// favours the left side of a pair (forced choice), `blurrier` the more blurred side of a "which fits the scene?"
// pair. Response times are log-normal (sd 0.3 in natural-log units) around
// rt x (1 + rthard exp(-d'^2 / 2)), d' the trial's evidence over its noise: hard trials take longer.
//
// model=pixel (the observer of blurcue <= 0.x, kept as a named parameter set): the same decisions on radii in photo
// px, with a fixed JND: D = (m_right - m_left) + bias_px * sign(r_left - r_right) + N(0, jnd_px) for the mismatch task,
// criterion jnd_px / 2 for can't tell; response times rt x exp(0.3 N(0, 1)). It knows nothing of the screen.
//
// Forced choice (both models). Each side's mismatch is how far its blur is from the blur the scene itself has at
// that depth, m = |T(r_side) - T(r_scene)| (T: the radius in px, or ln E of its arcmin), and the observer picks the
// side with the smaller mismatch; "can't tell" when the difference is within half the comparison's noise sd. With
// probability `lapse` the answer is a uniform draw of the choices instead.
//
// Adjustment (depth matching: the real picture below, the virtual one above at the level shown). model=arcmin: the
// observer sets the virtual picture to the blur it cannot tell from the real picture's, both in visual angle - each
// level's blur as its equivalent Gaussian (scene::ButterworthEquivalentSigma) and the real one as its camera made it
// (content.real_camera). It steps "next" through every level, comparing each once with the real picture,
// D = ln E(level) - ln E(real) + N(0, compare sd), then steps back the shorter way to the level with the smallest |D|
// and accepts it. Through the dipper, levels all sharper than the eye's intrinsic blur look alike, so for a sharp
// real picture it takes any of them. model=pixel (of old): it wants the cut-off cutoff_1m * distance_m ^ slope *
// exp(N(0, sd_log)), a straight line in log-log (the shape of the thesis's Fig. 3.3), steps "next" until a level is
// within tolerance_log of it in log units and accepts that; after seeing them all it steps back the shorter way to
// the closest one seen and accepts it.
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "procedure/answer.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "stimulus/stimulus.h"

namespace blurcue::procedure {

enum class ObserverModel { kArcmin, kPixel };

struct ObserverParams {
  ObserverModel model = ObserverModel::kArcmin;
  // model=arcmin. Defaults: the middle of the ranges the literature reports (intrinsic blur 0.5-1 arcmin, Weber
  // fraction 0.3-0.6 well above it; see observer.cc for the points they were checked against).
  double intrinsic_arcmin = 0.6;  // s_i: the eye's equivalent intrinsic blur, Gaussian std (arcmin; r = 2 s)
  double weber = 0.35;            // w: 75 %-correct Weber fraction on the seen blur E
  double exponent = 2;            // p: how blur and intrinsic blur combine (2: in quadrature)
  double side_bias = 0;           // preference for the left side (noise sd units)
  double blurrier_bias = 0.3;     // preference for the more blurred side in "which fits the scene?" (noise sd units)
  double rt_hard = 0.5;           // a trial at d' = 0 takes (1 + rt_hard) x rt_ms
  // model=pixel
  double jnd_px = 0.6;        // sd of the internal noise on the mismatch difference (px)
  double bias_px = 0.2;       // preference for the more blurred side (px)
  // both
  double lapse = 0.04;        // probability of a random answer
  double rt_ms = 900;         // median response time (arcmin: of an easy trial); log-normal with sd_log 0.3
  double step_ms = 350;       // median time between adjustment steps
  // model=pixel's adjustment
  double cutoff_1m = 14;      // preferred cut-off at 1 m (cycles per picture width)
  double slope = -0.8;        // d log(cut-off) / d log(distance)
  double sd_log = 0.15;       // sd of the target in natural-log units
  double tolerance_log = 0.1; // accept a level this close to the target (natural-log units)
};

// "sim" (model=arcmin, defaults) or "sim:NAME=VALUE,...": model=arcmin|pixel; arcmin: intrinsic, weber, exponent,
// side, blurrier, rthard; pixel: jnd, bias, cutoff1m, slope, sdlog, tol; both: lapse, rt, step. A spec without model=
// that names a pixel-only parameter is model=pixel (every record before model= existed holds such a spec).
// Throws Error(kUsage) naming the parameter and the value for an unknown name, a parameter of the other model or an
// impossible value.
ObserverParams ParseObserver(const std::string& spec);
// The canonical "sim:model=...,..." form (every parameter of its model), recorded with the session; parses back to
// the same observer.
std::string ToString(const ObserverParams& params);

// What the observer sees of a pair trial: the radii (photo px, as recorded) and how large a photo px is on the eye.
struct PairView {
  std::array<double, 2> r_px{0, 0};  // each side's radius (photo px, as today), indexed by protocol::Index(side)
  double r_scene_px = 0;             // the scene's own blur there (photo px)
  double arcmin_per_px = 0;  // visual angle (arcmin) per photo px as shown; 0 = unknown (model=arcmin refuses it)
  double r(protocol::Side side) const { return r_px[protocol::Index(side)]; }
};

// model=arcmin: the probability that the observer (no lapse, no bias) tells radii a and b (arcmin, blurcue's r)
// apart in a 2AFC "which is more blurred?": Phi(z75 |ln E(a/2) - ln E(b/2)| / ln(1 + weber)). model=pixel has no
// closed form in arcmin: Error(kUsage) - use the PairView form.
double ProbabilityCorrect2afc(const ObserverParams& p, double r_a_arcmin, double r_b_arcmin);
// The same for a pair as shown, left against right, for either model (pixel: Phi(|r_left - r_right| / jnd_px)).
double ProbabilityCorrect2afc(const ObserverParams& p, const PairView& view);
// model=arcmin: the increment (arcmin, blurcue's r) a 2AFC tells from `r_ref_arcmin` 75 % of the time: the dipper,
// 2 (((1+w)^p ((r/2)^p + s_i^p) - s_i^p)^(1/p) - r/2).
double DiscriminationThresholdArcmin(const ObserverParams& p, double r_ref_arcmin);

// What the observer sees of an adjustment trial.
struct AdjustView {
  double distance_m = 0;               // the real picture's distance (model=pixel aims at a cut-off for it)
  double r_real_arcmin = -1;           // model=arcmin: the real picture's blur as shown (blurcue's r); < 0: unknown
  std::vector<double> level_r_arcmin;  // model=arcmin: each level's blur as shown, in the order of the levels
};

// One key press, after_ms after the previous one (the first: after the observer starts looking).
struct KeyPress {
  Action action;  // an answer, or an adjustment's step or accept
  double after_ms = 0;
};

class SimulatedObserver {
 public:
  SimulatedObserver(const ObserverParams& params, uint64_t seed) : params_(params), rng_(seed) {}

  // The single key press answering a forced-choice trial ("which fits the scene?"); without `cant_tell` (a strict
  // 2AFC) it guesses instead: the criterion is 0 and a lapse picks one of the two sides. D = m_right - m_left +
  // blurrier bias (toward the more blurred side) + side bias (toward left) + noise; left when D > criterion.
  KeyPress ChooseSide(const PairView& view, bool cant_tell = true);
  // "Which side is more blurred?" (a procedure's or a 2IFC's question): D = T(r_left) - T(r_right) + side bias +
  // noise; left when D > 0, else right - a forced guess, never can't tell; a lapse is a coin flip. Without a side
  // bias its probability of choosing the more blurred side is ProbabilityCorrect2afc (1 - lapse) + lapse / 2.
  KeyPress ChooseBlurrier(const PairView& view);
  // Odd one out: each of `intervals` intervals seen as T(its radius) + a look's noise (interval `odd`, 1-based, shows
  // r_right_px, the others r_left_px); the answer ("1".."n") is the one farthest from the mean of the others. A lapse
  // names an interval at random. By guessing it is right 1/n of the time.
  KeyPress ChooseOdd(const PairView& view, int intervals, int odd);
  // One object (layout single), seen as its mismatch with the scene's blur, e = |T(r_left) - T(r_scene)| + noise:
  // "yes" (it looks out of place) when e exceeds half the noise sd, else "no"; a lapse is a coin flip.
  KeyPress SayYesNo(const PairView& view);
  // The same evidence on a scale of `points`: 1 + the number of criteria sd / 2, 2 sd / 2, ... (n - 1 of them) that e
  // exceeds ("1".."n"); a lapse is a uniform draw.
  KeyPress Rate(const PairView& view, int points);
  // The presses answering an adjustment trial: levels in the order the participant steps through them (cyclic),
  // the index shown first, what is seen. model=arcmin throws Error(kUsage) without the real blur or a level's blur.
  std::vector<KeyPress> Adjust(const std::vector<double>& levels, int start_index, const AdjustView& view);

  // model=pixel: the cut-off this observer aims at for a distance, before its per-trial noise.
  double TargetCutoff(double distance_m) const;
  const ObserverParams& params() const { return params_; }

 private:
  double Normal();   // standard normal from raw generator output (Box-Muller), the same on every library
  double Uniform();  // [0, 1) from the top 53 bits
  // Log-normal around the median; model=arcmin: the median grows for hard trials (evidence d' near 0).
  double ResponseTimeMs(double median_ms, double d_prime = 1e9);
  // What the observer's decision variable makes of a radius (px, or ln E of its arcmin), and its noise sds: of one
  // look at one blur, and of one comparison of two.
  double Seen(double r_px, const PairView& view) const;
  double LookSd() const;
  double CompareSd() const;

  ObserverParams params_;
  std::mt19937_64 rng_;
};

// What a simulated observer answers to a trial, from the trial and what it shows - the one place `blurcue run`
// (headless or in a window) and `blurcue plan` (many simulated sessions, no GL) get their simulated answers from, so
// a plan predicts the answers a run records.

// The seed of the observer of one trial: from the session seed and the trial index (splitmix64), so a resumed
// session answers exactly as an uninterrupted one, and a plan as a run.
uint64_t TrialSeed(uint64_t session_seed, int trial_index);

// The key presses a simulated observer makes for a trial whose stimulus is `scene` (after ApplyLevel for a procedure's
// trial): the single answer, or the adjustment's presses. The task decides the question: yes/no and rating judge the
// one object against the scene; an odd-one-out trial names an interval; a procedure's trial or a practice run to a
// criterion asks "which side is more blurred?"; other pairs "which fits the scene?" (with can't tell when the
// protocol has its key). The presentation gives the arcmin per photo px the arcmin model sees.
std::vector<KeyPress> AnswerTrial(SimulatedObserver& observer, const protocol::Protocol& protocol,
                                  const protocol::Trial& trial, const stimulus::TrialScene& scene,
                                  const stimulus::Presentation& presentation);

// What the observer sees of an adjustment trial: the distance, and for a picture the real picture's blur (when the
// protocol names its camera) and each level's blur in arcmin as this presentation shows them.
AdjustView AdjustViewOf(const protocol::Trial& trial, const stimulus::TrialScene& scene,
                        const stimulus::Presentation& presentation);

// Throws Error(kInput) naming /content/real_camera when `observer` cannot answer the protocol's trials: the arcmin
// model in a depth-matching (adjustment) block without the real photos' camera. Run and plan check before any trial.
void CheckObserverCanAnswer(const ObserverParams& observer, const protocol::Protocol& protocol);

// What the observer sees of a trial's pair: its radii (photo px) and arcmin per photo px on this presentation.
PairView ViewOf(const stimulus::TrialScene& scene, const stimulus::Presentation& presentation);

}  // namespace blurcue::procedure
