#pragma once
// AlarmFeed: one device's (or one bus's) alarm set, joined to where its changes go. The owner
// (a DeviceSession, a CanOpenSession, a BusWorker) feeds it what it decoded, with the steady
// time the alarms wait on and the wall time a change is reported with; every change of state
// becomes one StateSink::on_alarm, at once.
//
// Lifetime: `sink` must outlive the feed (the owner's own sink). Threads: the owner's.

#include <array>
#include <cstdint>
#include <string>

#include "pmu/alarms/alarm_set.hpp"
#include "pmu/session/state_sink.hpp"
#include "pmu/session/request_queue.hpp"

namespace pmu::service {

class AlarmFeed {
 public:
  // Settings the set refuses (the config checks them first, so only a caller that skipped
  // the config) are logged and replaced by the table's defaults: a device is never left
  // without alarms.
  AlarmFeed(std::string bus, alarms::DeviceKind source, std::uint16_t device, const alarms::DeviceSettings& settings,
            StateSink& sink);

  void observe(alarms::Code code, double value, SteadyTime now, WallTime wall);
  void observe_flag(alarms::Code code, bool set, SteadyTime now, WallTime wall);
  void tick(SteadyTime now, WallTime wall);
  // An operator's acknowledgement; reported when it changed the state.
  alarms::AckResult acknowledge(alarms::Code code, SteadyTime now, WallTime wall);

  // The device answers at another address now: every alarm that is not NORMAL is reported
  // again under it, with the time of its last change, so the new key has the whole picture.
  void move_to(std::uint16_t device);

  const alarms::AlarmSet& set() const noexcept { return set_; }

 private:
  void changed(alarms::Code code, WallTime wall);
  void report(const alarms::Alarm& a);

  std::string bus_;
  alarms::DeviceKind source_;
  std::uint16_t device_;
  StateSink& sink_;
  alarms::AlarmSet set_;
  std::array<WallTime, alarms::kCodeCount> since_{};  // wall time of each alarm's last change
};

}  // namespace pmu::service
