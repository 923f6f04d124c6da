#include "pmu/energy_sink/energy_tracker.hpp"

#include <algorithm>
#include <variant>

namespace pmu::service {
namespace {

// The limit the device's alarm runs with: its override over the table's default. The config
// was checked by alarms::resolve when it was read, so the default is only a fallback.
double critical_limit(const alarms::DeviceSettings& settings, alarms::Code code) {
  const auto resolved = alarms::resolve(code, settings[code]);
  return resolved.ok() ? resolved.value().limit : alarms::default_config(code).limit;
}

}  // namespace

EnergyTracker::EnergyTracker(const std::vector<BusConfig>& buses, double stale_periods, StateSink& next)
    : stale_periods_(stale_periods), next_(next) {
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
  const auto max_gap = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(std::chrono::duration<double>(d.period).count() * std::max(stale_periods_, 1.0)));
  return pmus_.try_emplace(k, critical, max_gap).first->second;
}

void EnergyTracker::on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                                 std::chrono::system_clock::time_point received) {
  next_.on_telemetry(key, message, received);
  if (key.kind != DeviceKind::Pmu || message.request) return;
  const auto* volts = std::get_if<codec::Voltages>(&message.payload);
  const auto* amps = std::get_if<codec::Currents>(&message.payload);
  if (!volts && !amps) return;
  std::lock_guard<std::mutex> lock(mutex_);
  auto& e = energy_of(key);
  if (volts) e.on_voltages(received, *volts);
  if (amps) e.on_currents(received, *amps);
  if (const auto figures = e.report(received)) next_.on_energy(key, *figures, received);
}

void EnergyTracker::on_gone(const DeviceKey& key) {
  next_.on_gone(key);
  std::lock_guard<std::mutex> lock(mutex_);
  // A PMU that moved starts again at its new address: what was integrated here stays with
  // the instance that was disposed.
  if (key.kind == DeviceKind::Pmu) pmus_.erase(Key{key.bus, key.address});
}

}  // namespace pmu::service
