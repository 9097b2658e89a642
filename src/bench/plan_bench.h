#pragma once
// What a plan costs: the time per simulated participant of `blurcue plan` (src/plan/plan.h) with 1 thread and with
// more, measured interleaved in one run, and how it scales with cores (the speed-up and its ratio to the ideal).
// Each round also checks that every thread count gave the same answers. A second protocol (an adaptive one: QUEST+)
// is timed in the same rounds, so its cost is stated beside the first's, measured under the same load.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace blurcue::bench {

struct PlanBenchOptions {
  std::filesystem::path protocol_file;   // the protocol simulated (its calibration must exist)
  std::filesystem::path adaptive_file;   // timed beside it in every round (empty: none)
  std::string observer = "sim";
  int participants = 20, studies = 10;   // per timed run
  int rounds = 3;                        // runs per thread count, interleaved
  std::vector<int> threads = {1, 2};
  uint64_t seed = 1;
  std::function<void(const std::string&)> progress;
};

struct PlanBenchRow {
  std::string protocol;                          // the protocol's name
  int threads = 0, round = 0, participants = 0;  // participants: simulated in the run
  double seconds = 0, ms_per_participant = 0;
  double cpu_seconds = 0;  // the process's CPU time in the run: cpu_seconds / seconds is the cores it really got
};

std::vector<PlanBenchRow> RunPlanBench(const PlanBenchOptions& options);
void WritePlanBenchCsv(const std::vector<PlanBenchRow>& rows, const std::filesystem::path& path);
// Per protocol and thread count the median time per participant, and each count's speed-up over 1 thread with its
// share of the ideal (speed-up / threads); the second protocol's time per participant as a ratio of the first's.
std::string SummarizePlanBench(const std::vector<PlanBenchRow>& rows);

}  // namespace blurcue::bench
