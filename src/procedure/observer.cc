#include "procedure/observer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/names.h"
#include "core/typed.h"
#include "core/stats.h"
#include "core/seed.h"

namespace blurcue::procedure {

using protocol::Side;

namespace {

constexpr double kZ75 = 0.6744897501960817;  // Phi^-1(0.75)


// ln E(s) = ln (s^p + s_i^p)^(1/p), scaled by the larger term so that neither power overflows.
double LogSeenBlur(const ObserverParams& p, double s_arcmin) {
  const double s = std::max(0.0, s_arcmin), big = std::max(s, p.intrinsic_arcmin);
  return std::log(big) + std::log(std::pow(s / big, p.exponent) + std::pow(p.intrinsic_arcmin / big, p.exponent)) /
                             p.exponent;
}

// The shortest text that reads back as exactly `v`: the recorded observer is the one that answered.
std::string Number(double v) {
  char text[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

}  // namespace

ObserverParams ParseObserver(const std::string& spec) {
  ObserverParams p;
  if (spec == "sim") return p;
  if (spec.rfind("sim:", 0) != 0)
    throw Error(ErrorKind::kUsage, "--observer must be sim or sim:NAME=VALUE,..., got " + Echo(spec));
  std::vector<std::pair<std::string, std::string>> items;
  {
    std::stringstream list(spec.substr(4));
    std::string item;
    while (std::getline(list, item, ',')) {
      const size_t eq = item.find('=');
      items.emplace_back(item.substr(0, eq), eq == std::string::npos ? "" : item.substr(eq + 1));
    }
    if (items.empty() || spec.back() == ',')
      throw Error(ErrorKind::kUsage, "--observer: an empty parameter in " + Echo(spec) + " (sim:NAME=VALUE,...)");
  }
  // The model first: it decides which names belong. Without model=, jnd or bias name the pixel model (the form every
  // record before model= existed holds).
  bool named_model = false;
  for (const auto& [name, text] : items)
    if (name == "model") {
      if (text != "arcmin" && text != "pixel")
        throw Error(ErrorKind::kUsage, "--observer model must be arcmin or pixel, got " + Echo(text));
      p.model = text == "pixel" ? ObserverModel::kPixel : ObserverModel::kArcmin;
      named_model = true;
    }
  static const std::set<std::string> kArcminOnly = {"intrinsic", "weber", "exponent", "side", "blurrier", "rthard"};
  static const std::set<std::string> kPixelOnly = {"jnd", "bias", "cutoff1m", "slope", "sdlog", "tol"};
  if (!named_model)
    for (const auto& item : items)
      if (kPixelOnly.count(item.first)) p.model = ObserverModel::kPixel;
  const bool pixel = p.model == ObserverModel::kPixel;
  std::set<std::string> seen;
  for (const auto& [name, text] : items) {
    if (!seen.insert(name).second)
      throw Error(ErrorKind::kUsage, "--observer " + Echo(name, false) + " is given twice in " + Echo(spec));
    if (name == "model") continue;
    if ((pixel ? kArcminOnly : kPixelOnly).count(name))
      throw Error(ErrorKind::kUsage, "--observer " + name + " belongs to model=" + (pixel ? "arcmin" : "pixel") +
                                         ", not model=" + (pixel ? "pixel" : "arcmin") + " (got " + Echo(text) + ")");
    const std::optional<double> parsed = ParseDecimal(text);
    const double v = parsed.value_or(0);
    auto bad = [&](const std::string& what) {
      throw Error(ErrorKind::kUsage, "--observer " + name + " " + what + ", got " + Echo(text));
    };
    auto in = [&](double lo, double hi, bool open_lo, const char* what) {
      if (v > hi || v < lo || (open_lo && v == lo)) bad(what);
      return v;
    };
    static const std::set<std::string> kBoth = {"lapse", "rt", "step"};
    if (!kArcminOnly.count(name) && !kPixelOnly.count(name) && !kBoth.count(name)) {
      // A slip of a known name is answered with it (bais: did you mean bias?), as a protocol's names are.
      std::vector<std::string> known = {"model"};
      for (const auto* names : {pixel ? &kPixelOnly : &kArcminOnly, &kBoth})
        known.insert(known.end(), names->begin(), names->end());
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      const std::string hint = DidYouMean(name, known);
      throw Error(ErrorKind::kUsage, "--observer: unknown parameter " + Echo(name) +
                                         (hint.empty() ? " (known: " + list + ")" : hint));
    }
    if (!parsed) bad("must be a number");
    // Ranges: what a human observer could be, so a typo (1e308, a missing decimal point) is refused, not simulated.
    if (name == "intrinsic") p.intrinsic_arcmin = in(0, 60, true, "must be in (0, 60] arcmin (a Gaussian std)");
    else if (name == "weber") p.weber = in(0, 10, true, "must be in (0, 10]");
    else if (name == "exponent") p.exponent = in(0.5, 20, false, "must be in [0.5, 20]");
    else if (name == "side") p.side_bias = in(-10, 10, false, "must be in -10..10 (noise sds)");
    else if (name == "blurrier") p.blurrier_bias = in(-10, 10, false, "must be in -10..10 (noise sds)");
    else if (name == "rthard") p.rt_hard = in(0, 100, false, "must be in 0..100");
    else if (name == "jnd") p.jnd_px = in(0, 1e4, true, "must be in (0, 10000] px");
    else if (name == "bias") p.bias_px = in(-1e4, 1e4, false, "must be in -10000..10000 px");
    else if (name == "lapse") p.lapse = in(0, 1, false, "must be in 0..1");
    else if (name == "rt") p.rt_ms = in(0, 600000, true, "must be in (0, 600000] ms");
    else if (name == "step") p.step_ms = in(0, 600000, true, "must be in (0, 600000] ms");
    else if (name == "cutoff1m") p.cutoff_1m = in(0, 1e6, true, "must be in (0, 1e6] cycles per picture width");
    else if (name == "slope") p.slope = in(-100, 100, false, "must be in -100..100");
    else if (name == "sdlog") p.sd_log = in(0, 100, false, "must be in 0..100");
    else if (name == "tol") p.tolerance_log = in(0, 100, false, "must be in 0..100");
  }
  return p;
}

std::string ToString(const ObserverParams& p) {
  std::string text = "sim:model=";
  if (p.model == ObserverModel::kPixel)
    text += "pixel,jnd=" + Number(p.jnd_px) + ",bias=" + Number(p.bias_px);
  else
    text += "arcmin,intrinsic=" + Number(p.intrinsic_arcmin) + ",weber=" + Number(p.weber) + ",exponent=" +
            Number(p.exponent) + ",side=" + Number(p.side_bias) + ",blurrier=" + Number(p.blurrier_bias) +
            ",rthard=" + Number(p.rt_hard);
  text += ",lapse=" + Number(p.lapse) + ",rt=" + Number(p.rt_ms) + ",step=" + Number(p.step_ms);
  if (p.model == ObserverModel::kPixel)
    text += ",cutoff1m=" + Number(p.cutoff_1m) + ",slope=" + Number(p.slope) + ",sdlog=" + Number(p.sd_log) +
            ",tol=" + Number(p.tolerance_log);
  return text;
}

double ProbabilityCorrect2afc(const ObserverParams& p, double r_a_arcmin, double r_b_arcmin) {
  if (p.model != ObserverModel::kArcmin)
    throw Error(ErrorKind::kUsage, "--observer model=pixel answers in photo px: it has no probability for radii in "
                                   "arcmin (use model=arcmin)");
  // r = 2 s (DESIGN.md: blurcue's radius is twice the line-spread function's std).
  const double d = std::abs(LogSeenBlur(p, r_a_arcmin / 2) - LogSeenBlur(p, r_b_arcmin / 2));
  return StdNormalCdf(kZ75 * d / std::log1p(p.weber));
}

double ProbabilityCorrect2afc(const ObserverParams& p, const PairView& v) {
  if (p.model == ObserverModel::kPixel) return StdNormalCdf(std::abs(v.r(Side::kLeft) - v.r(Side::kRight)) / p.jnd_px);
  if (!(v.arcmin_per_px > 0))
    throw Error(ErrorKind::kInternal, "the arcmin observer was given a pair without its arcmin per photo px");
  return ProbabilityCorrect2afc(p, v.r(Side::kLeft) * v.arcmin_per_px, v.r(Side::kRight) * v.arcmin_per_px);
}

double DiscriminationThresholdArcmin(const ObserverParams& p, double r_ref_arcmin) {
  const double s = std::max(0.0, r_ref_arcmin / 2), e = p.exponent, si = p.intrinsic_arcmin;
  const double seen = std::pow(1 + p.weber, e) * (std::pow(s, e) + std::pow(si, e)) - std::pow(si, e);
  return 2 * (std::pow(seen, 1 / e) - s);
}

double SimulatedObserver::Uniform() { return double(rng_() >> 11) * 0x1.0p-53; }

double SimulatedObserver::Normal() {
  // Box-Muller from our own uniforms: std::normal_distribution differs between standard libraries.
  const double u1 = 1.0 - Uniform(), u2 = Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

double SimulatedObserver::ResponseTimeMs(double median_ms, double d_prime) {
  // Harder discriminations take longer (the arcmin model): up to (1 + rt_hard) x the median at d' = 0.
  if (params_.model == ObserverModel::kArcmin) median_ms *= 1 + params_.rt_hard * std::exp(-d_prime * d_prime / 2);
  return median_ms * std::exp(0.3 * Normal());
}

double SimulatedObserver::Seen(double r_px, const PairView& v) const {
  if (params_.model == ObserverModel::kPixel) return r_px;
  if (!(v.arcmin_per_px > 0) || !std::isfinite(v.arcmin_per_px))
    throw Error(ErrorKind::kInternal, "the arcmin observer was given a trial without its arcmin per photo px");
  return LogSeenBlur(params_, r_px * v.arcmin_per_px / 2);  // r = 2 s
}

double SimulatedObserver::LookSd() const {
  return params_.model == ObserverModel::kPixel ? params_.jnd_px : std::log1p(params_.weber) / (std::sqrt(2.0) * kZ75);
}

double SimulatedObserver::CompareSd() const {
  return params_.model == ObserverModel::kPixel ? params_.jnd_px : std::log1p(params_.weber) / kZ75;
}

// The draws of every answer come in one order (decision noise, lapse, lapse pick, response time), the pixel model's
// of old: a seed answers as it did before the arcmin model existed.
KeyPress SimulatedObserver::ChooseSide(const PairView& v, bool cant_tell) {
  const double sd = CompareSd();
  const double m_left = std::abs(Seen(v.r(Side::kLeft), v) - Seen(v.r_scene_px, v)),
               m_right = std::abs(Seen(v.r(Side::kRight), v) - Seen(v.r_scene_px, v));
  const double more_blurred = v.r(Side::kLeft) > v.r(Side::kRight) ? 1 : v.r(Side::kLeft) < v.r(Side::kRight) ? -1 : 0;
  const double bias = params_.model == ObserverModel::kPixel
                          ? params_.bias_px * more_blurred
                          : (params_.blurrier_bias * more_blurred + params_.side_bias) * sd;
  const double noise = Normal(), lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms, (m_right - m_left) / sd);
  const Choice left = Choice::Of(Side::kLeft), right = Choice::Of(Side::kRight),
               neither = Choice::Of(Choice::Kind::kCantTell);
  if (lapse_draw < params_.lapse) {
    const Choice choices[] = {left, right, neither};
    const int n = cant_tell ? 3 : 2;
    return {Action::Answer(choices[std::min(n - 1, int(lapse_pick * n))]), rt};
  }
  const double d = (m_right - m_left) + bias + sd * noise;
  const double criterion = cant_tell ? sd / 2 : 0;
  return {Action::Answer(d > criterion ? left : d < -criterion ? right : neither), rt};
}

KeyPress SimulatedObserver::ChooseBlurrier(const PairView& v) {
  const double sd = CompareSd();
  const double difference = Seen(v.r(Side::kLeft), v) - Seen(v.r(Side::kRight), v);
  const double side = params_.model == ObserverModel::kPixel ? 0 : params_.side_bias * sd;
  const double noise = Normal(), lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms, difference / sd);
  const Side chosen = lapse_draw < params_.lapse ? (lapse_pick < 0.5 ? Side::kLeft : Side::kRight)
                      : difference + side + sd * noise > 0 ? Side::kLeft
                                                           : Side::kRight;
  return {Action::Answer(Choice::Of(chosen)), rt};
}

KeyPress SimulatedObserver::ChooseOdd(const PairView& v, int intervals, int odd) {
  // Every interval is seen with its own noise; the odd one is the one farthest from the mean of the others.
  const double look = LookSd(), odd_seen = Seen(v.r(Side::kRight), v), other_seen = Seen(v.r(Side::kLeft), v);
  std::vector<double> seen(size_t(std::max(intervals, 1)));
  for (size_t i = 0; i < seen.size(); ++i) seen[i] = (int(i) + 1 == odd ? odd_seen : other_seen) + look * Normal();
  const double lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms, (odd_seen - other_seen) / CompareSd());
  const int n = int(seen.size());
  auto interval = [rt](int i) { return KeyPress{Action::Answer(Choice::Numbered(Choice::Kind::kInterval, i)), rt}; };
  if (lapse_draw < params_.lapse) return interval(1 + std::min(n - 1, int(lapse_pick * n)));
  double total = 0;
  for (double x : seen) total += x;
  int best = 0;
  double farthest = -1;
  for (int i = 0; i < n; ++i) {
    const double others = (total - seen[size_t(i)]) / std::max(1, n - 1);
    if (std::abs(seen[size_t(i)] - others) > farthest) farthest = std::abs(seen[size_t(i)] - others), best = i;
  }
  return interval(best + 1);
}

KeyPress SimulatedObserver::SayYesNo(const PairView& v) {
  const double sd = CompareSd(), mismatch = std::abs(Seen(v.r(Side::kLeft), v) - Seen(v.r_scene_px, v));
  const double evidence = mismatch + sd * Normal();
  const double lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms, mismatch / sd);
  const Choice yes = Choice::Of(Choice::Kind::kYes), no = Choice::Of(Choice::Kind::kNo);
  if (lapse_draw < params_.lapse) return {Action::Answer(lapse_pick < 0.5 ? yes : no), rt};
  return {Action::Answer(evidence > sd / 2 ? yes : no), rt};
}

