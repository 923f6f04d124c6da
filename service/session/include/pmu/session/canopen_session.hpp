#pragma once
// CanOpenSession: the service's view of one battery (MG BMS) or MPPT on a bus. These devices
// are read, never commanded: each frame carries one value (canopen_state.hpp), and the
// session assembles them into the device's state and publishes it.
//
// Publishing: at the end of a bus-loop turn (tick) a state that frames updated since its last
// sample is published, at most once per `publish_period` (config canopen_publish_period), so
// a burst of frames gives one sample, and a sample carries every value received so far. The
// sample's time is the receive time of the newest frame in it. Battery values and cell
// voltages are separate topics with separate schedules.
//
// Health: like a PMU's (HealthTracker), from the age of the newest frame against the
// configured period (seconds between a device's frames of one value). A frame after OFFLINE
// is a reconnect: every value is forgotten (NaN again) before the frame's own is stored, so a
// sample never mixes a replaced or restarted unit's values with the old one's.
//
// Alarms (interface.md 1.6): the session owns the device's AlarmSet (kind Battery or Mppt),
// built from its config settings, fed from the assembled values after every frame and from
// its health at every tick; every change goes to StateSink::on_alarm (canopen_session.cpp
// says what feeds which code).
//
// No I/O and no clock of its own: time comes in with every call.
//
// Lifetime: `sink` must outlive the session, which keeps a reference (the DdsPublisher in the
// daemon: main.cpp makes it before the bus workers that own the sessions, and destroys it
// after them).
// Threads: no lock: every member on the thread of the bus worker that owns it.

#include <chrono>
#include <optional>
#include <string>

#include "pmu/codec/can_frame.hpp"
#include "pmu/config/config.hpp"
#include "pmu/session/alarm_feed.hpp"
#include "pmu/session/canopen_state.hpp"
#include "pmu/session/state_sink.hpp"
#include "pmu/session/health_tracker.hpp"
#include "pmu/session/request_queue.hpp"

namespace pmu::service {

// The device a battery or MPPT frame comes from (battery: node = COB-ID & 0x7F; MPPT: device
// 0..7 from its block of ids), or nullopt for a frame that is not one of theirs.
std::optional<DeviceKey> canopen_device(const std::string& bus, const codec::CanFrame& frame) noexcept;

class CanOpenSession {
 public:
  // `key.kind` is Battery or Mppt; `alarms` the device's alarm settings (its config entry's).
  CanOpenSession(DeviceKey key, std::chrono::milliseconds period, std::chrono::milliseconds publish_period,
                 const Timeouts& timeouts, StateSink& sink, SteadyTime now, const alarms::DeviceSettings& alarms = {});

  const DeviceKey& key() const noexcept { return key_; }
  // A frame whose id canopen_device() gave this session's key.
  void on_frame(const codec::CanFrame& frame, SteadyTime now, WallTime received);
  void on_bus_state(transport::BusState state, SteadyTime now);
  void on_bus_counters(const transport::BusCounters& counters) noexcept { health_.on_bus_counters(counters); }
  // Publishes what is due, keeps health current and runs the alarms' delays. Call at the end
  // of every bus-loop turn; `wall` is the wall time of `now`.
  void tick(SteadyTime now, WallTime wall);

  const HealthReport& health() const noexcept { return health_.report(); }
  const BatteryState& battery() const noexcept { return battery_; }
  const BatteryCellsState& cells() const noexcept { return cells_; }
  const MpptState& mppt() const noexcept { return mppt_; }
  const alarms::AlarmSet& alarms() const noexcept { return alarms_.set(); }
  // As DeviceSession::acknowledge_alarm.
  alarms::AckResult acknowledge_alarm(alarms::Code code, SteadyTime now, WallTime wall) {
    return alarms_.acknowledge(code, now, wall);
  }

 private:
  // One published topic's schedule.
  struct Schedule {
    bool dirty = false;         // values arrived since the last sample
    WallTime newest{};          // receive time of the newest frame in the state
    SteadyTime next_allowed{};  // rate limit
  };
  bool due(Schedule& s, SteadyTime now) const noexcept;
  void forget(SteadyTime now);
  void update_health(SteadyTime now, bool force);
  void feed_alarms(SteadyTime now, WallTime wall);

  DeviceKey key_;
  std::chrono::milliseconds period_;
  std::chrono::milliseconds publish_period_;
  StateSink& sink_;
  HealthTracker health_;
  AlarmFeed alarms_;

  BatteryState battery_;
  BatteryCellsState cells_;
  MpptState mppt_;
  Schedule values_;  // pmu/battery or pmu/mppt
  Schedule cell_schedule_;
};

}  // namespace pmu::service
