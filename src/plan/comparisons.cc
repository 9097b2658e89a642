#include "plan/comparisons.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>

#include "plan/power.h"
#include "protocol/protocol.h"

namespace blurcue::plan {
namespace {

const double kNan = std::numeric_limits<double>::quiet_NaN();

// A row with nothing but its names filled: every statistic NaN (written as an empty field).
PowerRow Row(const std::string& test, const std::string& condition, const std::string& measure, int m) {
  PowerRow row;
  row.test = test;
  row.condition = condition;
  row.measure = measure;
  row.chance = kNan;
  row.participants = m;
  row.expected_share = row.share_first = row.share_second = row.share_cant_tell = row.share_none = kNan;
  row.mean_trials = row.wilson_width = row.power = kNan;
  return row;
}

struct Moments {
  double mean = kNan, sd = kNan;
  int n = 0;
};

Moments MomentsOf(const std::vector<double>& v) {
  Moments m;
  double sum = 0;
  for (double x : v)
    if (std::isfinite(x)) sum += x, ++m.n;
  if (m.n == 0) return m;
  m.mean = sum / m.n;
  double ss = 0;
  for (double x : v)
    if (std::isfinite(x)) ss += (x - m.mean) * (x - m.mean);
  m.sd = m.n > 1 ? std::sqrt(ss / (m.n - 1)) : kNan;
  return m;
}

// [study][participant] -> the participant's estimate for `key` (NaN: none).
using Grid = std::vector<std::vector<double>>;

Grid EstimatesOf(const PlanResult& r, const ConditionKey& key) {
  Grid g(r.studies.size());
  for (size_t s = 0; s < r.studies.size(); ++s)
    for (const SimParticipant& p : r.studies[s]) {
      const auto it = p.thresholds.find(key);
      g[s].push_back(it != p.thresholds.end() ? it->second : kNan);
    }
  return g;
}

std::vector<double> Flat(const Grid& g) {
  std::vector<double> all;
  for (const auto& study : g) all.insert(all.end(), study.begin(), study.end());
  return all;
}

// The power at each N of a test whose p-value per study comes from `p_of(s, m)` (NaN: no test in that study),
// with `fill` naming the rows; appended to r.rows.
template <typename PValue>
void AddPowerRows(PlanResult& r, const PlanOptions& o, const PowerRow& named, PValue p_of) {
  for (int m = 1; m <= o.participants; ++m) {
    PowerRow row = named;
    row.participants = m;
    // A comparison of thresholds needs 3 participants, as the report's (tracks.py MIN_FOR_INTERVAL): with 2, the
    // paired t of skewed per-track estimates rejected a null difference 10 % of the time at alpha 5 %.
    if (named.measure == "threshold" && m < 3) {
      row.power = kNan;
      r.rows.push_back(row);
      continue;
    }
    int rejected = 0;
    for (int s = 0; s < o.studies; ++s) {
      const double p = p_of(s, m);
      rejected += std::isfinite(p) && p < o.alpha;
    }
    row.power = double(rejected) / o.studies;
    r.rows.push_back(row);
  }
}

std::string Signed(double v) { return (v >= 0 ? "+" : "") + protocol::LevelText(v); }

}  // namespace

std::string DifferenceText(const Difference& d, const std::string& units) {
  return d.relative ? Signed(100 * d.value) + " % of the true threshold" : Signed(d.value) + " " + units;
}

std::vector<std::string> DesignWarnings(const Condition& c, const PowerRow& row) {
  std::vector<std::string> out;
  char text[320];
  if (std::isfinite(row.determined_share) && row.determined_share < kDeterminedEnough) {
    std::snprintf(text, sizeof text,
                  "%s: only %.0f %% of tracks determine their threshold (the report says 'not determined' for the "
                  "rest)%s",
                  c.label.c_str(), 100 * row.determined_share,
                  c.truth_beyond != 0 ? "" : ": more trials per track, or levels nearer the threshold");
    out.push_back(text);
  }
  if (std::isfinite(row.coverage) && row.coverage < kCoveredEnough) {
    std::snprintf(text, sizeof text, "%s: the tracks' 95 %% intervals hold the true threshold in only %.0f %% of them",
                  c.label.c_str(), 100 * row.coverage);
    out.push_back(text);
  }
  if (c.truth_determined && c.truth > 0 && std::isfinite(row.bias) && std::abs(row.bias) > kBiasEnough * c.truth) {
    std::snprintf(text, sizeof text,
                  "%s: the estimates sit %+.0f %% from the true threshold on average (their median %+.0f %%): more "
                  "trials per track narrow each track's posterior and bring both toward the truth",
                  c.label.c_str(), 100 * row.bias / c.truth,
                  std::isfinite(row.median_estimate) ? 100 * (row.median_estimate / c.truth - 1) : kNan);
    out.push_back(text);
  }
  if (!c.truth_determined && c.truth_beyond != 0) {
    const bool above = c.truth_beyond > 0;
    std::snprintf(text, sizeof text, "%s: the observer's threshold lies %s the levels the procedure can show: %s",
                  c.label.c_str(), above ? "above" : "below",
                  above ? "raise its max (QUEST+: its threshold grid and stimuli)"
                        : "lower its min (QUEST+: its threshold grid and stimuli)");
    out.push_back(text);
  }
  return out;
}

namespace {

// The threshold rows of a plan: each procedure cell's precision, and the power of the comparisons the report would
// run between cells (paired), between groups (Welch) and, with --difference, against a second cell like it.
class ThresholdRows {
 public:
  ThresholdRows(PlanResult& r, const PlanOptions& o, std::vector<const Condition*> cells)
      : r_(r), o_(o), cells_(std::move(cells)) {
    for (const Condition* c : cells_) {
      est_[c->key] = EstimatesOf(r_, c->key);
      overall_[c->key] = MomentsOf(Flat(est_[c->key]));
    }
  }
  void Add() {
    for (const Condition* c : cells_) AddPrecision(*c);
    AddPaired();
    const bool compared_groups = AddGroups();
    if (!o_.difference) {
      r_.notes.push_back("the power to detect a difference between thresholds is planned with --difference (e.g. "
                         "--difference 0.5 in the procedure's units, or --difference 20%)");
      return;
    }
    if (!compared_groups) AddSecondCells();
  }

