#include "plan/plan.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <mutex>
#include <set>
#include <thread>

#include "core/error.h"
#include "core/typed.h"
#include "core/json_io.h"
#include "core/seed.h"
#include "plan/comparisons.h"
#include "plan/power.h"
#include "plan/threshold.h"
#include "protocol/trials.h"
#include "procedure/observer.h"
#include "procedure/prepare.h"
#include "procedure/trial_logic.h"
#include "store/export.h"
#include "store/record.h"
#include "store/schema.h"

namespace blurcue::plan {

using procedure::Choice;
using protocol::Side;

bool ConditionKey::operator<(const ConditionKey& o) const {
  if (block != o.block) return block < o.block;
  if (slope != o.slope) return slope < o.slope;
  if (const int c = protocol::Compare(levels, o.levels)) return c < 0;
  return group < o.group;
}

namespace {

using protocol::Task;


// A level as a label shows it: a number as %g, a string as itself, an object by its id or name.
std::string LevelText(const protocol::LevelValue& value) {
  return value.IsNumber() ? protocol::LevelText(value.number) : value.text;
}
std::string LevelText(const protocol::Level& level) {
  if (!level.object) return LevelText(level.value);
  for (const char* name : {"id", "name"})
    if (const protocol::LevelValue* v = level.Field(name)) return LevelText(*v);
  return protocol::ToJson(level).dump();
}

// The thesis's forced-choice studies, which the report analyses with their own views (analysis/common.py
// FORCED_CHOICE_STUDIES): the share of the design's first source among decisive answers.
bool IsThesisForcedChoice(const std::string& study) {
  return study == "test1-static-grids" || study == "test2-moving-balls" || study == "test3-no-board";
}

// The condition of a main (not practice) trial and the measure its tests use; nullopt for what is not planned.
std::optional<Condition> ConditionOf(const protocol::Protocol& protocol, const protocol::Trial& trial,
                                     const stimulus::TrialScene& scene, bool several_blocks) {
  Condition c;
  c.block = protocol::BlockIndex(protocol, trial);
  c.key.block = trial.block;
  c.key.levels = trial.levels;
  std::string label;
  for (const protocol::Level& level : trial.levels)
    label += (label.empty() ? "" : " ") + level.factor + "=" + LevelText(level);
  c.label = (several_blocks ? trial.block + (label.empty() ? "" : ": ") : "") + (label.empty() && !several_blocks ? "all" : label);
  const protocol::TaskTraits& task = protocol::TraitsOf(trial.task);
  if (task.answer == protocol::TaskAnswer::kYesNo) {
    c.measure = "yes";
  } else if (trial.cell >= 0) {
    // A procedure sets how often its trials are right (it moves the level to its target share): what it measures is
    // the threshold, so that is what is planned, not its share correct against chance.
    c.measure = "threshold";
    c.units = protocol::ToString(protocol::BlockOf(protocol, trial)->procedure->variable);
  } else if (!trial.test_side.empty()) {
    c.measure = "correct";
    c.chance = scene.intervals > 2 ? 1.0 / scene.intervals : 0.5;
  } else if (task.answer == protocol::TaskAnswer::kSide && scene.content != protocol::ContentType::kPicture) {
    // The report's measure of a pair: for any study, trials.csv's chose_more_blurred - the side that showed the
    // larger blur radius, among decisive answers where the radii differ (the design's first source, planned before,
    // reads the other way round wherever the second source is the blurrier one: a comparison of none against
    // measured gave 0.1 for the report's 0.9); for the thesis's own forced-choice studies, whose report view
    // (analysis/forced_choice.py) tests the design's first source, that source.
    c.measure = IsThesisForcedChoice(protocol.name) ? "first_source" : "more_blurred";
    c.chance = 0.5;
  } else {
    return std::nullopt;
  }
  return c;
}

// With groups, a block that several groups run is planned per group (key and label name the group): its conditions -
// shares and procedure cells alike - are compared between the groups, never pooled over them (a shared block's
// "edge=1" binomial and a shared QUEST+ cell's threshold and interval width mixed both groups' participants).
void SplitByGroup(const protocol::Protocol& protocol, const protocol::Trial& trial, const std::string& group,
                  Condition* c) {
  if (!protocol.groups || protocol.groups->names.size() < 2 || group.empty()) return;
  if (protocol::BlockOf(protocol, trial)->groups.size() == 1) return;
  c->key.group = group;
  c->label = "group=" + group + ": " + c->label;
}

// A pair's answer counted: by the source chosen (as designed) and, as the report's measure, whether the side chosen
// showed the larger radius - as store/export.cc's chose_more_blurred: radii within 1e-9 px are equal and count for
// neither side.
void TallyPair(const protocol::Trial& trial, const stimulus::TrialScene& scene, const Choice& choice, bool by_first,
               Tally* t) {
  const bool left = choice == Choice::Of(Side::kLeft), right = choice == Choice::Of(Side::kRight);
  const bool first = trial.swapped ? right : left, second = trial.swapped ? left : right;
  t->first += first, t->second += second, t->cant_tell += choice.kind == Choice::Kind::kCantTell;
  const double r_left = scene.sides[protocol::Index(Side::kLeft)].r_px;
  const double r_right = scene.sides[protocol::Index(Side::kRight)].r_px;
  const bool differ = std::abs(r_left - r_right) > 1e-9, left_blurrier = r_left > r_right;
  if (!differ) {
    ++t->blurrier_equal;
  } else {
    (left_blurrier != trial.swapped ? t->blurrier_first : t->blurrier_second) += 1;
  }
  if (by_first)
    t->k += first, t->n += first || second;
  else if (differ && (left || right))
    t->k += left == left_blurrier, ++t->n;
}

// One simulated participant through the session's own decisions (what `blurcue run --observer sim` does headless).
SimParticipant Simulate(procedure::PreparedSession& study, const procedure::ObserverParams& observer, const std::string& id,
                        uint64_t seed, const std::string& group, bool keep_answers, bool several_blocks,
                        procedure::SceneCache* cache, std::map<ConditionKey, Condition>* conditions,
                        std::set<std::string>* unplanned) {
  procedure::PrepareParticipant(&study, id, seed, group, cache);
  SimParticipant p;
  p.id = id;
  p.seed = seed;
  p.group = study.group;
  const protocol::Protocol& protocol = study.protocol;
  procedure::SessionLogic logic(study, cache);
  // A procedure cell's track: the levels shown and the answers as the procedure scored them (a missed deadline wrong).
  struct Track {
    const protocol::Procedure* procedure;
    std::vector<double> levels;
    std::vector<bool> correct;
  };
  std::map<ConditionKey, Track> tracks;
  for (const protocol::Trial& trial : study.trials) {
    if (logic.SkipReason(trial)) {
      if (keep_answers) p.answers.emplace_back(trial.index, Choice::Of(Choice::Kind::kSkipped));
      continue;
    }
    double level = 0;
    const stimulus::TrialScene scene = logic.SceneOf(trial, &level);
    const auto presses = procedure::ObserverPresses(observer, study.seed, protocol, trial, scene, study.presentation);
    const Choice choice = procedure::HeadlessAnswer(protocol, trial, scene, presses).first;
    const procedure::Scored scored = logic.Answer(trial, scene, level, choice);
    if (keep_answers) p.answers.emplace_back(trial.index, choice);
    if (trial.practice) continue;
    if (protocol::TraitsOf(trial.task).answer == protocol::TaskAnswer::kLevel &&
        scene.content == protocol::ContentType::kPicture) {
      // Depth matching: one condition per block, the slope of the accepted cut-off on distance across its trials.
      Condition c;
      c.block = protocol::BlockIndex(protocol, trial);
      c.key.block = trial.block;
      c.key.slope = true;
      c.label = (several_blocks ? trial.block + ": " : std::string()) + "cut-off ~ distance";
      c.measure = "log_cutoff_slope";
      c.chance = 0;
      SplitByGroup(protocol, trial, p.group, &c);
      conditions->emplace(c.key, c);
      Tally& t = p.tallies[c.key];
      ++t.shown;
      // The level as the record writes it (%g), as the report reads a run's: the plan fits the same numbers.
      const double cutoff = choice.kind == Choice::Kind::kLevel ? ParseDecimal(procedure::Name(choice)).value_or(0) : 0;
      if (!(cutoff > 0) || !(scene.distance_m > 0)) {
        ++t.none;
        continue;
      }
      ++t.n;
      p.matches[c.key].emplace_back(std::log(scene.distance_m), std::log(cutoff));
      continue;
    }
    std::optional<Condition> c = ConditionOf(protocol, trial, scene, several_blocks);
    if (c) SplitByGroup(protocol, trial, p.group, &*c);
    if (!c) {
      unplanned->insert(protocol::ToString(trial.task));
      continue;
    }
    if (c->measure == "threshold") {
      if (!conditions->count(c->key)) {
        // The truth from the observer model's own psychometric function at the scene as planned (no answers yet).
        Condition with_truth = *c;
        const protocol::Procedure& procedure = *protocol::BlockOf(protocol, trial)->procedure;
        const TrueThreshold truth =
            ObserverThreshold(observer, procedure, trial, study.scenes[size_t(trial.index)], study.presentation);
        with_truth.truth_determined = truth.determined;
        with_truth.truth = truth.level;
        with_truth.truth_why = truth.why;
        with_truth.truth_beyond = truth.beyond;
        with_truth.range_lo = truth.range_lo, with_truth.range_hi = truth.range_hi;
        char target[160];
        if (procedure.kind == protocol::Procedure::Kind::kQuestPlus)
          std::snprintf(target, sizeof target, "%.1f %% correct without lapses (QUEST+'s Weibull threshold)",
                        100 * TargetShare(procedure, 0));
        else
          std::snprintf(target, sizeof target, "%.1f %% correct, lapses included (the %d-up/%d-down rule's convergence point)",
                        100 * TargetShare(procedure, 0), procedure.up, procedure.down);
        with_truth.target = target;
        conditions->emplace(c->key, with_truth);
      }
      Track& track =
          tracks.try_emplace(c->key, Track{&*protocol::BlockOf(protocol, trial)->procedure, {}, {}}).first->second;
      track.levels.push_back(level);
      track.correct.push_back(scored.correct.value_or(false));
      continue;
    }
    conditions->emplace(c->key, *c);
    Tally& t = p.tallies[c->key];
    ++t.shown;
    const bool none = choice.kind == Choice::Kind::kNone;
    t.none += none;
    if (c->measure == "more_blurred" || c->measure == "first_source") {
      TallyPair(trial, scene, choice, c->measure == "first_source", &t);
    } else if (c->measure == "correct") {
      // The report counts answers (a missed deadline is no answer), correct against the guess rate.
      if (!none) t.k += scored.correct.value_or(false), ++t.n;
    } else if (!none) {
      t.k += choice.kind == Choice::Kind::kYes, ++t.n;
    }
  }
  for (const auto& [key, track] : tracks) {
    procedure::TrackThreshold t = TrackEstimate(*track.procedure, track.levels, track.correct);
    if (t.determined) p.thresholds[key] = t.estimate;
    p.tracks[key] = std::move(t);
  }
  return p;
}

std::string Number(double v, const char* format = "%.6f") {
  if (!std::isfinite(v)) return "";
  char text[48];
  std::snprintf(text, sizeof text, format, v);
  return text;
}


}  // namespace

namespace {

void CheckSizes(const PlanOptions& options) {
  if (options.participants < 1 || options.studies < 1)
    throw Error(ErrorKind::kUsage, "--participants and --studies must be at least 1");
  if (double(options.participants) * options.studies > 2e7)
    throw Error(ErrorKind::kUsage, "--participants x --studies must be at most 20000000 simulated participants, got " +
                                       std::to_string(options.participants) + " x " + std::to_string(options.studies));
}

}  // namespace

std::vector<std::vector<SimParticipant>> SimulateStudies(const PlanOptions& options,
                                                         const procedure::PreparedSession& study,
                                                         std::vector<Condition>* conditions,
                                                         std::vector<std::string>* notes, int* threads_used) {
  CheckSizes(options);
  const procedure::ObserverParams observer = procedure::ParseObserver(options.observer);
  const protocol::Protocol& protocol = study.protocol;
  procedure::CheckObserverCanAnswer(observer, protocol);
  int main_blocks = 0;
  for (const auto& b : protocol.blocks) main_blocks += !b.practice;
  const bool several_blocks = main_blocks > 1;
  // Groups as a study would assign them, participant after participant (balanced: the fewest so far).
  const int n = options.participants;
  std::vector<std::string> ids(static_cast<size_t>(n)), groups(static_cast<size_t>(n));
  std::map<std::string, int64_t> sessions;
  for (int i = 0; i < n; ++i) {
    ids[size_t(i)] = "P" + std::to_string(i + 1);
    groups[size_t(i)] = protocol::AssignGroup(protocol, ids[size_t(i)], sessions);
    if (!groups[size_t(i)].empty()) ++sessions[groups[size_t(i)]];
  }
  const int64_t total = int64_t(n) * options.studies;
  int threads = options.threads > 0 ? options.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  threads = int(std::min<int64_t>(threads, total));
  *threads_used = threads;
  std::vector<std::vector<SimParticipant>> out(static_cast<size_t>(options.studies),
                                                std::vector<SimParticipant>(static_cast<size_t>(n)));
  std::vector<std::map<ConditionKey, Condition>> found(static_cast<size_t>(threads));
  std::vector<std::set<std::string>> unplanned(static_cast<size_t>(threads));
  std::atomic<int64_t> next{0}, done{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::exception_ptr error;
  int64_t error_at = total;
  auto work = [&](int worker) {
    procedure::PreparedSession mine = study;  // each worker's own copy (images are shared, read only)
    procedure::SceneCache cache;              // and its own scenes, reused by its participants
    for (int64_t index; !failed && (index = next++) < total;) {
      const int s = int(index / n), i = int(index % n);
      try {
        out[size_t(s)][size_t(i)] = Simulate(mine, observer, ids[size_t(i)], DeriveSeed(DeriveSeed(options.seed, s), i),
                                             groups[size_t(i)], s == 0, several_blocks, &cache, &found[size_t(worker)],
                                             &unplanned[size_t(worker)]);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        // The first failing participant in order, whatever the thread count.
        if (index < error_at) error = std::current_exception(), error_at = index;
        failed = true;
      }
      const int64_t d = ++done;
      if (options.progress && (d * 10 / total != (d - 1) * 10 / total || d == total)) {
        std::lock_guard<std::mutex> lock(mutex);
        options.progress("simulated " + std::to_string(d) + " of " + std::to_string(total) + " participants");
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  std::map<ConditionKey, Condition> all;
  std::set<std::string> skipped_tasks;
  for (int t = 0; t < threads; ++t) {
    all.insert(found[size_t(t)].begin(), found[size_t(t)].end());
    skipped_tasks.insert(unplanned[size_t(t)].begin(), unplanned[size_t(t)].end());
  }
  conditions->clear();
  for (const auto& [key, c] : all) conditions->push_back(c);
  // Stable: the same block and levels in several groups keep the keys' order (the map's), whatever the threads.
  std::stable_sort(conditions->begin(), conditions->end(), [](const Condition& a, const Condition& b) {
    if (a.block != b.block) return a.block < b.block;
    return protocol::Compare(a.key.levels, b.key.levels) < 0;
  });
  for (const std::string& task : skipped_tasks)
    notes->push_back(task + " trials are not planned: they have no share to test against a chance level");
  return out;
}

namespace {

// Depth matching's rows: per N, the mean slope, the mean width of its 95 % t interval across N participants, and the
// power of the t-test of the slopes against 0.
void AddSlopeRows(PlanResult& r, const Condition& c, const PlanOptions& options) {
  const int N = options.participants, S = options.studies;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Over every study and participant, as the binomial rows: the mean slope and the share without an answer.
  double sum = 0, shown = 0, none = 0;
  int count = 0;
  for (const auto& study : r.studies)
    for (const SimParticipant& p : study)
      if (const auto it = p.tallies.find(c.key); it != p.tallies.end()) shown += it->second.shown, none += it->second.none;
  // Per study, the slopes of participants 1 .. m so far (those with one), grown with m.
  std::vector<std::vector<double>> slopes(static_cast<size_t>(S));
  std::vector<double> t975(1, nan);  // by degrees of freedom, worked out once each
  double matches = 0;                // answered matches of participants 1 .. m, over the studies
  for (int m = 1; m <= N; ++m) {
    PowerRow row;
    row.test = "slope_t";
    row.condition = c.label;
    row.measure = c.measure;
    row.chance = 0;
    row.participants = m;
    row.share_first = row.share_second = row.share_cant_tell = nan;
    row.share_none = shown > 0 ? none / shown : nan;
    double width = 0;
    int rejected = 0, widths = 0;
    for (int s = 0; s < S; ++s) {
      const SimParticipant& p = r.studies[size_t(s)][size_t(m - 1)];
      std::vector<double>& values = slopes[size_t(s)];
      if (const auto it = p.matches.find(c.key); it != p.matches.end()) {
        matches += double(it->second.size());
        if (const double b = OlsSlope(it->second); std::isfinite(b)) values.push_back(b), sum += b, ++count;
      }
      if (values.size() < 2) continue;
      const double n = double(values.size());
      double mean = 0, ss = 0;
      for (double v : values) mean += v;
      mean /= n;
      for (double v : values) ss += (v - mean) * (v - mean);
      while (t975.size() < values.size()) t975.push_back(StudentT975(int(t975.size())));
      width += 2 * t975[values.size() - 1] * std::sqrt(ss / (n - 1) / n);
      ++widths;
      rejected += OneSampleTTestP(values, 0) < options.alpha;
    }
    row.mean_trials = matches / S;  // answered matches per study at this N
    row.wilson_width = widths > 0 ? width / widths : nan;
    row.power = double(rejected) / S;
    r.rows.push_back(row);
  }
  // The mean slope over every study and participant, now that all are counted.
  for (auto row = r.rows.end() - N; row != r.rows.end(); ++row) row->expected_share = count > 0 ? sum / count : nan;
}

// Which of a pair's sources (as designed, swaps undone) showed the larger radius in a condition's trials, in a word.
std::string BlurrierSource(const Tally& t) {
  const int kinds = (t.blurrier_first > 0) + (t.blurrier_second > 0) + (t.blurrier_equal > 0);
  if (kinds > 1) return "varies";
  return t.blurrier_first > 0 ? "first" : t.blurrier_second > 0 ? "second" : t.blurrier_equal > 0 ? "equal" : "";
}

// p-values of the exact test are a function of (k, n, chance): each (n, chance) computed once.
class ExactBinomialP {
 public:
  double operator()(int k, int n, double chance) {
    auto& v = cache_[{n, chance}];
    if (v.empty()) v = BinomialTestPAll(n, chance);
    return v[size_t(k)];
  }

 private:
  std::map<std::pair<int, double>, std::vector<double>> cache_;
};

// A condition's rows of the exact test against chance: per N, the expected shares, the mean Wilson width and the
// power of the report's test.
void AddExactRows(PlanResult& r, const Condition& c, const PlanOptions& options, ExactBinomialP& p_of) {
  const int N = options.participants, S = options.studies;
  // The expected shares over every study and participant.
  Tally all;
  for (const auto& study : r.studies)
    for (const auto& p : study)
      if (const auto it = p.tallies.find(c.key); it != p.tallies.end()) {
        const Tally& t = it->second;
        all.k += t.k, all.n += t.n, all.first += t.first, all.second += t.second, all.cant_tell += t.cant_tell,
            all.none += t.none, all.shown += t.shown, all.blurrier_first += t.blurrier_first,
            all.blurrier_second += t.blurrier_second, all.blurrier_equal += t.blurrier_equal;
      }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double shown = all.shown > 0 ? all.shown : nan;
  std::vector<int> k(static_cast<size_t>(S), 0), n(static_cast<size_t>(S), 0);
  // Per study, the participants' deviations from chance so far (participants with a counting answer), and their
  // sum, sum of squares and smallest size for SignFlipNormalP (O(1) per N past SignFlipP's exact range).
  struct Deviations {
    std::vector<double> d;
    double sum = 0, square = 0, step = INFINITY;
  };
  std::vector<Deviations> dev(static_cast<size_t>(S));
  for (int m = 1; m <= N; ++m) {
    PowerRow row;
    row.test = c.chance >= 0 ? "exact" : "none";
    row.condition = c.label;
    row.measure = c.measure;
    row.chance = c.chance >= 0 ? c.chance : nan;
    row.participants = m;
    row.expected_share = all.n > 0 ? double(all.k) / all.n : nan;
    if (c.measure == "more_blurred" || c.measure == "first_source") {
      row.more_blurred = BlurrierSource(all);
      row.share_first = all.first / shown, row.share_second = all.second / shown;
      row.share_cant_tell = all.cant_tell / shown, row.share_none = all.none / shown;
    } else {
      row.share_first = row.share_second = row.share_cant_tell = nan;
      row.share_none = all.none / shown;
    }
    double width = 0, trials = 0;
    int rejected = 0;
    for (int s = 0; s < S; ++s) {
      if (const auto it = r.studies[size_t(s)][size_t(m - 1)].tallies.find(c.key);
          it != r.studies[size_t(s)][size_t(m - 1)].tallies.end()) {
        k[size_t(s)] += it->second.k, n[size_t(s)] += it->second.n;
        if (it->second.n > 0) {
          Deviations& e = dev[size_t(s)];
          const double d = double(it->second.k) / it->second.n - c.chance;
          if (e.d.size() <= kSignFlipExactUpTo) e.d.push_back(d);
          e.sum += d, e.square += d * d;
          if (std::abs(d) > 1e-12) e.step = std::min(e.step, std::abs(d));
        }
      }
      const auto [lo, hi] = Wilson95(k[size_t(s)], n[size_t(s)]);
      width += hi - lo;
      trials += n[size_t(s)];
      if (c.chance < 0 || n[size_t(s)] == 0) continue;
      // The report's test (analysis/study_tests.py against_chance_counts): one participant - the exact binomial of
      // their answers, none for a single answer (OneParticipantTestP: its NaN is never below alpha); two - none;
      // three or more with a share - at chance 0.5 the exact sign-flip test of their shares around it, else the
      // exact binomial of the answers pooled (every participant guessing).
      if (m == 1) {
        rejected += OneParticipantTestP(k[size_t(s)], n[size_t(s)], c.chance) < options.alpha;
        continue;
      }
      const Deviations& e = dev[size_t(s)];
      if (e.d.size() < 3) continue;
      const double p = std::abs(c.chance - 0.5) >= 1e-12      ? p_of(k[size_t(s)], n[size_t(s)], c.chance)
                       : e.d.size() <= kSignFlipExactUpTo ? SignFlipP(e.d)
                                                          : SignFlipNormalP(e.sum, e.square, e.step);
      rejected += p < options.alpha;
    }
    // No counting answer in any study (every one can't tell, say): no share, and an interval of [0, 1] says nothing.
    row.wilson_width = all.n > 0 ? width / S : nan;
    row.mean_trials = trials / S;
    row.power = c.chance >= 0 ? double(rejected) / S : nan;
    r.rows.push_back(row);
  }
}

// Across participants: each participant's share over all the trials of one measure, against its chance level.
void AddParticipantRows(PlanResult& r, const PlanOptions& options) {
  const int N = options.participants, S = options.studies;
  std::set<std::pair<std::string, double>> measures;
  for (const Condition& c : r.conditions)
    if (c.chance >= 0 && c.measure != "log_cutoff_slope" && r.groups.size() < 2) measures.insert({c.measure, c.chance});
  for (const auto& [measure, chance] : measures) {
    std::vector<std::vector<double>> shares(static_cast<size_t>(S));
    double sum = 0;
    int count = 0;
    for (int s = 0; s < S; ++s)
      for (const auto& p : r.studies[size_t(s)]) {
        int k = 0, n = 0;
        for (const Condition& c : r.conditions)
          if (c.measure == measure && c.chance == chance)
            if (const auto it = p.tallies.find(c.key); it != p.tallies.end()) k += it->second.k, n += it->second.n;
        // A participant with no counting answer (every one can't tell) has no share: left out, as the report's
        // models leave out rows without a decisive answer.
        shares[size_t(s)].push_back(n > 0 ? double(k) / n : std::numeric_limits<double>::quiet_NaN());
        if (n > 0) sum += double(k) / n, ++count;
      }
    for (int m = 1; m <= N; ++m) {
      PowerRow row;
      row.test = "participants_t";
      row.condition = "all";
      row.measure = measure;
      row.chance = chance;
      row.participants = m;
      row.expected_share = count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
      row.share_first = row.share_second = row.share_cant_tell = row.share_none = row.wilson_width =
          std::numeric_limits<double>::quiet_NaN();
      int rejected = 0;
      double used = 0;
      for (int s = 0; s < S; ++s) {
        std::vector<double> values;
        for (int i = 0; i < m; ++i)
          if (std::isfinite(shares[size_t(s)][size_t(i)])) values.push_back(shares[size_t(s)][size_t(i)]);
        used += double(values.size());
        rejected += values.size() >= 2 && OneSampleTTestP(values, chance) < options.alpha;
      }
      row.mean_trials = used / S;  // here: participants with a share
      row.power = double(rejected) / S;
      r.rows.push_back(row);
    }
  }
}

}  // namespace

PlanResult RunPlan(const PlanOptions& options) {
  if (!(options.alpha > 0 && options.alpha < 1)) throw Error(ErrorKind::kUsage, "--alpha must be in (0, 1)");
  PlanResult r;
  (void)procedure::ParseObserver(options.observer);  // a bad --observer before any file is read
  const procedure::PreparedSession study = procedure::PrepareStudy(options.protocol_file, options.display_profile);
  r.study = study.protocol.name;
  r.display = study.display.name;
  if (study.protocol.groups) r.groups = study.protocol.groups->names;
  r.protocol_hash = store::ProtocolHash(store::CanonicalProtocolText(study.protocol_text));
  const auto start = std::chrono::steady_clock::now();
  r.studies = SimulateStudies(options, study, &r.conditions, &r.notes, &r.threads_used);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.observer = procedure::ToString(procedure::ParseObserver(options.observer));
  if (r.conditions.empty())
    throw InputError(options.protocol_file.string(),
                     "nothing to plan: no main trial has a share to test (forced choice, a procedure, odd one out or "
                     "yes/no) or a depth matching over distances");
  ExactBinomialP p_of;
  for (const Condition& c : r.conditions) {
    if (c.measure == "log_cutoff_slope") {
      AddSlopeRows(r, c, options);
      continue;
    }
    if (c.measure == "threshold") continue;  // comparisons.h
    AddExactRows(r, c, options, p_of);
  }
  AddParticipantRows(r, options);
  // Groups are compared, not pooled: each group's own test against chance and the between-group test.
  AddGroupShareRows(r, options);
  AddThresholdRows(r, options);
  for (const PowerRow& row : r.rows) {
    const std::string name = row.test + " " + row.condition + (row.test == "participants_t" ? " " + row.measure : "");
    if (row.test != "none" && row.power >= options.target_power && !r.smallest_n.count(name))
      r.smallest_n[name] = row.participants;
  }
  return r;
}

std::string PlanCsv(const PlanResult& r) {
  std::string out =
      "test,condition,measure,chance,participants,expected_share,share_first,share_second,share_cant_tell,share_none,"
      "mean_trials,wilson_width,power,true_threshold,mean_estimate,bias,sd_estimate,interval_width,difference,determined_share,coverage,"
      "more_blurred_source\n";
  for (const PowerRow& row : r.rows)
    out += row.test + "," + store::CsvField(row.condition) + "," + row.measure + "," + Number(row.chance, "%.6g") + "," +
           std::to_string(row.participants) + "," + Number(row.expected_share) + "," + Number(row.share_first) + "," +
           Number(row.share_second) + "," + Number(row.share_cant_tell) + "," + Number(row.share_none) + "," +
           Number(row.mean_trials, "%.3f") + "," + Number(row.wilson_width) + "," + Number(row.power) + "," +
           Number(row.true_threshold) + "," + Number(row.mean_estimate) + "," + Number(row.bias) + "," +
           Number(row.sd_estimate) + "," + Number(row.interval_width) + "," + Number(row.difference) + "," +
           Number(row.determined_share) + "," + Number(row.coverage) + "," + row.more_blurred + "\n";
  return out;
}

Difference ParseDifference(const std::string& text) {
  Difference d;
  std::string number = text;
  if (!number.empty() && number.back() == '%') d.relative = true, number.pop_back();
  const std::optional<double> value = ParseDecimal(number);
  if (!value || !std::isfinite(*value) || *value == 0)
    throw Error(ErrorKind::kUsage, "--difference: must be a non-zero number in the procedure's units (0.5) or a "
                                   "percentage of the true threshold (20%), got " + Echo(text));
  d.value = d.relative ? *value / 100 : *value;
  return d;
}

std::string AnswersCsv(const PlanResult& r) {
  std::string out = "participant,seed,group,trial_index,choice\n";
  if (r.studies.empty()) return out;
  for (const SimParticipant& p : r.studies.front())
    for (const auto& [index, choice] : p.answers)
      out += p.id + ",s" + std::to_string(p.seed) + "," + store::CsvField(p.group) + "," + std::to_string(index) + "," +
             store::CsvField(procedure::Name(choice)) + "\n";
  return out;
}

std::string Summary(const PlanResult& r, const PlanOptions& o) {
  std::string out;
  char line[1024];
  std::snprintf(line, sizeof line,
                "plan of %s: %d simulated studies of %d participants (seed %llu), observer %s, display %s\n",
                r.study.c_str(), o.studies, o.participants, static_cast<unsigned long long>(o.seed),
                r.observer.c_str(), r.display.c_str());
  out += line;
  bool shares = false;
  for (const PowerRow& row : r.rows) shares = shares || row.measure != "threshold";
  if (shares) {
    std::snprintf(line, sizeof line,
                  "per condition at N = %d: the expected share (more_blurred: the side showing the larger blur radius "
                  "among decisive answers, the report's chose_more_blurred - 'more blurred:' names which source that "
                  "was, as designed; first_source: the thesis's own studies, whose report view tests the design's first "
                  "source; correct; yes), the mean width of its 95 %% Wilson interval, the power of the report's "
                  "exact test against chance (alpha %g; participants as the unit: at chance 0.5 the sign-flip test of "
                  "their shares, which needs 6 of them to reach 0.05; else the binomial of the answers; one "
                  "participant: the binomial of their answers, none for one answer; two: none) and the smallest N "
                  "reaching %g %%\n",
                  o.participants, o.alpha, 100 * o.target_power);
    out += line;
    std::snprintf(line, sizeof line, "  %-28s %-13s %7s %8s %8s %7s  %s\n", "condition", "measure", "share", "width",
                  "power", "N", "answers (first / second / can't tell / none)");
    out += line;
  }
  for (const PowerRow& row : r.rows) {
    if (row.participants != o.participants || row.measure == "threshold") continue;  // ThresholdSummary
    const std::string name = row.test + " " + row.condition + (row.test == "participants_t" ? " " + row.measure : "");
    const auto it = r.smallest_n.find(name);
    const std::string reached = row.test == "none" ? "-" : it != r.smallest_n.end() ? std::to_string(it->second)
                                                                                      : "> " + std::to_string(o.participants);
    std::string shown;
    if (std::isfinite(row.share_first))
      shown = Number(row.share_first, "%.2f") + " / " + Number(row.share_second, "%.2f") + " / " +
              Number(row.share_cant_tell, "%.2f") + " / " + Number(row.share_none, "%.2f") +
              (row.more_blurred.empty() ? "" : "; more blurred: " + row.more_blurred + " source");
    if (row.test == "participants_t" || row.test == "groups_t") {
      const std::string label = row.test == "groups_t"   ? row.condition + ": Welch t"
                                : row.condition == "all" ? std::string("all: t across participants")
                                                         : row.condition + ": t";
      std::snprintf(line, sizeof line, "  %-28s %-13s %7s %8s %8.3f %7s\n", label.c_str(), row.measure.c_str(),
                    std::isfinite(row.expected_share) ? Number(row.expected_share, "%.3f").c_str() : "-", "",
                    row.power, reached.c_str());
    } else {
      // A condition without one counting answer has no share (nor width): "-", never "nan".
      auto shown3 = [](double v) { return std::isfinite(v) ? Number(v, "%.3f") : std::string("-"); };
      std::snprintf(line, sizeof line, "  %-28s %-13s %7s %8s %8s %7s  %s\n", row.condition.c_str(),
                    row.measure.c_str(), shown3(row.expected_share).c_str(), shown3(row.wilson_width).c_str(),
                    std::isfinite(row.power) ? Number(row.power, "%.3f").c_str() : "-", reached.c_str(), shown.c_str());
    }
    out += line;
  }
  if (shares && r.groups.size() < 2)
    out += "all: t across participants = a one-sample t-test of each participant's share against chance, the "
           "stand-in for the report's GLMM (its intercept), whose fit per simulated study would be too slow\n";
  if (shares && r.groups.size() >= 2)
    out += "groups are compared, not pooled: group=NAME: t = each group's participants' shares against chance; "
           "group B - group A: Welch t = Welch's two-sample t-test of the participants' shares between the groups "
           "(share: the difference of the groups' mean shares)\n";
  for (const PowerRow& row : r.rows)
    if (row.test == "slope_t") {
      out += "cut-off ~ distance = depth matching: share is the mean slope b of log(accepted cut-off) on log(distance) "
             "per participant (the report's c = e^a d^b), width its 95 % t interval's across the N participants, power "
             "that of a t-test of the slopes against 0\n";
      break;
    }
  out += ThresholdSummary(r, o);
  for (const std::string& note : r.notes) out += "note: " + note + "\n";
  return out;
}

}  // namespace blurcue::plan
