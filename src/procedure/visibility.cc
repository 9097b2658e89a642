#include "procedure/visibility.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <cstdio>
#include <map>

#include "procedure/adaptive.h"
#include "procedure/observer.h"
#include "protocol/design.h"

namespace blurcue::procedure {

using stimulus::ApplyLevel;
using stimulus::Presentation;
using stimulus::TrialScene;

std::string LevelsLabel(const protocol::Trial& t) {
  std::string levels;
  for (const protocol::Level& level : t.levels) {
    // An object level by its name as trials.csv gives it (its id, else its members), never as a JSON object.
    const protocol::LevelValue* id = level.object ? level.Field("id") : nullptr;
    const std::string name = id             ? protocol::ToJson(*id).dump()
                             : level.object ? protocol::LevelName(level)
                                            : protocol::ToJson(level).dump();
    levels += (levels.empty() ? "" : " ") + level.factor + " " + name;
  }
  return levels;
}

namespace {

// A pair as listed: its levels and the sources it compares (either side order is one pair). Ordered by the levels
// (numbers as numbers: edge 2 before edge 10), then the sources.
struct PairKey {
  std::vector<protocol::Level> levels;
  std::vector<std::string> sources;
  bool operator<(const PairKey& o) const {
    if (const int c = protocol::Compare(levels, o.levels)) return c < 0;
    return sources < o.sources;
  }
};

}  // namespace

std::vector<PairVisibility> PairVisibilities(const PreparedSession& prepared, const ObserverParams& observer,
                                             double level) {
  const protocol::Protocol& p = prepared.protocol;
  std::vector<PairVisibility> pairs;
  std::map<PairKey, size_t> index;  // the pair's key -> its place in `pairs`
  std::vector<PairKey> keys;        // per pair: its key, the order they are listed in
  AdaptiveState adaptive(p);             // no answers yet: each procedure's first level
  for (const protocol::Trial& t : prepared.trials) {
    TrialScene s = prepared.scenes[size_t(t.index)];
    if (protocol::TraitsOf(t.task).answer == protocol::TaskAnswer::kLevel || s.content == protocol::ContentType::kPicture)
      continue;
    // Either side order is one pair: a swapped copy shows the same two blurs.
    const std::string a = protocol::SideText(t.left), b = protocol::SideText(t.right);
    const PairKey key{t.levels, s.left_only ? std::vector<std::string>{a}
                                            : std::vector<std::string>{std::min(a, b), std::max(a, b)}};
    if (const auto it = index.find(key); it != index.end()) {
      ++pairs[it->second].trials;
      continue;
    }
    std::string at = LevelsLabel(t);
    if (t.cell >= 0) {
      const protocol::Procedure& procedure = *protocol::BlockOf(p, t)->procedure;  // t.cell >= 0: it has one
      const double first = adaptive.Level(t);
      ApplyLevel(procedure, t, first, prepared.presentation, &s);
      PlanLeveled(prepared, t, &s);
      at += (at.empty() ? "" : ", ") + std::string("the first ") + protocol::ToString(procedure.variable) + " " + Json(first).dump();
    }
    PairVisibility pair;
    PairView view = ViewOf(s, prepared.presentation);
    if (s.left_only) {
      // One object: does it look out of place - its blur against the scene's own there.
      pair.what = "object " + a + " vs the scene";
      pair.against_scene = true;
      view.r_px[protocol::Index(protocol::Side::kRight)] = view.r_scene_px;
    } else {
      pair.what = a + " vs " + b;
    }
    if (!at.empty()) pair.what += " at " + at;
    pair.r_a_arcmin = prepared.presentation.Arcmin(view.r(protocol::Side::kLeft));
    pair.r_b_arcmin = prepared.presentation.Arcmin(view.r(protocol::Side::kRight));
    pair.p_correct = ProbabilityCorrect2afc(observer, view);
    pair.visible = pair.p_correct >= level;
    pair.trials = 1;
    index[key] = pairs.size();
    pairs.push_back(pair);
    keys.push_back(key);
  }
  // Listed by level (numbers as numbers: edge 2 before edge 10), not in the trial list's random order.
  std::vector<size_t> order(pairs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return keys[a] < keys[b]; });
  std::vector<PairVisibility> sorted;
  for (size_t i : order) sorted.push_back(pairs[i]);
  return sorted;
}