 private:
  double T975(size_t df) {
    while (t975_.size() <= df) t975_.push_back(StudentT975(int(t975_.size())));
    return t975_[df];
  }
  void Note(const std::string& text) {
    if (std::find(r_.notes.begin(), r_.notes.end(), text) == r_.notes.end()) r_.notes.push_back(text);
  }
  void AddPrecision(const Condition& c);
  double Declared(const Condition& c, const Condition& other);
  void AddPaired();
  bool AddGroups();
  void AddSecondCells();

  PlanResult& r_;
  const PlanOptions& o_;
  const std::vector<const Condition*> cells_;
  std::map<ConditionKey, Grid> est_;
  std::map<ConditionKey, Moments> overall_;
  std::set<ConditionKey> paired_;  // cells compared with another of the same participants
  std::vector<double> t975_ = std::vector<double>(1, kNan);
};

// Precision: over the simulated participants, the estimates against the observer's true threshold, and how wide the
// 95 % t interval of their mean is with N of them.
void ThresholdRows::AddPrecision(const Condition& c) {
  const int N = o_.participants, S = o_.studies;
  const Moments& all = overall_[c.key];
  const Grid& g = est_[c.key];
  for (int m = 1; m <= N; ++m) {
    PowerRow row = Row("threshold", c.label, "threshold", m);
    row.true_threshold = c.truth_determined ? c.truth : kNan;
    row.mean_estimate = all.mean;
    row.bias = c.truth_determined ? all.mean - c.truth : kNan;
    row.sd_estimate = all.sd;
    double width = 0, count = 0;
    int widths = 0;
    for (int s = 0; s < S; ++s) {
      std::vector<double> values;
      for (int i = 0; i < m; ++i)
        if (std::isfinite(g[size_t(s)][size_t(i)])) values.push_back(g[size_t(s)][size_t(i)]);
      count += double(values.size());
      const Moments here = MomentsOf(values);
      if (here.n < 2) continue;
      width += 2 * T975(size_t(here.n - 1)) * here.sd / std::sqrt(double(here.n));
      ++widths;
    }
    row.mean_trials = count / S;  // here: participants with an estimate
    row.interval_width = widths > 0 ? width / widths : kNan;
    if (m == N) {
      double tracks = 0, determined = 0, covered = 0;
      for (const auto& study : r_.studies)
        for (const SimParticipant& p : study) {
          const auto it = p.tracks.find(c.key);
          if (it == p.tracks.end()) continue;
          ++tracks;
          if (!it->second.determined) continue;
          ++determined;
          covered += it->second.low <= c.truth && c.truth <= it->second.high;
        }
      row.determined_share = tracks > 0 ? determined / tracks : kNan;
      std::vector<double> values;
      for (const double v : Flat(g))
        if (std::isfinite(v)) values.push_back(v);
      if (!values.empty()) {
        std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
        row.median_estimate = values[values.size() / 2];
      }
      row.coverage = determined > 0 && c.truth_determined ? covered / determined : kNan;
    }
    r_.rows.push_back(row);
  }
}

// The declared difference in the procedure's units for a cell; NaN, with a note saying why, where it means nothing:
// the cell's true threshold is not known (the procedure sits at a bound of its range, or shows nothing near it: its
// estimates barely scatter, so any shift had "power 1.000 at N = 2"), or the second threshold, truth + the
// difference, lies outside what the procedure measures (--difference 1e308, -200%: a negative threshold). `c` is the
// cell the difference is declared from, `other` the one shifted by it (the same cell for a second cell).
double ThresholdRows::Declared(const Condition& c, const Condition& other) {
  if (!o_.difference) return kNan;
  const std::string what = "--difference " + DifferenceText(*o_.difference, c.units) + " is not planned for " + c.label;
  if (!c.truth_determined) {
    Note(what + ": its true threshold is " + c.truth_why);
    return kNan;
  }
  const double delta = o_.difference->relative ? o_.difference->value * c.truth : o_.difference->value;
  const double second = c.truth + delta;
  if (!(second >= other.range_lo && second <= other.range_hi)) {
    Note(what + ": the second threshold (its true " + protocol::LevelText(c.truth) + " " + (delta >= 0 ? "+ " : "- ") +
         protocol::LevelText(std::abs(delta)) + ") would be " + (second < other.range_lo ? "below" : "above") +
         " the tested range (" + protocol::LevelText(other.range_lo) + " to " + protocol::LevelText(other.range_hi) +
         ")");
    return kNan;
  }
  // The declared difference is planned by shifting the estimates as simulated: shifted past the range, they are
  // estimates the procedure can never report (an observer with 90 % lapses drives QUEST+ to its grid's top, 5.95 of
  // 6, sd 0.05: "+0.5 arcmin, power 1.000 at N = 3").
  const double shifted = overall_[c.key].mean + delta;
  if (!(shifted >= other.range_lo && shifted <= other.range_hi)) {
    Note(what + ": its estimates (mean " + protocol::LevelText(overall_[c.key].mean) + ") shifted by it would be " +
         (shifted < other.range_lo ? "below" : "above") + " the tested range (" + protocol::LevelText(other.range_lo) +
         " to " + protocol::LevelText(other.range_hi) + "), which the procedure cannot report");
    return kNan;
  }
  return delta;
}

// Between two cells of the same participants: the paired t-test of per-participant thresholds the report would run.
void ThresholdRows::AddPaired() {
  const int N = o_.participants, S = o_.studies;
  for (size_t a = 0; a < cells_.size(); ++a)
    for (size_t b = a + 1; b < cells_.size(); ++b) {
      const Condition &A = *cells_[a], &B = *cells_[b];
      // Thresholds in different units (a difference in arcmin, a relative one) have no difference to test: their
      // paired t-test subtracted a fraction from arcmin ("-1.035, power 1.000 at N = 4").
      if (A.target != B.target) {
        r_.notes.push_back(B.label + " and " + A.label + " are not compared: their thresholds stand for different "
                           "criteria (" + B.target + "; " + A.target + ")");
        continue;
      }
      if (A.units != B.units) {
        r_.notes.push_back(B.label + " and " + A.label + " are not compared: their thresholds are in different units (" +
                           B.units + ", " + A.units + ")");
        continue;
      }
      const Grid &ga = est_[A.key], &gb = est_[B.key];
      bool both = false;
      for (int s = 0; s < S && !both; ++s)
        for (int i = 0; i < N && !both; ++i)
          both = std::isfinite(ga[size_t(s)][size_t(i)]) && std::isfinite(gb[size_t(s)][size_t(i)]);
      if (!both) continue;
      paired_.insert(A.key), paired_.insert(B.key);
      const std::string name = B.label + " - " + A.label;
      auto differences = [&](int s, int m, double shift_a, double shift_b) {
        std::vector<double> d;
        for (int i = 0; i < m; ++i) {
          const double x = ga[size_t(s)][size_t(i)], y = gb[size_t(s)][size_t(i)];
          if (std::isfinite(x) && std::isfinite(y)) d.push_back((y - shift_b) - (x - shift_a));
        }
        return d;
      };
      PowerRow own = Row("paired_t", name + " (the model's own)", "threshold", 0);
      own.difference = A.truth_determined && B.truth_determined ? B.truth - A.truth : kNan;
      own.mean_estimate = overall_[B.key].mean - overall_[A.key].mean;
      AddPowerRows(r_, o_, own, [&](int s, int m) { return OneSampleTTestP(differences(s, m, 0, 0), 0); });
      if (!o_.difference) continue;
      const double delta = Declared(A, B);
      if (!std::isfinite(delta)) continue;
      // The estimates' scatter as simulated, each cell centred on its own mean estimate, the second shifted by delta.
      PowerRow shifted = Row("paired_t", name + " (declared " + DifferenceText(*o_.difference, A.units) + ")",
                             "threshold", 0);
      shifted.difference = delta;
      const double ma = overall_[A.key].mean, mb = overall_[B.key].mean - delta;
      AddPowerRows(r_, o_, shifted, [&](int s, int m) { return OneSampleTTestP(differences(s, m, ma, mb), 0); });
    }
}

// Groups: the same cell (its levels) in two groups, Welch's t-test of the groups' thresholds. True when some pair of
// groups was compared.
bool ThresholdRows::AddGroups() {
  bool compared_groups = false;
  const std::vector<std::string>& groups = r_.groups;
  for (size_t g1 = 0; g1 < groups.size(); ++g1)
    for (size_t g2 = g1 + 1; g2 < groups.size(); ++g2) {
      std::set<std::vector<protocol::Level>, protocol::LevelsLess> levels;
      for (const Condition* c : cells_) levels.insert(c->key.levels);
      for (const std::vector<protocol::Level>& level : levels) {
        // Per group, the cell of those levels its participants run (its block may be the group's own).
        const Condition *A = nullptr, *B = nullptr;
        for (const auto& study : r_.studies)
          for (const SimParticipant& p : study)
            for (const Condition* c : cells_)
              if (c->key.levels == level && p.thresholds.count(c->key)) {
                if (p.group == groups[g1] && !A) A = c;
                if (p.group == groups[g2] && !B) B = c;
              }
        if (!A || !B || A->units != B->units) continue;
        compared_groups = true;
        const Grid &ga = est_[A->key], &gb = est_[B->key];
        auto values = [&](const Grid& g, const std::string& group, int s, int m, double shift) {
          std::vector<double> v;
          for (int i = 0; i < m; ++i)
            if (r_.studies[size_t(s)][size_t(i)].group == group && std::isfinite(g[size_t(s)][size_t(i)]))
              v.push_back(g[size_t(s)][size_t(i)] - shift);
          return v;
        };
        // A block both groups run is planned per group ("group=a: edge=9"): the comparison names its cell once.
        auto cell = [](const Condition& c, const std::string& group) {
          const std::string prefix = "group=" + group + ": ";
          return c.label.rfind(prefix, 0) == 0 ? c.label.substr(prefix.size()) : c.label;
        };
        const std::string la = cell(*A, groups[g1]), lb = cell(*B, groups[g2]);
        const std::string name = "group " + groups[g2] + " - " + groups[g1] + ": " + (la == lb ? la : lb + " - " + la);
        PowerRow own = Row("groups_t", name + " (the model's own)", "threshold", 0);
        own.difference = A->truth_determined && B->truth_determined ? B->truth - A->truth : kNan;
        own.mean_estimate = overall_[B->key].mean - overall_[A->key].mean;
        AddPowerRows(r_, o_, own, [&](int s, int m) {
          return WelchTTestP(values(gb, groups[g2], s, m, 0), values(ga, groups[g1], s, m, 0));
        });
        if (!o_.difference) continue;
        const double delta = Declared(*A, *B);
        if (!std::isfinite(delta)) continue;
        PowerRow shifted = Row("groups_t", name + " (declared " + DifferenceText(*o_.difference, A->units) + ")",
                               "threshold", 0);
        shifted.difference = delta;
        const double ma = overall_[A->key].mean, mb = overall_[B->key].mean - delta;
        AddPowerRows(r_, o_, shifted, [&](int s, int m) {
          return WelchTTestP(values(gb, groups[g2], s, m, mb), values(ga, groups[g1], s, m, ma));
        });
      }
    }
  return compared_groups;
}

// A cell with no partner: the power of a paired t-test against a second cell like it in the same participants,
// differing by the declared amount. Participant i's second track is participant i's in the next study (every
// simulated participant is the same observer with its own seed, so the two are independent draws).
void ThresholdRows::AddSecondCells() {
  const int S = o_.studies;
  for (const Condition* c : cells_) {
    if (paired_.count(c->key)) continue;
    const double delta = Declared(*c, *c);
    if (!std::isfinite(delta)) continue;
    if (S < 2) {
      r_.notes.push_back("--difference for " + c->label + " needs --studies 2 or more (a second cell's track comes "
                         "from the next study)");
      continue;
    }
    const Grid& g = est_[c->key];
    PowerRow row = Row("second_cell_t", c->label + " vs a second cell " + DifferenceText(*o_.difference, c->units),
                       "threshold", 0);
    row.difference = delta;
    AddPowerRows(r_, o_, row, [&](int s, int m) {
      std::vector<double> d;
      for (int i = 0; i < m; ++i) {
        const double x = g[size_t(s)][size_t(i)], y = g[size_t((s + 1) % S)][size_t(i)];
        if (std::isfinite(x) && std::isfinite(y)) d.push_back(y + delta - x);
      }
      return OneSampleTTestP(d, 0);
    });
  }
}

}  // namespace

void AddThresholdRows(PlanResult& r, const PlanOptions& o) {
  std::vector<const Condition*> cells;
  for (const Condition& c : r.conditions)
    if (c.measure == "threshold") cells.push_back(&c);
  if (cells.empty()) {
    if (o.difference)
      r.notes.push_back("--difference is not planned: it is a difference between thresholds, and no block of this "
                        "protocol has a procedure (staircase or QUEST+)");
    return;
  }
  ThresholdRows(r, o, std::move(cells)).Add();
}

void AddGroupShareRows(PlanResult& r, const PlanOptions& o) {
  if (r.groups.size() < 2) return;
  const int S = o.studies;
  std::set<std::pair<std::string, double>> measures;
  for (const Condition& c : r.conditions)
    if (c.chance >= 0 && c.measure != "log_cutoff_slope" && c.measure != "threshold") measures.insert({c.measure, c.chance});
  for (const auto& [measure, chance] : measures) {
    // Each participant's share over all their trials of this measure (NaN: no counting answer).
    Grid share(static_cast<size_t>(S));
    for (int s = 0; s < S; ++s)
      for (const SimParticipant& p : r.studies[size_t(s)]) {
        int k = 0, n = 0;
        for (const Condition& c : r.conditions)
          if (c.measure == measure && c.chance == chance)
            if (const auto it = p.tallies.find(c.key); it != p.tallies.end()) k += it->second.k, n += it->second.n;
        share[size_t(s)].push_back(n > 0 ? double(k) / n : kNan);
      }
    auto values = [&](const std::string& group, int s, int m) {
      std::vector<double> v;
      for (int i = 0; i < m; ++i)
        if (r.studies[size_t(s)][size_t(i)].group == group && std::isfinite(share[size_t(s)][size_t(i)]))
          v.push_back(share[size_t(s)][size_t(i)]);
      return v;
    };
    auto mean_of = [&](const std::string& group) {
      std::vector<double> all;
      for (int s = 0; s < S; ++s) {
        const auto v = values(group, s, o.participants);
        all.insert(all.end(), v.begin(), v.end());
      }
      return MomentsOf(all).mean;
    };
    // Only the groups whose blocks give this measure: a group that runs none of it had a t-test and a Welch test with
    // no values, printed as "power 0.000".
    std::vector<std::string> groups;
    for (const std::string& group : r.groups) {
      bool any = false;
      for (int s = 0; s < S && !any; ++s) any = !values(group, s, o.participants).empty();
      if (any) groups.push_back(group);
    }
    if (groups.size() < r.groups.size() && !groups.empty()) {
      std::string without;
      for (const std::string& group : r.groups)
        if (std::find(groups.begin(), groups.end(), group) == groups.end()) without += (without.empty() ? "" : ", ") + group;
      r.notes.push_back(measure + " is not compared between groups: group" +
                        (r.groups.size() - groups.size() > 1 ? "s " : " ") + without + " run" +
                        (r.groups.size() - groups.size() > 1 ? "" : "s") + " no block that gives it");
    }
    for (const std::string& group : groups) {
      PowerRow row = Row("participants_t", "group=" + group, measure, 0);
      row.chance = chance;
      row.expected_share = mean_of(group);
      AddPowerRows(r, o, row, [&](int s, int m) {
        const auto v = values(group, s, m);
        return v.size() >= 2 ? OneSampleTTestP(v, chance) : kNan;
      });
    }
    for (size_t g1 = 0; g1 < groups.size(); ++g1)
      for (size_t g2 = g1 + 1; g2 < groups.size(); ++g2) {
        PowerRow row = Row("groups_t", "group " + groups[g2] + " - " + groups[g1], measure, 0);
        row.chance = chance;
        row.expected_share = mean_of(groups[g2]) - mean_of(groups[g1]);
        AddPowerRows(r, o, row, [&](int s, int m) {
          return WelchTTestP(values(groups[g2], s, m), values(groups[g1], s, m));
        });
      }
  }
}

std::string ThresholdSummary(const PlanResult& r, const PlanOptions& o) {
  std::vector<const Condition*> cells;
  for (const Condition& c : r.conditions)
    if (c.measure == "threshold") cells.push_back(&c);
  if (cells.empty()) return "";
  auto number = [](double v, const char* format = "%.3f") {
    if (!std::isfinite(v)) return std::string("-");
    char text[48];
    std::snprintf(text, sizeof text, format, v);
    return std::string(text);
  };
  std::string out;
  char line[1024];
  std::snprintf(line, sizeof line,
                "procedure cells: the threshold each estimates (QUEST+: its posterior median over its grid; a staircase: "
                "the median of its posterior at the staircase's target, as the report takes them), over every simulated "
                "participant, against the simulated observer's true threshold (its psychometric function's point the "
                "procedure aims at: QUEST+'s Weibull threshold, a staircase's convergence point), and the mean width "
                "of the 95 %% t interval of the mean of N = %d participants' estimates; determined: the share of tracks whose "
                "threshold the report would give (the same rule), covered: of those, the share whose own 95 %% "
                "interval holds the true threshold\n",
                o.participants);
  out += line;
  std::snprintf(line, sizeof line, "  %-28s %-18s %8s %8s %8s %8s %9s %10s %8s\n", "cell", "units", "truth", "mean",
                "bias", "sd", "width", "determined", "covered");
  out += line;
  for (const Condition* c : cells)
    for (const PowerRow& row : r.rows)
      if (row.test == "threshold" && row.condition == c->label && row.participants == o.participants) {
        std::snprintf(line, sizeof line, "  %-28s %-18s %8s %8s %8s %8s %9s %10s %8s\n", c->label.c_str(),
                      c->units.c_str(), number(row.true_threshold).c_str(), number(row.mean_estimate).c_str(),
                      number(row.bias, "%+.3f").c_str(), number(row.sd_estimate).c_str(),
                      number(row.interval_width).c_str(), number(100 * row.determined_share, "%.0f %%").c_str(),
                      number(100 * row.coverage, "%.0f %%").c_str());
        out += line;
        if (!c->target.empty()) out += "    threshold at " + c->target + "\n";
        for (const std::string& warning : DesignWarnings(*c, row)) out += "  WARNING: " + warning + "\n";
        if (!c->truth_determined)
          out += "  " + c->label + ": the true threshold is " + c->truth_why + ", so no bias is given\n";
      }
  bool header = false;
  for (const PowerRow& row : r.rows) {
    if (row.measure != "threshold" || row.test == "threshold" || row.participants != o.participants) continue;
    if (!header) {
      std::snprintf(line, sizeof line,
                    "power at N = %d of the t-test the report would run on per-participant thresholds (paired_t: "
                    "paired, between two cells of the same participants; second_cell_t: paired, against a second cell "
                    "like it; groups_t: Welch, between groups), alpha %g, and the smallest N reaching %g %%\n",
                    o.participants, o.alpha, 100 * o.target_power);
      out += line;
      std::snprintf(line, sizeof line, "  %-14s %-62s %10s %8s %7s\n", "test", "comparison", "difference", "power",
                    "N");
      out += line;
      header = true;
    }
    const auto it = r.smallest_n.find(row.test + " " + row.condition);
    const std::string reached =
        it != r.smallest_n.end() ? std::to_string(it->second) : "> " + std::to_string(o.participants);
    std::snprintf(line, sizeof line, "  %-14s %-62s %10s %8.3f %7s\n", row.test.c_str(), row.condition.c_str(),
                  number(row.difference, "%+.3f").c_str(), row.power, reached.c_str());
    out += line;
  }
  if (header)
    out += "difference: the true difference (the model's own: from the observer's true thresholds; '-' where one is "
           "not determined) or the declared one (--difference): the estimates' scatter as simulated, shifted by it\n";
  return out;
}

}  // namespace blurcue::plan
