// Ctrl-C (SIGINT) or a kill (SIGTERM) asked of a long command. While an InterruptScope lives its handlers note the
// signal, and the command ends its work at its next safe point: a live run writes its log whole, a session stops
// between trials (or on a text screen) with every answer already committed, and says so. The handlers in place before
// are restored when the scope ends.
#pragma once

#include <atomic>

namespace blurcue {

// The signal noted (SIGINT or SIGTERM), 0 while none.
std::atomic<int>& InterruptSignal();
inline bool Interrupted() { return InterruptSignal().load() != 0; }
// "SIGINT", "SIGTERM" (what the record and the messages call it).
const char* InterruptName(int signal);
// The shell's exit status for a command ended so: 128 + the signal (130 for Ctrl-C), as had it been killed.
inline int InterruptExitCode(int signal) { return 128 + signal; }

class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  void (*old_int_)(int);
  void (*old_term_)(int);
};

}  // namespace blurcue