KeyPress SimulatedObserver::Rate(const PairView& v, int points) {
  const double sd = CompareSd(), mismatch = std::abs(Seen(v.r(Side::kLeft), v) - Seen(v.r_scene_px, v));
  const double evidence = mismatch + sd * Normal();
  const double lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms, mismatch / sd);
  const int n = std::max(points, 1);
  auto point = [rt](int i) { return KeyPress{Action::Answer(Choice::Numbered(Choice::Kind::kRating, i)), rt}; };
  if (lapse_draw < params_.lapse) return point(1 + std::min(n - 1, int(lapse_pick * n)));
  int rating = 1;
  for (int j = 1; j < n; ++j) rating += evidence > j * sd / 2;
  return point(rating);
}

double SimulatedObserver::TargetCutoff(double distance_m) const {
  return params_.cutoff_1m * std::pow(distance_m, params_.slope);
}

std::vector<KeyPress> SimulatedObserver::Adjust(const std::vector<double>& levels, int start_index,
                                                const AdjustView& view) {
  std::vector<KeyPress> presses;
  const int n = static_cast<int>(levels.size());
  if (n == 0) return presses;
  // How far level i is from what the observer wants (looked at once, when first shown), and the most it accepts.
  std::function<double(int)> look;
  double accept_within = 0;
  if (params_.model == ObserverModel::kPixel) {
    const double target = std::log(TargetCutoff(view.distance_m)) + params_.sd_log * Normal();
    look = [&levels, target](int i) { return std::abs(std::log(std::max(levels[size_t(i)], 1e-9)) - target); };
    accept_within = params_.tolerance_log;
  } else {
    if (!(view.r_real_arcmin >= 0) || view.level_r_arcmin.size() != levels.size())
      throw Error(ErrorKind::kUsage, "the arcmin observer matches the real picture's blur in visual angle: the "
                                     "protocol must name the camera of its real photos (content.real_camera), or use "
                                     "--observer sim:model=pixel");
    const double real = LogSeenBlur(params_, view.r_real_arcmin / 2), sd = CompareSd();
    look = [this, &view, real, sd](int i) {
      return std::abs(LogSeenBlur(params_, view.level_r_arcmin[size_t(i)] / 2) - real + sd * Normal());
    };
    accept_within = -1;  // every level is seen; the closest-looking one is taken
  }
  double first = ResponseTimeMs(params_.rt_ms);  // looking at the first level shown
  int at = ((start_index % n) + n) % n, best = at;
  double best_miss = std::numeric_limits<double>::infinity();
  for (int seen = 1;; ++seen) {
    const double miss = look(at);
    if (miss < best_miss) best = at, best_miss = miss;
    if (miss <= accept_within || seen == n) break;
    presses.push_back({Action::Of(Action::Kind::kNext), first + ResponseTimeMs(params_.step_ms)});
    first = 0;
    at = (at + 1) % n;
  }
  // Back the shorter way round to the best level seen.
  const int forward = ((best - at) % n + n) % n, backward = n - forward;
  const bool go_next = forward <= backward;
  for (int k = 0, steps = go_next ? forward : backward; k < steps; ++k)
    presses.push_back({Action::Of(go_next ? Action::Kind::kNext : Action::Kind::kPrevious),
                       first + ResponseTimeMs(params_.step_ms)}),
        first = 0;
  presses.push_back({Action::Of(Action::Kind::kAccept), first + ResponseTimeMs(params_.step_ms)});
  return presses;
}

