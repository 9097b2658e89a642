#include "core/interrupt.h"

#include <csignal>

namespace blurcue {
namespace {
void OnSignal(int signal) { InterruptSignal().store(signal); }
}  // namespace

std::atomic<int>& InterruptSignal() {
  static std::atomic<int> signal{0};
  return signal;
}

const char* InterruptName(int signal) { return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : "a signal"; }

InterruptScope::InterruptScope() : old_int_(std::signal(SIGINT, OnSignal)), old_term_(std::signal(SIGTERM, OnSignal)) {
  InterruptSignal().store(0);
}

InterruptScope::~InterruptScope() {
  std::signal(SIGINT, old_int_);
  std::signal(SIGTERM, old_term_);
}

}  // namespace blurcue
