#pragma once
// Which procedure to choose: simulated 2AFC observers of known psychometric function answer hundreds of seeded runs
// of each procedure - the method of constant stimuli, 1-up/2-down and 1-up/3-down staircases and QUEST+ - and the
// threshold each estimates is compared with the observer's true one after 20, 40, 80 and 160 trials: bias,
// precision (SD) and RMSE against the number of trials (speed: the participant's time), and where each fails -
// observers with lapses, a side bias, a slope unlike QUEST+'s prior, a threshold beyond the stimulus range.
// Pure computation (procedure/adaptive.h), no GL.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace blurcue::bench {

struct ProcedureBenchOptions {
  int runs = 200;  // seeded runs per procedure, condition (each run goes to the largest trial count)
  uint64_t seed = 1;
  std::function<void(const std::string&)> progress;
};

struct ProcedureRow {
  std::string procedure;  // constant_stimuli | staircase_1u2d | staircase_1u3d | quest_plus
  std::string condition;  // nominal | lapses | side_bias | steep_slope | beyond_range
  int trials = 0;
  int runs = 0, failed = 0;      // failed: runs that gave no estimate (a staircase without two reversals)
  double truth = 0;              // the level the procedure aims at, from the observer's true function
  double bias = 0, sd = 0, rmse = 0;  // of the estimate, in level units
  // Monte Carlo standard errors of bias and RMSE over the runs: sd / sqrt(n); the delta method on the mean squared
  // error, sd(squared errors) / sqrt(n) / (2 RMSE). A claim about a row holds only beyond about twice these.
  double bias_se = 0, rmse_se = 0;
  // The verdicts each claim in the report reads (one rule, here): whether the RMSE is within 10 % of the target
  // (rmse + 1.96 rmse_se <= 10 %), beyond it (rmse - 1.96 rmse_se > 10 %), or undecided at this number of runs; and
  // whether the procedure fails (|bias| - 1.96 bias_se > 15 % of the target), holds (|bias| + 1.96 bias_se <= 15 %)
  // or is undecided. A row with failed runs is never within.
  enum class Verdict { kYes, kNo, kUndecided };
  Verdict within = Verdict::kUndecided, fails = Verdict::kUndecided;
  double us_per_trial = 0;       // computation per trial (the procedure's own cost, not the participant's)
};

std::vector<ProcedureRow> RunProcedureBench(const ProcedureBenchOptions& options);
// The last column, quick, says a --quick (smoke) run made the rows: charts say so.
void WriteProcedureCsv(const std::vector<ProcedureRow>& rows, const std::filesystem::path& path,
                     bool quick = false);
const char* ToString(ProcedureRow::Verdict verdict);
// Per condition, the trials each procedure needs for an RMSE within 10 % of its target (bias and spread together)
// and its bias and SD at the most trials.
std::string SummarizeProcedures(const std::vector<ProcedureRow>& rows);

}  // namespace blurcue::bench
