#pragma once
// HealthTracker: one device's health, from the age of its last frame.
//
// ONLINE while a frame came within stale_periods x period, STALE until offline_periods x
// period, then OFFLINE. A device never heard from is UNKNOWN until offline_periods x period
// have passed since the session started, then OFFLINE. The period is the caller's (it
// follows the device's packet period), passed in with every update.
//
// The report is due for publishing when the state changes, when the caller forces it (the
// bus state changed) and otherwise once a second, so readers see the age grow while a
// device is silent. Counters (frames, decode errors, timeouts, reconnects, bus errors) are
// kept here and travel in the same report.
//
// No clock of its own: time comes in through every call.

#include <chrono>

#include "pmu/config/config.hpp"
#include "pmu/session/device_state.hpp"

namespace pmu::service {

class HealthTracker {
 public:
  HealthTracker(std::chrono::steady_clock::time_point created, const Timeouts& timeouts) noexcept;

  // A frame from the device arrived (decoded or not).
  void on_frame(std::chrono::steady_clock::time_point now) noexcept;
  // The state last computed is OFFLINE: a good frame now is a reconnect.
  bool offline() const noexcept { return report_.state == HealthState::Offline; }
  void on_reconnect() noexcept { ++report_.reconnects; }
  void on_decode_error() noexcept { ++report_.decode_errors; }
  void on_sent() noexcept { ++report_.frames_sent; }
  void on_timeout() noexcept { ++report_.timeouts; }
  // True when the bus state changed (then force the next update).
  bool on_bus_state(transport::BusState state) noexcept;
  void on_bus_counters(const transport::BusCounters& counters) noexcept;

  struct Update {
    bool changed = false;  // the state differs from the last update's
    bool publish = false;  // the report is due for publishing now
  };
  Update update(std::chrono::steady_clock::time_point now, std::chrono::milliseconds period, bool force) noexcept;

  const HealthReport& report() const noexcept { return report_; }

 private:
  double stale_periods_;
  double offline_periods_;
  std::chrono::steady_clock::time_point created_;
  std::optional<std::chrono::steady_clock::time_point> last_rx_;
  std::chrono::steady_clock::time_point next_publish_;
  HealthReport report_;
};

}  // namespace pmu::service
