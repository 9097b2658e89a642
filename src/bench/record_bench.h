#pragma once
// What each answer's durability costs: the same session (trials with a second of display flips each) recorded into
// a real SQLite file with synchronous=FULL (survives a power loss) and with NORMAL (survives a killed process),
// interleaved in one run on this machine's disk.
#include <filesystem>
#include <functional>
#include <string>

namespace blurcue::bench {

struct RecordBenchOptions {
  std::filesystem::path folder;  // where the record files are written (the disk being measured)
  int trials = 200;
  int frames_per_trial = 60;     // one second at 60 Hz
  std::function<void(const std::string&)> progress;
};

struct RecordBenchResult {
  double full_median_ms = 0, full_p99_ms = 0;      // per answer (RecordResponse: answer + frames, one commit)
  double normal_median_ms = 0, normal_p99_ms = 0;
};

RecordBenchResult RunRecordBench(const RecordBenchOptions& options);

}  // namespace blurcue::bench
