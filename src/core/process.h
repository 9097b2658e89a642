#pragma once
// Starting another program and waiting for it (the analysis's Python, a benchmark's command).
#include <string>
#include <vector>

namespace blurcue {

// How long a finished child took: wall time from its start to its end, and its own CPU time (user + system, the
// kernel's account of the reaped child).
struct ProcessTimes {
  double wall_ms = 0, cpu_ms = 0;
};

// Runs `argv` (argv[0] looked up on PATH unless it holds a '/') and returns its wait status; `times` (optional) gets
// its wall and CPU time. The child dies with this process: a kill of the caller, -9 included, must not leave it
// running on to write into a folder nobody will use. Throws Error(kInternal) when it cannot be started or waited for.
// `cwd` (when not empty) is the child's working folder; a child that cannot enter it exits 126.
int RunProcess(const std::vector<std::string>& argv, ProcessTimes* times = nullptr, const std::string& cwd = "");

}  // namespace blurcue
