#include "core/process.h"

#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace blurcue {

int RunProcess(const std::vector<std::string>& argv, ProcessTimes* times, const std::string& cwd) {
  std::vector<char*> args;
  for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const pid_t parent = getpid();
  std::fflush(stdout);
  std::fflush(stderr);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t child = fork();
  if (child < 0) throw Error(ErrorKind::kInternal, "cannot start " + argv[0] + ": " + std::strerror(errno));
  if (child == 0) {
    // Only async-signal-safe calls here. PR_SET_PDEATHSIG sends SIGKILL when the parent dies; a parent that died
    // before the prctl took effect is caught by getppid() no longer being it.
    if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || getppid() != parent) _exit(126);
    if (!cwd.empty() && chdir(cwd.c_str()) != 0) _exit(126);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  while (wait4(child, &status, 0, &usage) < 0) {
    if (errno != EINTR) throw Error(ErrorKind::kInternal, "cannot wait for " + argv[0] + ": " + std::strerror(errno));
  }
  if (times) {
    times->wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    auto ms = [](const timeval& t) { return t.tv_sec * 1e3 + t.tv_usec * 1e-3; };
    times->cpu_ms = ms(usage.ru_utime) + ms(usage.ru_stime);
  }
  return status;
}

}  // namespace blurcue