std::vector<MatchVisibility> MatchVisibilities(const PreparedSession& prepared, const ObserverParams& observer,
                                               double level) {
  std::map<double, MatchVisibility> by_distance;
  const Presentation& shown = prepared.presentation;
  if (!(shown.real_frame_px_per_px > 0)) return {};
  for (const protocol::Trial& t : prepared.trials) {
    const TrialScene& s = prepared.scenes[size_t(t.index)];
    if (protocol::TraitsOf(t.task).answer != protocol::TaskAnswer::kLevel || s.content != protocol::ContentType::kPicture)
      continue;
    MatchVisibility& m = by_distance[s.distance_m];
    if (m.trials++ > 0) continue;
    m.distance_m = s.distance_m;
    m.r_real_arcmin = shown.RealArcmin(s.r_scene_px);
    std::vector<double> levels = t.adjust_levels;
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    m.levels = int(levels.size());
    // The level that looks most like the real picture: the smallest share correct, and where shares tie (all 100 %
    // for a keen observer) the nearest blur.
    std::pair<double, double> nearest{2, 0};
    for (double c : levels) {
      const double r = shown.LevelArcmin(c), p = ProbabilityCorrect2afc(observer, r, m.r_real_arcmin);
      if (const std::pair<double, double> key{p, std::abs(r - m.r_real_arcmin)}; key < nearest)
        nearest = key, m.closest = c, m.closest_r_arcmin = r, m.closest_p = p;
      if (p >= level) continue;
      m.alike.push_back(c);
      m.alike_r_min = m.alike.size() == 1 ? r : std::min(m.alike_r_min, r);
      m.alike_r_max = std::max(m.alike_r_max, r);
    }
  }
  std::vector<MatchVisibility> out;
  for (auto& [distance, m] : by_distance) out.push_back(m);
  return out;
}

std::string Describe(const MatchVisibility& m, double level) {
  char text[512];
  int n = std::snprintf(text, sizeof text,
                        "depth matching at %g m: the real picture's blur %.2f' - %zu of %d levels look the same (under "
                        "%.0f %% correct)",
                        m.distance_m, m.r_real_arcmin, m.alike.size(), m.levels, 100 * level);
  if (!m.alike.empty())
    n += std::snprintf(text + n, sizeof text - size_t(n), ": cut-offs %g-%g (%.2f'-%.2f')", m.alike.front(),
                       m.alike.back(), m.alike_r_min, m.alike_r_max);
  std::snprintf(text + n, sizeof text - size_t(n), "; the closest, %g (%.2f'), %.0f %% correct", m.closest,
                m.closest_r_arcmin, 100 * m.closest_p);
  return text;
}

std::vector<std::string> VisibilityLines(const PreparedSession& prepared, const ObserverParams& observer, double level,
                                         bool invisible_only) {
  const auto pairs = PairVisibilities(prepared, observer, level);
  const bool arcmin = observer.model == ObserverModel::kArcmin;
  const auto matches = arcmin ? MatchVisibilities(prepared, observer, level) : std::vector<MatchVisibility>{};
  size_t invisible = 0, as_scene = 0, objects = 0;
  for (const auto& pair : pairs) {
    objects += pair.against_scene;
    (pair.against_scene ? as_scene : invisible) += !pair.visible;
  }
  char line[600];
  std::snprintf(line, sizeof line, "visibility (%s; flagged below %g %% correct): %zu distinct pairs, %zu invisible",
                ToString(observer).c_str(), 100 * level, pairs.size() - objects, invisible);
  std::vector<std::string> lines = {line};
  if (objects > 0)
    lines.back() += "; " + std::to_string(objects) + " single objects, " + std::to_string(as_scene) +
                    " as blurred as the scene to this observer";
  if (!matches.empty()) lines.back() += "; " + std::to_string(matches.size()) + " depth-matching distances";
  for (const auto& pair : pairs)
    if (!invisible_only || !pair.visible) lines.push_back("  " + Describe(pair, prepared.display));
  for (const auto& match : matches) lines.push_back("  " + Describe(match, level));
  if (pairs.empty() && matches.empty())
    lines.push_back(arcmin ? "  nothing to compare: adjustment trials without content.real_camera (the real blur is "
                             "unknown)"
                           : "  nothing to compare: model=pixel has no visual angle for adjustment trials");
  return lines;
}

std::string Describe(const PairVisibility& pair, const display::Profile& profile) {
  char text[512];
  std::snprintf(text, sizeof text, "%s: %.2f arcmin apart (%.2f' vs %.2f'), predicted %.0f %% correct%s",
                pair.what.c_str(), std::abs(pair.r_a_arcmin - pair.r_b_arcmin), pair.r_a_arcmin, pair.r_b_arcmin,
                100 * pair.p_correct,
                pair.visible ? "" : pair.against_scene ? " - as blurred as the scene at " : " - invisible at ");
  std::string line = text;
  if (!pair.visible) {
    std::snprintf(text, sizeof text, "%g cm on this monitor", profile.distance_mm / 10);
    line += text;
  }
  return line;
}

}  // namespace blurcue::procedure