uint64_t TrialSeed(uint64_t seed, int index) { return DeriveSeed(seed, static_cast<uint64_t>(index)); }

PairView ViewOf(const stimulus::TrialScene& scene, const stimulus::Presentation& presentation) {
  // One photo px's angle at the centre of the screen (Presentation::Arcmin): the radii are a few px, where the
  // exact 2 atan(s / 2d) and the straight line agree to far better than 1e-6.
  return {{scene.side(Side::kLeft).r_px, scene.side(Side::kRight).r_px}, scene.r_scene_px, presentation.Arcmin(1)};
}

AdjustView AdjustViewOf(const protocol::Trial& trial, const stimulus::TrialScene& scene,
                        const stimulus::Presentation& presentation) {
  AdjustView view;
  view.distance_m = scene.distance_m;
  if (scene.content != protocol::ContentType::kPicture) return view;
  if (presentation.real_frame_px_per_px > 0) view.r_real_arcmin = presentation.RealArcmin(scene.r_scene_px);
  for (double level : trial.adjust_levels) view.level_r_arcmin.push_back(presentation.LevelArcmin(level));
  return view;
}

void CheckObserverCanAnswer(const ObserverParams& observer, const protocol::Protocol& protocol) {
  if (observer.model != ObserverModel::kArcmin || protocol.content.type != protocol::ContentType::kPicture ||
      protocol.content.real_camera)
    return;
  for (const auto& block : protocol.blocks)
    if (protocol::TraitsOf(block.task).answer == protocol::TaskAnswer::kLevel)
      throw InputError(protocol.file.string() + ": /content/real_camera",
                       "is needed by the simulated observer (model=arcmin), which sets the picture to the real "
                       "picture's blur in visual angle: name the camera and focus of the real photos, or use "
                       "--observer sim:model=pixel (a cut-off per distance)");
}

