#pragma once
// StateFanout: one StateSink that hands every event to several, in order: the service's own
// DdsPublisher and, with `also_serve_contract`, the publisher of the previous contract's
// participant, so both contracts' consumers see the same values at the same moments.
//
// Lifetime: the sinks must outlive the fanout, and the fanout every BusWorker given it.
// Threads: as the sinks' (each StateSink member from any bus worker thread).

#include <utility>
#include <vector>

#include "pmu/session/state_sink.hpp"

namespace pmu::service {

class StateFanout final : public StateSink {
 public:
  explicit StateFanout(std::vector<StateSink*> sinks) : sinks_(std::move(sinks)) {}

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override {
    for (auto* s : sinks_) s->on_telemetry(key, message, received);
  }
  void on_config(const DeviceKey& key, const ConfigState& config) override {
    for (auto* s : sinks_) s->on_config(key, config);
  }
  void on_info(const DeviceKey& key, const InfoState& info) override {
    for (auto* s : sinks_) s->on_info(key, info);
  }
  void on_health(const DeviceKey& key, const HealthReport& health) override {
    for (auto* s : sinks_) s->on_health(key, health);
  }
  void on_gone(const DeviceKey& key) override {
    for (auto* s : sinks_) s->on_gone(key);
  }
  void on_battery(const DeviceKey& key, const BatteryState& battery,
                  std::chrono::system_clock::time_point newest) override {
    for (auto* s : sinks_) s->on_battery(key, battery, newest);
  }
  void on_battery_cells(const DeviceKey& key, const BatteryCellsState& cells,
                        std::chrono::system_clock::time_point newest) override {
    for (auto* s : sinks_) s->on_battery_cells(key, cells, newest);
  }
  void on_mppt(const DeviceKey& key, const MpptState& mppt, std::chrono::system_clock::time_point newest) override {
    for (auto* s : sinks_) s->on_mppt(key, mppt, newest);
  }
  void on_alarm(const AlarmReport& alarm) override {
    for (auto* s : sinks_) s->on_alarm(alarm);
  }
  void on_readiness(const ReadinessReport& readiness) override {
    for (auto* s : sinks_) s->on_readiness(readiness);
  }
  void on_energy(const DeviceKey& key, const energy::Figures& figures,
                 std::chrono::system_clock::time_point at) override {
    for (auto* s : sinks_) s->on_energy(key, figures, at);
  }
  void on_bms_energy(const DeviceKey& key, const energy::BmsFigures& figures,
                     std::chrono::system_clock::time_point at) override {
    for (auto* s : sinks_) s->on_bms_energy(key, figures, at);
  }

 private:
  std::vector<StateSink*> sinks_;
};

}  // namespace pmu::service
