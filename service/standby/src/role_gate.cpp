#include "pmu/standby/role_gate.hpp"

#include <utility>

namespace pmu::standby {

RoleGate::RoleGate(service::StateSink& next, std::function<void()> on_close)
    : next_(next), on_close_(std::move(on_close)) {}

RoleGate::Kept& RoleGate::kept(const service::DeviceKey& key) {
  auto& k = devices_[key_of(key)];
  k.key = key;
  return k;
}

void RoleGate::open() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (open_) return;
  open_ = true;
  // Health before the values it vouches for, as a session writes them at its start.
  for (const auto& [_, k] : devices_) {
    if (k.health) next_.on_health(k.key, *k.health);
    if (k.info) next_.on_info(k.key, *k.info);
    if (k.config) next_.on_config(k.key, *k.config);
    if (k.battery) next_.on_battery(k.key, k.battery->value, k.battery->at);
    if (k.cells) next_.on_battery_cells(k.key, k.cells->value, k.cells->at);
    if (k.mppt) next_.on_mppt(k.key, k.mppt->value, k.mppt->at);
    if (k.energy) next_.on_energy(k.key, k.energy->value, k.energy->at);
    if (k.bms_energy) next_.on_bms_energy(k.key, k.bms_energy->value, k.bms_energy->at);
  }
  for (const auto& [_, a] : alarms_) next_.on_alarm(a);
  if (readiness_) next_.on_readiness(*readiness_);
}

void RoleGate::close() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!open_) return;
  open_ = false;
  if (on_close_) on_close_();
}

bool RoleGate::is_open() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return open_;
}

// Every event is kept, open or not: the gate that closes and opens again has the newest.

void RoleGate::on_telemetry(const service::DeviceKey& key, const codec::PmuMessage& message,
                            std::chrono::system_clock::time_point received) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (open_) next_.on_telemetry(key, message, received);
}

void RoleGate::on_config(const service::DeviceKey& key, const service::ConfigState& config) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).config = config;
  if (open_) next_.on_config(key, config);
}

void RoleGate::on_info(const service::DeviceKey& key, const service::InfoState& info) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).info = info;
  if (open_) next_.on_info(key, info);
}

void RoleGate::on_health(const service::DeviceKey& key, const service::HealthReport& health) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).health = health;
  if (open_) next_.on_health(key, health);
}

void RoleGate::on_gone(const service::DeviceKey& key) {
  std::lock_guard<std::mutex> lock(mutex_);
  devices_.erase(key_of(key));
  if (open_) next_.on_gone(key);
}

void RoleGate::on_battery(const service::DeviceKey& key, const service::BatteryState& battery,
                          std::chrono::system_clock::time_point newest) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).battery = Stamped<service::BatteryState>{battery, newest};
  if (open_) next_.on_battery(key, battery, newest);
}

void RoleGate::on_battery_cells(const service::DeviceKey& key, const service::BatteryCellsState& cells,
                                std::chrono::system_clock::time_point newest) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).cells = Stamped<service::BatteryCellsState>{cells, newest};
  if (open_) next_.on_battery_cells(key, cells, newest);
}

void RoleGate::on_mppt(const service::DeviceKey& key, const service::MpptState& mppt,
                       std::chrono::system_clock::time_point newest) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).mppt = Stamped<service::MpptState>{mppt, newest};
  if (open_) next_.on_mppt(key, mppt, newest);
}

void RoleGate::on_alarm(const service::AlarmReport& alarm) {
  std::lock_guard<std::mutex> lock(mutex_);
  alarms_[{alarm.bus, alarm.source, alarm.device, alarm.code}] = alarm;
  if (open_) next_.on_alarm(alarm);
}

void RoleGate::on_readiness(const service::ReadinessReport& readiness) {
  std::lock_guard<std::mutex> lock(mutex_);
  readiness_ = readiness;
  if (open_) next_.on_readiness(readiness);
}

void RoleGate::on_energy(const service::DeviceKey& key, const energy::Figures& figures,
                         std::chrono::system_clock::time_point at) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).energy = Stamped<energy::Figures>{figures, at};
  if (open_) next_.on_energy(key, figures, at);
}

void RoleGate::on_bms_energy(const service::DeviceKey& key, const energy::BmsFigures& figures,
                             std::chrono::system_clock::time_point at) {
  std::lock_guard<std::mutex> lock(mutex_);
  kept(key).bms_energy = Stamped<energy::BmsFigures>{figures, at};
  if (open_) next_.on_bms_energy(key, figures, at);
}

}  // namespace pmu::standby
