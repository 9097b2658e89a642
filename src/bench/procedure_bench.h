#pragma once
// Which procedure to choose: simulated 2AFC observers of known psychometric function answer hundreds of seeded runs
// of each procedure - the method of constant stimuli, 1-up/2-down and 1-up/3-down staircases and QUEST+ - and the
// threshold each estimates is compared with the observer's true one after 20, 40, 80 and 160 trials: bias,
// precision (SD) and RMSE against the number of trials (speed: the participant's time), and where each fails -
// observers with lapses, a side bias, a slope unlike QUEST+'s prior, a threshold beyond the stimulus range.
// Pure computation (session/adaptive.h), no GL.
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
  double us_per_trial = 0;       // computation per trial (the procedure's own cost, not the participant's)
};

std::vector<ProcedureRow> RunProcedureBench(const ProcedureBenchOptions& options);
// The last column, quick, says a --quick (smoke) run made the rows: charts say so.
void WriteProcedureCsv(const std::vector<ProcedureRow>& rows, const std::filesystem::path& path,
                     bool quick = false);
// Per condition, the trials each procedure needs for an RMSE within 10 % of its target (bias and spread together)
// and its bias and SD at the most trials.
std::string SummarizeProcedures(const std::vector<ProcedureRow>& rows);

}  // namespace blurcue::bench
