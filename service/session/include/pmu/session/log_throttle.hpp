#pragma once
// LogThrottle: lets one report of a repeating fault through per interval and counts the ones
// held back, so a fault that repeats thousands of times a second is still reported, with how
// often, without flooding the journal. (The logger's duplicate filter only collapses
// identical lines; these lines carry running counts.) Not thread-safe: callers hold a lock.

#include <chrono>
#include <cstdint>
#include <optional>

namespace pmu::service {

class LogThrottle {
 public:
  using Clock = std::chrono::steady_clock;
  explicit LogThrottle(Clock::duration interval) : interval_(interval) {}

  // When this event may be reported: how many were held back since the last report.
  // Otherwise nullopt (the event is counted).
  std::optional<std::uint64_t> allow(Clock::time_point now) {
    if (last_ && now - *last_ < interval_) {
      ++held_back_;
      return std::nullopt;
    }
    last_ = now;
    const auto held = held_back_;
    held_back_ = 0;
    return held;
  }

 private:
  Clock::duration interval_;
  std::optional<Clock::time_point> last_;
  std::uint64_t held_back_ = 0;
};

}  // namespace pmu::service