std::vector<KeyPress> AnswerTrial(SimulatedObserver& observer, const protocol::Protocol& protocol,
                                  const protocol::Trial& trial, const stimulus::TrialScene& scene,
                                  const stimulus::Presentation& presentation) {
  using protocol::TaskAnswer;
  switch (protocol::TraitsOf(trial.task).answer) {
    case TaskAnswer::kLevel:
      return observer.Adjust(trial.adjust_levels, trial.start_index, AdjustViewOf(trial, scene, presentation));
    case TaskAnswer::kYesNo: return {observer.SayYesNo(ViewOf(scene, presentation))};
    case TaskAnswer::kRatingPoint:
      return {observer.Rate(ViewOf(scene, presentation), int(protocol.responses.rating.size()))};
    case TaskAnswer::kSide: break;
  }
  const PairView view = ViewOf(scene, presentation);
  const KeyPress press =
      scene.intervals > 2 ? observer.ChooseOdd(view, scene.intervals, protocol::TestInterval(trial))
      // A procedure, or practice scored by a criterion: "which side is more blurred?"
      : trial.cell >= 0 || trial.round >= 0 ? observer.ChooseBlurrier(view)
                                            : observer.ChooseSide(view, !protocol.responses.cant_tell.empty());
  return {press};
}

}  // namespace blurcue::procedure
