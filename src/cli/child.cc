#include "cli/child.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>

#include "core/error.h"
#include "core/process.h"
#include "core/typed.h"

namespace blurcue::cli {

int RunChild(const std::vector<std::string>& argv, const std::string& cwd) { return RunProcess(argv, nullptr, cwd); }

void RunAnalysis(const std::vector<std::string>& argv, const std::string& what, const std::string& unchanged,
                 const std::vector<std::string>& promised) {
  const int status = RunChild(argv);
  if (WIFSIGNALED(status))
    throw Error(ErrorKind::kInternal,
                what + " was killed by signal " + std::to_string(WTERMSIG(status)) + "; " + unchanged + " is unchanged");
  const int code = WEXITSTATUS(status);
  if (code == 127) throw Error(ErrorKind::kUsage, "--python " + argv[0] + ": not found");
  if (code != 0)
    throw Error(code == 3 ? ErrorKind::kInput : ErrorKind::kInternal,
                what + " stopped (exit " + std::to_string(code) + "; its message is above); " + unchanged +
                    " is unchanged");
  for (const std::string& file : promised)
    if (access(file.c_str(), F_OK) != 0)
      throw Error(ErrorKind::kInternal, what + " ended without writing " + file + "; " + unchanged + " is unchanged");
}

void RequirePython3(const std::string& python, const std::vector<std::string>& modules) {
  // Exit 42 is what only an interpreter that ran the script gives; 43 + i that module i would not import.
  std::string script = "import sys\nif sys.version_info[0] != 3: sys.exit(1)\n";
  for (size_t i = 0; i < modules.size(); ++i)
    script += "try:\n  import " + modules[i] + "\nexcept Exception:\n  sys.exit(" + std::to_string(43 + i) + ")\n";
  script += "sys.exit(42)\n";
  const int status = RunChild({python, "-c", script});
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 42) return;
  const std::string name = "--python " + Echo(python, false) + ": ";
  if (code == 127) throw Error(ErrorKind::kUsage, name + "not found");
  if (code >= 43 && code < 43 + int(modules.size()))
    throw Error(ErrorKind::kUsage, name + "cannot import " + modules[code - 43] + " (the analysis needs " +
                                       [&] {
                                         std::string all;
                                         for (const auto& m : modules) all += (all.empty() ? "" : ", ") + m;
                                         return all;
                                       }() +
                                       "); give the python3 that sees Debian's python3-* packages, e.g. /usr/bin/python3");
  throw Error(ErrorKind::kUsage, name + "not a Python 3 (a script asking for exit 42 ended with " +
                                     (code >= 0 ? "exit " + std::to_string(code)
                                                : "signal " + std::to_string(WTERMSIG(status))) +
                                     "); give the python3 that sees Debian's python3-* packages, e.g. /usr/bin/python3");
}

}  // namespace blurcue::cli
