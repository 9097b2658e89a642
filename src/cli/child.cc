#include "cli/child.h"

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace blurcue::cli {

int RunChild(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const pid_t parent = getpid();
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child < 0) throw Error(ErrorKind::kInternal, "cannot start " + argv[0] + ": " + std::strerror(errno));
  if (child == 0) {
    // Only async-signal-safe calls here. PR_SET_PDEATHSIG sends SIGKILL when the parent dies; a parent that died
    // before the prctl took effect is caught by getppid() no longer being it.
    if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent) _exit(126);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) throw Error(ErrorKind::kInternal, "cannot wait for " + argv[0] + ": " + std::strerror(errno));
  }
  return status;
}

void RunAnalysis(const std::vector<std::string>& argv, const std::string& what, const std::string& unchanged) {
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
}

}  // namespace blurcue::cli
