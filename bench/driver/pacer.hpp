#pragma once
// steady_ns(): CLOCK_MONOTONIC in ns (what std::chrono::steady_clock reads), shared by the
// driver and its child processes.
// paced(): calls `write(i)` `count` times at `rate` per second on absolute deadlines (a writer that
// falls behind catches up without sleeping), until `stop` is set. Returns the calls made.

#include <sys/prctl.h>
#include <time.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>

namespace pmu::bench {

inline std::int64_t steady_ns() noexcept {
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}

template <typename Write>
std::uint64_t paced(double rate, std::uint64_t count, const std::atomic<bool>* stop, Write&& write) {
  ::prctl(PR_SET_TIMERSLACK, 1UL);  // the default 50 us slack would blur the pacing
  const auto interval = static_cast<std::int64_t>(1e9 / rate);
  const std::int64_t start = steady_ns() + 1000000;
  std::uint64_t i = 0;
  for (; i < count; ++i) {
    if (stop && stop->load(std::memory_order_relaxed)) break;
    const std::int64_t due = start + static_cast<std::int64_t>(i) * interval;
    if (steady_ns() < due) {
      const timespec ts{static_cast<time_t>(due / 1000000000), static_cast<long>(due % 1000000000)};
      while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
    }
    write(i);
  }
  return i;
}

}  // namespace pmu::bench
