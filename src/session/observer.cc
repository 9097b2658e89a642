#include "session/observer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "core/error.h"

namespace blurcue::session {

ObserverParams ParseObserver(const std::string& spec) {
  ObserverParams p;
  if (spec == "sim") return p;
  if (spec.rfind("sim:", 0) != 0)
    throw Error(ErrorKind::kUsage, "--observer must be sim or sim:NAME=VALUE,..., got '" + spec + "'");
  std::stringstream items(spec.substr(4));
  std::string item;
  while (std::getline(items, item, ',')) {
    const size_t eq = item.find('=');
    const std::string name = item.substr(0, eq);
    const std::string text = eq == std::string::npos ? "" : item.substr(eq + 1);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    auto bad = [&](const std::string& what) {
      throw Error(ErrorKind::kUsage, "--observer " + name + " " + what + ", got '" + text + "'");
    };
    if (text.empty() || *end != '\0' || !std::isfinite(v)) bad("must be a number");
    if (name == "jnd") { if (v <= 0) bad("must be > 0"); p.jnd_px = v; }
    else if (name == "bias") p.bias_px = v;
    else if (name == "lapse") { if (v < 0 || v > 1) bad("must be in 0..1"); p.lapse = v; }
    else if (name == "rt") { if (v <= 0) bad("must be > 0"); p.rt_ms = v; }
    else if (name == "step") { if (v <= 0) bad("must be > 0"); p.step_ms = v; }
    else if (name == "cutoff1m") { if (v <= 0) bad("must be > 0"); p.cutoff_1m = v; }
    else if (name == "slope") p.slope = v;
    else if (name == "sdlog") { if (v < 0) bad("must be >= 0"); p.sd_log = v; }
    else if (name == "tol") { if (v < 0) bad("must be >= 0"); p.tolerance_log = v; }
    else
      throw Error(ErrorKind::kUsage, "--observer: unknown parameter '" + name +
                                         "' (known: jnd, bias, lapse, rt, step, cutoff1m, slope, sdlog, tol)");
  }
  return p;
}

std::string ToString(const ObserverParams& p) {
  char text[256];
  std::snprintf(text, sizeof text, "sim:jnd=%g,bias=%g,lapse=%g,rt=%g,step=%g,cutoff1m=%g,slope=%g,sdlog=%g,tol=%g",
                p.jnd_px, p.bias_px, p.lapse, p.rt_ms, p.step_ms, p.cutoff_1m, p.slope, p.sd_log, p.tolerance_log);
  return text;
}

double SimulatedObserver::Uniform() { return double(rng_() >> 11) * 0x1.0p-53; }

double SimulatedObserver::Normal() {
  // Box-Muller from our own uniforms: std::normal_distribution differs between standard libraries.
  const double u1 = 1.0 - Uniform(), u2 = Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

double SimulatedObserver::ResponseTimeMs(double median_ms) { return median_ms * std::exp(0.3 * Normal()); }

KeyPress SimulatedObserver::ChooseSide(const PairView& v, bool cant_tell) {
  const double noise = Normal(), lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms);
  if (lapse_draw < params_.lapse) {
    static const char* kActions[] = {"left", "right", "cant_tell"};
    const int choices = cant_tell ? 3 : 2;
    return {kActions[std::min(choices - 1, int(lapse_pick * choices))], rt};
  }
  const double m_left = std::abs(v.r_left_px - v.r_scene_px), m_right = std::abs(v.r_right_px - v.r_scene_px);
  const double more_blurred = v.r_left_px > v.r_right_px ? 1 : v.r_left_px < v.r_right_px ? -1 : 0;
  const double d = (m_right - m_left) + params_.bias_px * more_blurred + params_.jnd_px * noise;
  const double criterion = cant_tell ? params_.jnd_px / 2 : 0;
  return {d > criterion ? "left" : d < -criterion ? "right" : "cant_tell", rt};
}

KeyPress SimulatedObserver::ChooseBlurrier(const PairView& v) {
  const double noise = Normal(), lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms);
  if (lapse_draw < params_.lapse) return {lapse_pick < 0.5 ? "left" : "right", rt};
  return {v.r_left_px - v.r_right_px + params_.jnd_px * noise > 0 ? "left" : "right", rt};
}

