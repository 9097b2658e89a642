#pragma once
// Starting the analysis's Python from a command (report, plan).
#include <string>
#include <vector>

namespace blurcue::cli {

// Runs `argv` (argv[0] looked up on PATH) and returns its wait status. The child dies with this process: a kill
// of the command, -9 included, must not leave Python running on to write into a folder nobody will use.
// `cwd` (when not empty) is its working folder.
int RunChild(const std::vector<std::string>& argv, const std::string& cwd = "");

// Runs the analysis script `argv` as RunChild and turns a failure into an Error that names `what` and says that
// `unchanged` (the output folder) is left as it was: killed -> kInternal, exit 127 (no such program) -> kUsage naming
// --python, exit 3 -> kInput, other exits -> kInternal.
// Then, when it exits 0, each of `promised` (files it must have written) must exist: otherwise kInternal naming the
// first missing one.
void RunAnalysis(const std::vector<std::string>& argv, const std::string& what, const std::string& unchanged,
                 const std::vector<std::string>& promised = {});

// Throws Error(kUsage) naming --python unless `python` runs as a Python 3 that can import each of `modules` (the
// analysis's packages), naming the first it cannot. It must exit with the code a one-line script asks for, so
// /bin/true or /bin/false do not pass. Costs one interpreter start; a command calls it before its long work.
void RequirePython3(const std::string& python, const std::vector<std::string>& modules);

}  // namespace blurcue::cli
