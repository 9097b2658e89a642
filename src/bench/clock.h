#pragma once
// The benches' one clock: steady_clock, and the milliseconds since a start. Internal to the bench module.
#include <chrono>

namespace blurcue::bench::detail {

using Clock = std::chrono::steady_clock;

inline double Ms(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

}  // namespace blurcue::bench::detail
