#pragma once
// LowRateGate: which telemetry samples also go to the low-rate topics (pmu/low_rate/*,
// docs/interface.md 1.5), at most one per device and packet per period.
//
// A ground station on a slow radio link reads those topics instead of the full-rate ones:
// its readers match only the low-rate writers, so the full-rate samples never cross the
// link (Fast DDS 2.9 has no TIME_BASED_FILTER that would do this at the writer). Samples are
// chosen on a schedule (due, due + period, ...), not "period after the last one", so a PMU
// streaming every 0.1 s with jitter gives one sample per period on average, not one per
// period plus a frame.

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <utility>

namespace pmu::service {

class LowRateGate {
 public:
  using TimePoint = std::chrono::system_clock::time_point;
  static constexpr std::size_t kPackets = 5;  // the streamed packets 0x00..0x04

  // `period` 0: the gate is closed (no low-rate topics).
  explicit LowRateGate(std::chrono::milliseconds period) : period_(period) {}

  bool enabled() const noexcept { return period_.count() > 0; }

  // True when the sample of `packet` (0..4) from device (bus, address), received at
  // `received`, is the one the low-rate topic gets for its period. Not thread-safe.
  bool due(const std::string& bus, std::uint16_t address, std::size_t packet, TimePoint received);

 private:
  std::chrono::milliseconds period_;
  // Per device and packet: when the next low-rate sample is due (epoch: never sent yet).
  std::map<std::pair<std::string, std::uint16_t>, std::array<TimePoint, kPackets>> next_;
};

}  // namespace pmu::service
