#pragma once
// The alarms of one device (or one bus): every row of the table that applies to its kind and
// is enabled in its settings, each an Alarm. The owner (a session, on its bus worker's
// thread) feeds it what it decodes and ticks it; whoever publishes reads the codes that
// changed and the alarms that are not NORMAL. No lock: one thread owns a set.

#include <string>
#include <utility>
#include <vector>

#include "pmu/alarms/alarm.hpp"
#include "pmu/alarms/settings.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::alarms {

class AlarmSet {
 public:
  // The table's rows for `kind` with `settings` applied; the error is resolve()'s.
  static codec::Result<AlarmSet, std::string> make(DeviceKind kind, const DeviceSettings& settings = {});

  DeviceKind kind() const noexcept { return kind_; }

  // Feed one alarm; false (nothing changed) for a code the set does not hold.
  bool observe(Code code, double value, Time now) noexcept;
  bool observe_flag(Code code, bool set, Time now) noexcept;
  // Every alarm's waits; the codes whose state changed, in table order.
  std::vector<Code> tick(Time now);
  AckResult acknowledge(Code code, Time now) noexcept;

  // nullptr for a code the set does not hold (not of this kind, or disabled).
  const Alarm* find(Code code) const noexcept;
  const std::vector<Alarm>& alarms() const noexcept { return alarms_; }
  // The alarms that are not NORMAL, in table order: what a late joiner is shown.
  std::vector<const Alarm*> not_normal() const;

 private:
  AlarmSet(DeviceKind kind, std::vector<Alarm> alarms) noexcept : kind_(kind), alarms_(std::move(alarms)) {}
  Alarm* find_mutable(Code code) noexcept;

  DeviceKind kind_;
  std::vector<Alarm> alarms_;  // table order
};

}  // namespace pmu::alarms
