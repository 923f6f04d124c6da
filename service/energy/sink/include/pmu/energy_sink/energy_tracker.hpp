#pragma once
// EnergyTracker: a StateSink in front of another (the publishers) that passes every event on
// and derives energy figures from what the sessions report, with the samples' receive times:
// each PMU's voltages and currents feed a PmuEnergy (pmu/energy/pmu_energy.hpp), each
// battery's pmu/battery values a BmsEnergy (pmu/energy/bms_energy.hpp). When a device's
// figures are due (at most once a second of receive time) it hands them on with on_energy or
// on_bms_energy. It reads no clock: time is the samples'.
//
// Limits come from the config, as the device's alarms run with them: a PMU's critical voltages
// are its battery_a/b_critical_voltage alarms' limits as its `alarms:` sets them (its bus's
// `discover:` settings for a discovered PMU), a battery's critical state of charge its
// bms_critical_soc alarm's limit, and its capacity its `capacity_ah` (none for a battery heard
// through listen_canopen but not listed). So the endurance runs to what raises the alarm.
//
// Lifetime: `next` must outlive the tracker, which keeps a reference to it (main.cpp makes the
// publishers first, and the bus workers, which write through the tracker, are destroyed
// before it). `buses` is copied.
// Threads: every StateSink member from any bus worker thread at once; `mutex_` serialises
// the devices' state and the figures, which are handed on under it so they reach `next` in order.

#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "pmu/config/config.hpp"
#include "pmu/energy/bms_energy.hpp"
#include "pmu/energy/pmu_energy.hpp"
#include "pmu/session/state_sink.hpp"

namespace pmu::service {

class EnergyTracker final : public ForwardingSink {
 public:
  // `stale_periods`: the config's timeouts.stale_periods; a device's period times this is the
  // longest gap integrated (the time after which its health reads STALE).
  EnergyTracker(const std::vector<BusConfig>& buses, double stale_periods, StateSink& next);

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override;
  void on_gone(const DeviceKey& key) override;
  void on_battery(const DeviceKey& key, const BatteryState& battery,
                  std::chrono::system_clock::time_point newest) override;
  // The rest pass on unchanged (ForwardingSink): figures come from this tracker, and ones
  // handed to it go on as they are.

 private:
  using Key = std::tuple<std::string, std::uint16_t>;      // (bus, PMU address or battery node)
  energy::PmuEnergy& energy_of(const DeviceKey& key);      // with mutex_ held
  energy::BmsEnergy& bms_energy_of(const DeviceKey& key);  // with mutex_ held
  std::chrono::nanoseconds max_gap(std::chrono::milliseconds period) const;

  std::map<std::string, BusConfig> buses_;  // by bus name
  double stale_periods_;
  std::mutex mutex_;
  std::map<Key, energy::PmuEnergy> pmus_;
  std::map<Key, energy::BmsEnergy> batteries_;
};

}  // namespace pmu::service
