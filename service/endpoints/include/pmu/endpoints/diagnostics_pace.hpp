#pragma once
// When Ros2Publisher writes /diagnostics (docs/interface.md 11.3). Every array holds every
// device's status, and every device reports its health each second: an array per report
// would carry N arrays of N statuses a second, the square of the device count, which a radio
// link to a ROS 2 reader pays. So an array is written at once when what a reader sees of a
// device changes (its level or message, a device added or gone), and otherwise at most once a
// period: the counters and other values ride on that one.
// Pure: the times come in (the publisher's injected clock), nothing is read or slept. Not
// thread-safe: the caller holds its lock.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

namespace pmu::service {

// What a reader sees change in a device's DiagnosticStatus.
struct ShownStatus {
  std::uint8_t level = 0;
  std::string message;
};
bool operator==(const ShownStatus& a, const ShownStatus& b) noexcept;
bool operator!=(const ShownStatus& a, const ShownStatus& b) noexcept;

class DiagnosticsPace {
 public:
  using TimePoint = std::chrono::steady_clock::time_point;
  explicit DiagnosticsPace(std::chrono::steady_clock::duration period = std::chrono::seconds(1)) noexcept
      : period_(period) {}

  // A device's health report at `now`: `before` is its status in the arrays so far (nullopt:
  // a device not in them), `after` the one it reports. Whether the array is written now.
  bool on_report(const std::optional<ShownStatus>& before, const ShownStatus& after, TimePoint now) noexcept;
  // A device left the array: written at once.
  bool on_gone(TimePoint now) noexcept;

 private:
  bool at_once(TimePoint now) noexcept;

  std::chrono::steady_clock::duration period_;
  // When the next unchanged report may write. It moves on by whole periods while reports keep
  // coming, so reports a little less than a period apart do not skip a period.
  std::optional<TimePoint> due_;
};

}  // namespace pmu::service
