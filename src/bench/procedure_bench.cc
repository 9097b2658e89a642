#include "bench/procedure_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>

#include "core/atomic_file.h"
#include "protocol/protocol.h"
#include "plan/threshold.h"
#include "procedure/threshold_fit.h"
#include "procedure/adaptive.h"

namespace blurcue::bench {
namespace {

constexpr int kCheckpoints[] = {20, 40, 80, 160};
constexpr double kGuess = 0.5;          // 2AFC
constexpr double kLowest = 0.125, kHighest = 3.0;  // the stimulus range every procedure is given

// The simulated observer: a Weibull of threshold t, slope b and lapse l, and a share `side_bias` of answers that
// say left whatever is shown (correct when the test side is left).
struct Observer {
  double t = 1, b = 3, lapse = 0, side_bias = 0;
  double Sensory(double x) const { return 1 - (1 - kGuess) * std::exp(-std::pow(std::max(x, 0.0) / t, b)); }
  bool Answer(double x, std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> u(0, 1);
    const bool test_left = u(rng) < 0.5;
    if (u(rng) < side_bias) return test_left;
    if (u(rng) < lapse) return u(rng) < 0.5;
    return u(rng) < Sensory(x);
  }
  // The level where the sensory function (no lapses, no bias) reaches p.
  double LevelAt(double p) const { return t * std::pow(-std::log((1 - p) / (1 - kGuess)), 1 / b); }
};

struct Condition {
  const char* name;
  Observer observer;
};

const Condition kConditions[] = {
    {"nominal", {1.0, 3.0, 0.0, 0.0}},
    {"lapses", {1.0, 3.0, 0.05, 0.0}},
    {"side_bias", {1.0, 3.0, 0.0, 0.25}},
    {"steep_slope", {1.0, 8.0, 0.0, 0.0}},   // QUEST+'s prior covers slopes 1.5-5
    {"beyond_range", {4.0, 3.0, 0.0, 0.0}},  // the threshold lies above the highest level any procedure shows
};

protocol::Procedure Staircase(int down) {
  protocol::Procedure p;
  p.kind = protocol::Procedure::Kind::kStaircase;
  p.start = 2.0, p.min = 0.02, p.max = kHighest;
  p.up = 1, p.down = down;
  p.steps = {0.4, 0.2, 0.1, 0.05};
  return p;
}

protocol::Procedure Quest() {
  protocol::Procedure p;
  p.kind = protocol::Procedure::Kind::kQuestPlus;
  for (int i = 0; i < 24; ++i) p.stimuli.push_back(kLowest + (kHighest - kLowest) * i / 23);
  for (int i = 0; i < 20; ++i) p.thresholds.push_back(0.15 + (kHighest - 0.15) * i / 19);
  p.slopes = {1.5, 2.5, 3.5, 5};
  p.lapses = {0, 0.02, 0.05};
  p.guess = kGuess;
  return p;
}

// Constant stimuli: 8 levels log-spaced over the range, shown in turn; the threshold of the Weibull fitted by
// maximum likelihood (a grid over threshold and slope, lapse 0.02) to the first n answers.
std::vector<double> ConstantLevels() {
  std::vector<double> levels;
  for (int i = 0; i < 8; ++i) levels.push_back(kLowest * std::pow(kHighest / kLowest, i / 7.0));
  return levels;
}

double FitThreshold(const std::vector<double>& levels, const std::vector<int>& correct, const std::vector<int>& shown) {
  double best_t = 0, best_ll = -1e300;
  for (int i = 0; i < 200; ++i) {
    const double t = 0.05 * std::pow(6 / 0.05, i / 199.0);
    for (double b : {1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0}) {
      double ll = 0;
      for (size_t k = 0; k < levels.size(); ++k) {
        const double p = 1 - 0.02 - (1 - kGuess - 0.02) * std::exp(-std::pow(levels[k] / t, b));
        ll += correct[k] * std::log(p) + (shown[k] - correct[k]) * std::log(1 - p);
      }
      if (ll > best_ll) best_ll = ll, best_t = t;
    }
  }
  return best_t;
}

struct Tally {
  std::vector<double> estimates;
  int failed = 0;
};

constexpr double kPrecision = 0.10;  // the stated precision: RMSE within 10 % of the target
constexpr double kFailBias = 0.15;   // a procedure fails where its bias exceeds 15 % of the target
constexpr double kZ95 = 1.959964;

ProcedureRow::Verdict Compare(double value, double se, double limit) {
  if (value + kZ95 * se <= limit) return ProcedureRow::Verdict::kYes;
  if (value - kZ95 * se > limit) return ProcedureRow::Verdict::kNo;
  return ProcedureRow::Verdict::kUndecided;
}

// Bias, SD and RMSE of the estimates against the truth, with their Monte Carlo standard errors, and the verdicts.
void Summarize(const std::vector<double>& estimates, double truth, ProcedureRow* row) {
  const double n = double(estimates.size());
  double mean = 0, mse = 0;
  for (double e : estimates) mean += e, mse += (e - truth) * (e - truth);
  mean /= n, mse /= n;
  double var = 0, var_sq = 0;
  for (double e : estimates) {
    var += (e - mean) * (e - mean);
    const double sq = (e - truth) * (e - truth);
    var_sq += (sq - mse) * (sq - mse);
  }
  const double denominator = std::max(1.0, n - 1);
  row->bias = mean - truth;
  row->sd = std::sqrt(var / denominator);
  row->rmse = std::sqrt(mse);
  row->bias_se = row->sd / std::sqrt(n);
  row->rmse_se = row->rmse > 0 ? std::sqrt(var_sq / denominator / n) / (2 * row->rmse) : 0;
  row->within = row->failed > 0 ? ProcedureRow::Verdict::kNo : Compare(row->rmse, row->rmse_se, kPrecision * truth);
  // Compare says whether |bias| stays within the line; failing is the other way round.
  switch (Compare(std::abs(row->bias), row->bias_se, kFailBias * truth)) {
    case ProcedureRow::Verdict::kYes: row->fails = ProcedureRow::Verdict::kNo; break;
    case ProcedureRow::Verdict::kNo: row->fails = ProcedureRow::Verdict::kYes; break;
    case ProcedureRow::Verdict::kUndecided: row->fails = ProcedureRow::Verdict::kUndecided; break;
  }
}

}  // namespace

const char* ToString(ProcedureRow::Verdict verdict) {
  switch (verdict) {
    case ProcedureRow::Verdict::kYes: return "yes";
    case ProcedureRow::Verdict::kNo: return "no";
    case ProcedureRow::Verdict::kUndecided: return "undecided";
  }
  return "undecided";
}

std::vector<ProcedureRow> RunProcedureBench(const ProcedureBenchOptions& options) {
  const char* kProcedures[] = {"constant_stimuli", "staircase_1u2d", "staircase_1u3d", "quest_plus"};
  const int most = kCheckpoints[3];
  std::vector<ProcedureRow> rows;
  for (const Condition& condition : kConditions) {
    const Observer& o = condition.observer;
    for (const char* name : kProcedures) {
      const std::string procedure = name;
      std::map<int, Tally> tallies;
      const auto start = std::chrono::steady_clock::now();
      for (int run = 0; run < options.runs; ++run) {
        std::mt19937_64 rng(options.seed * 1000003 + uint64_t(run));
        if (procedure == "constant_stimuli") {
          const std::vector<double> levels = ConstantLevels();
          std::vector<int> correct(levels.size(), 0), shown(levels.size(), 0);
          for (int trial = 1; trial <= most; ++trial) {
            const size_t k = size_t(trial - 1) % levels.size();
            ++shown[k];
            correct[k] += o.Answer(levels[k], rng);
            if (std::find(std::begin(kCheckpoints), std::end(kCheckpoints), trial) != std::end(kCheckpoints))
              tallies[trial].estimates.push_back(FitThreshold(levels, correct, shown));
          }
        } else if (procedure == "quest_plus") {
          procedure::QuestPlus q(Quest());
          for (int trial = 1; trial <= most; ++trial) {
            const double x = q.Next();
            q.Update(x, o.Answer(x, rng));
            if (std::find(std::begin(kCheckpoints), std::end(kCheckpoints), trial) != std::end(kCheckpoints))
              tallies[trial].estimates.push_back(q.MeanThreshold());
          }
        } else {
          const protocol::Procedure spec = Staircase(procedure == "staircase_1u2d" ? 2 : 3);
          procedure::Staircase s(spec);
          std::vector<double> levels;
          std::vector<bool> answers;
          for (int trial = 1; trial <= most; ++trial) {
            const double level = s.Level();
            const bool ok = o.Answer(level, rng);
            s.Update(ok);
            levels.push_back(level), answers.push_back(ok);
            if (std::find(std::begin(kCheckpoints), std::end(kCheckpoints), trial) == std::end(kCheckpoints)) continue;
            // The report's estimate (procedure/threshold_fit.h): the posterior median at the staircase's target.
            const procedure::TrackThreshold t = procedure::StaircasePosterior(
                {spec.guess, plan::TargetShare(spec, 0), spec.min, spec.max}, levels, answers);
            if (!t.determined) {
              ++tallies[trial].failed;
              continue;
            }
            tallies[trial].estimates.push_back(t.estimate);
          }
        }
      }
      const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() /
                        (double(options.runs) * most);
      // What each aims at: the Weibull threshold (QUEST+, constant stimuli), a staircase's convergence point.
      const double truth = procedure == "staircase_1u2d"   ? o.LevelAt(std::sqrt(0.5))
                           : procedure == "staircase_1u3d" ? o.LevelAt(std::pow(0.5, 1 / 3.0))
                                                           : o.t;
      for (int n : kCheckpoints) {
        const Tally& tally = tallies[n];
        ProcedureRow row;
        row.procedure = procedure;
        row.condition = condition.name;
        row.trials = n;
        row.runs = options.runs;
        row.failed = tally.failed;
        row.truth = truth;
        row.us_per_trial = us;
        if (!tally.estimates.empty())
          Summarize(tally.estimates, truth, &row);
        else
          row.within = ProcedureRow::Verdict::kNo;  // no estimate at all
        rows.push_back(row);
      }
      if (options.progress) {
        char line[160];
        std::snprintf(line, sizeof line, "%-12s %-16s 160 trials: bias %+.3f sd %.3f (target %.3f), %.1f us/trial",
                      condition.name, name, rows.back().bias, rows.back().sd, truth, us);
        options.progress(line);
      }
    }
  }
  return rows;
}

void WriteProcedureCsv(const std::vector<ProcedureRow>& rows, const std::filesystem::path& path, bool quick) {
  std::ostringstream out;
  out << "procedure,condition,trials,runs,failed,truth,bias,bias_se,sd,rmse,rmse_se,within_target,fails,us_per_trial,"
         "quick\n";
  for (const auto& r : rows) {
    char line[320];
    std::snprintf(line, sizeof line, "%s,%s,%d,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%s,%s,%.4g,%d\n",
                  r.procedure.c_str(), r.condition.c_str(), r.trials, r.runs, r.failed, r.truth, r.bias, r.bias_se,
                  r.sd, r.rmse, r.rmse_se, ToString(r.within), ToString(r.fails), r.us_per_trial, int(quick));
    out << line;
  }
  WriteFileAtomically(path, out.str());
}

std::string SummarizeProcedures(const std::vector<ProcedureRow>& rows) {
  std::ostringstream out;
  for (const Condition& c : kConditions) {
    out << c.name << ":\n";
    for (const char* name : {"constant_stimuli", "staircase_1u2d", "staircase_1u3d", "quest_plus"}) {
      int needed = -1;
      const ProcedureRow* last = nullptr;
      for (const auto& r : rows)
        if (r.condition == c.name && r.procedure == name) {
          if (needed < 0 && r.within == ProcedureRow::Verdict::kYes) needed = r.trials;
          last = &r;
        }
      if (!last) continue;
      const char* verdict = last->fails == ProcedureRow::Verdict::kYes         ? "  <- fails here (bias > 15 %)"
                            : last->fails == ProcedureRow::Verdict::kUndecided ? "  (bias near 15 %: undecided)"
                                                                                : "";
      char line[240];
      std::snprintf(line, sizeof line,
                    "  %-17s RMSE clearly within 10 %% of its target by %s trials; at 160: bias %+5.1f %% "
                    "(MC se %.1f %%), sd %4.1f %%%s\n",
                    name, needed < 0 ? "> 160" : std::to_string(needed).c_str(), 100 * last->bias / last->truth,
                    100 * last->bias_se / last->truth, 100 * last->sd / last->truth, verdict);
      out << line;
    }
  }
  return out.str();
}

}  // namespace blurcue::bench
