#include "pmu/energy_sink/energy_tracker.hpp"

#include <algorithm>
#include <string_view>
#include <variant>

namespace pmu::service {
namespace {

// The limit the device's alarm runs with: its override over the table's default. The config
// was checked by alarms::resolve when it was read, so the default is only a fallback.
double critical_limit(const alarms::DeviceSettings& settings, alarms::Code code) {
  const auto resolved = alarms::resolve(code, settings[code]);
  return resolved.ok() ? resolved.value().limit : alarms::default_config(code).limit;
}

// A battery value in the contract's unit; NaN when not received.
double value_of(const BatteryState& battery, std::string_view name) {
  const auto slot = battery_slot(name);
  return slot ? battery.values[*slot] : energy::kUnknown;
}

}  // namespace

EnergyTracker::EnergyTracker(const std::vector<BusConfig>& buses, double stale_periods, StateSink& next)
    : ForwardingSink(next), stale_periods_(stale_periods) {
  for (const auto& b : buses) buses_[b.name] = b;
}

energy::PmuEnergy& EnergyTracker::energy_of(const DeviceKey& key) {
  const Key k{key.bus, key.address};
  if (auto it = pmus_.find(k); it != pmus_.end()) return it->second;
  const DeviceConfig* device = nullptr;
  if (auto b = buses_.find(key.bus); b != buses_.end()) {
    device = &b->second.discovered_defaults;
    for (const auto& d : b->second.devices)
      if (d.address == key.address) device = &d;
  }
  const DeviceConfig fallback;
  const DeviceConfig& d = device ? *device : fallback;
  const energy::CriticalVoltages critical{critical_limit(d.alarms, alarms::Code::BatteryACriticalVoltage),
                                          critical_limit(d.alarms, alarms::Code::BatteryBCriticalVoltage)};
  return pmus_.try_emplace(k, critical, max_gap(d.period)).first->second;
}

energy::BmsEnergy& EnergyTracker::bms_energy_of(const DeviceKey& key) {
  const Key k{key.bus, key.address};
  if (auto it = batteries_.find(k); it != batteries_.end()) return it->second;
  // A battery heard through listen_canopen but not listed: a period of 1 s, the table's
  // alarm limits and no capacity, as its session has.
  BatteryConfig battery;
  if (auto b = buses_.find(key.bus); b != buses_.end())
    for (const auto& listed : b->second.batteries)
      if (listed.node == key.address) battery = listed;
  energy::BmsSettings settings;
  if (battery.capacity_ah) settings.capacity_ah = *battery.capacity_ah;
  settings.critical_state_of_charge = critical_limit(battery.alarms, alarms::Code::BmsCriticalSoc);
  return batteries_.try_emplace(k, settings, max_gap(battery.period)).first->second;
}

// The device's STALE time: after it the device's health says its values are old.
std::chrono::nanoseconds EnergyTracker::max_gap(std::chrono::milliseconds period) const {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(std::chrono::duration<double>(period).count() * std::max(stale_periods_, 1.0)));
}

void EnergyTracker::on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                                 std::chrono::system_clock::time_point received) {
  next().on_telemetry(key, message, received);
  if (key.kind != DeviceKind::Pmu || message.request) return;
  const auto* volts = std::get_if<codec::Voltages>(&message.payload);
  const auto* amps = std::get_if<codec::Currents>(&message.payload);
  if (!volts && !amps) return;
  std::lock_guard<std::mutex> lock(mutex_);
  auto& e = energy_of(key);
  if (volts) e.on_voltages(received, *volts);
  if (amps) e.on_currents(received, *amps);
  if (const auto figures = e.report(received)) next().on_energy(key, *figures, received);
}

void EnergyTracker::on_battery(const DeviceKey& key, const BatteryState& battery,
                               std::chrono::system_clock::time_point newest) {
  next().on_battery(key, battery, newest);
  if (key.kind != DeviceKind::Battery) return;
  const energy::BmsReading reading{value_of(battery, "voltage"), value_of(battery, "current"),
                                   value_of(battery, "state_of_charge")};
  std::lock_guard<std::mutex> lock(mutex_);
  auto& e = bms_energy_of(key);
  e.on_sample(newest, reading);
  if (const auto figures = e.report(newest)) next().on_bms_energy(key, *figures, newest);
}

void EnergyTracker::on_gone(const DeviceKey& key) {
  next().on_gone(key);
  std::lock_guard<std::mutex> lock(mutex_);
  // A PMU that moved starts again at its new address: what was integrated here stays with
  // the instance that was disposed.
  if (key.kind == DeviceKind::Pmu) pmus_.erase(Key{key.bus, key.address});
}

}  // namespace pmu::service