KeyPress SimulatedObserver::ChooseOdd(const PairView& v, int intervals, int odd) {
  // Every interval is seen with its own noise; the odd one is the one farthest from the mean of the others.
  std::vector<double> seen(size_t(std::max(intervals, 1)));
  for (size_t i = 0; i < seen.size(); ++i)
    seen[i] = (int(i) + 1 == odd ? v.r_right_px : v.r_left_px) + params_.jnd_px * Normal();
  const double lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms);
  const int n = int(seen.size());
  if (lapse_draw < params_.lapse) return {std::to_string(1 + std::min(n - 1, int(lapse_pick * n))), rt};
  double total = 0;
  for (double x : seen) total += x;
  int best = 0;
  double farthest = -1;
  for (int i = 0; i < n; ++i) {
    const double others = (total - seen[size_t(i)]) / std::max(1, n - 1);
    if (std::abs(seen[size_t(i)] - others) > farthest) farthest = std::abs(seen[size_t(i)] - others), best = i;
  }
  return {std::to_string(best + 1), rt};
}

KeyPress SimulatedObserver::SayYesNo(const PairView& v) {
  const double evidence = std::abs(v.r_left_px - v.r_scene_px) + params_.jnd_px * Normal();
  const double lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms);
  if (lapse_draw < params_.lapse) return {lapse_pick < 0.5 ? "yes" : "no", rt};
  return {evidence > params_.jnd_px / 2 ? "yes" : "no", rt};
}

KeyPress SimulatedObserver::Rate(const PairView& v, int points) {
  const double evidence = std::abs(v.r_left_px - v.r_scene_px) + params_.jnd_px * Normal();
  const double lapse_draw = Uniform(), lapse_pick = Uniform();
  const double rt = ResponseTimeMs(params_.rt_ms);
  const int n = std::max(points, 1);
  if (lapse_draw < params_.lapse) return {std::to_string(1 + std::min(n - 1, int(lapse_pick * n))), rt};
  int rating = 1;
  for (int j = 1; j < n; ++j) rating += evidence > j * params_.jnd_px / 2;
  return {std::to_string(rating), rt};
}

double SimulatedObserver::TargetCutoff(double distance_m) const {
  return params_.cutoff_1m * std::pow(distance_m, params_.slope);
}

std::vector<KeyPress> SimulatedObserver::Adjust(const std::vector<double>& levels, int start_index,
                                                double distance_m) {
  std::vector<KeyPress> presses;
  const int n = static_cast<int>(levels.size());
  if (n == 0) return presses;
  const double target = std::log(TargetCutoff(distance_m)) + params_.sd_log * Normal();
  auto miss = [&](int i) { return std::abs(std::log(std::max(levels[size_t(i)], 1e-9)) - target); };
  double first = ResponseTimeMs(params_.rt_ms);  // looking at the first level shown
  int at = ((start_index % n) + n) % n, best = at;
  for (int seen = 1;; ++seen) {
    if (miss(at) < miss(best)) best = at;
    if (miss(at) <= params_.tolerance_log || seen == n) break;
    presses.push_back({"next", first + ResponseTimeMs(params_.step_ms)});
    first = 0;
    at = (at + 1) % n;
  }
  // Back the shorter way round to the best level seen.
  const int forward = ((best - at) % n + n) % n, backward = n - forward;
  const bool go_next = forward <= backward;
  for (int k = 0, steps = go_next ? forward : backward; k < steps; ++k)
    presses.push_back({go_next ? "next" : "previous", first + ResponseTimeMs(params_.step_ms)}), first = 0;
  presses.push_back({"accept", first + ResponseTimeMs(params_.step_ms)});
  return presses;
}

}  // namespace blurcue::session
