#pragma once
// StateSink: the port through which the sessions hand on what the service knows of its
// devices (device_state.hpp): the DDS publishers in the daemon, a recorder in tests, and the
// trackers in front of the publishers (readiness, energy), which watch some events and pass
// every event on. ForwardingSink is their base: it passes each event to the next sink, so a
// tracker overrides only the events it watches.
//
// Threads: every member is called on the bus worker's thread that made the event (on_readiness:
// whichever worker's event changed it); a sink shared by several buses is called from several
// threads at once.

#include <chrono>

#include "pmu/session/device_state.hpp"

namespace pmu::service {

class StateSink {
 public:
  virtual ~StateSink() = default;
  // A telemetry frame (packets 0x00..0x04) decoded; `received` is the frame's receive time.
  virtual void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                            std::chrono::system_clock::time_point received) = 0;
  virtual void on_config(const DeviceKey& key, const ConfigState& config) = 0;
  virtual void on_info(const DeviceKey& key, const InfoState& info) = 0;
  virtual void on_health(const DeviceKey& key, const HealthReport& health) = 0;
  // No device is at `key` any more (a PMU that moved to another CAN address): every
  // instance of every topic under it is unregistered and disposed, so neither a reader
  // nor a late joiner keeps a device that is not there. The last health sent before is
  // OFFLINE.
  virtual void on_gone(const DeviceKey& key) = 0;
  // A battery's or MPPT's assembled values changed (canopen_session.hpp); `newest` is the
  // receive time of the newest frame that contributed.
  virtual void on_battery(const DeviceKey& key, const BatteryState& battery,
                          std::chrono::system_clock::time_point newest) = 0;
  virtual void on_battery_cells(const DeviceKey& key, const BatteryCellsState& cells,
                                std::chrono::system_clock::time_point newest) = 0;
  virtual void on_mppt(const DeviceKey& key, const MpptState& mppt, std::chrono::system_clock::time_point newest) = 0;
  // An alarm changed state (raised, acknowledged, cleared, back to NORMAL).
  virtual void on_alarm(const AlarmReport& alarm) = 0;
  virtual void on_readiness(const ReadinessReport& readiness) = 0;
  // A PMU's derived energy (interface.md 1.8), from the EnergyTracker; `at` is the receive
  // time of the sample that made it due.
  virtual void on_energy(const DeviceKey& key, const energy::Figures& figures,
                         std::chrono::system_clock::time_point at) = 0;
  // A BMS-reported battery's derived energy (pmu/bms_energy), from the EnergyTracker; `at`
  // is the receive time of the pmu/battery sample that made it due.
  virtual void on_bms_energy(const DeviceKey& key, const energy::BmsFigures& figures,
                             std::chrono::system_clock::time_point at) = 0;
};

// A StateSink in front of another that passes every event on unchanged, on the caller's
// thread. A tracker derives from it, overrides the events it watches and passes those on
// itself (next()), so each event reaches `next` once and in the order it came.
// Lifetime: `next` must outlive this sink, which keeps a reference to it.
class ForwardingSink : public StateSink {
 public:
  explicit ForwardingSink(StateSink& next) noexcept : next_(next) {}

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override {
    next_.on_telemetry(key, message, received);
  }
  void on_config(const DeviceKey& key, const ConfigState& config) override { next_.on_config(key, config); }
  void on_info(const DeviceKey& key, const InfoState& info) override { next_.on_info(key, info); }
  void on_health(const DeviceKey& key, const HealthReport& health) override { next_.on_health(key, health); }
  void on_gone(const DeviceKey& key) override { next_.on_gone(key); }
  void on_battery(const DeviceKey& key, const BatteryState& battery,
                  std::chrono::system_clock::time_point newest) override {
    next_.on_battery(key, battery, newest);
  }
  void on_battery_cells(const DeviceKey& key, const BatteryCellsState& cells,
                        std::chrono::system_clock::time_point newest) override {
    next_.on_battery_cells(key, cells, newest);
  }
  void on_mppt(const DeviceKey& key, const MpptState& mppt, std::chrono::system_clock::time_point newest) override {
    next_.on_mppt(key, mppt, newest);
  }
  void on_alarm(const AlarmReport& alarm) override { next_.on_alarm(alarm); }
  void on_readiness(const ReadinessReport& readiness) override { next_.on_readiness(readiness); }
  void on_energy(const DeviceKey& key, const energy::Figures& figures,
                 std::chrono::system_clock::time_point at) override {
    next_.on_energy(key, figures, at);
  }
  void on_bms_energy(const DeviceKey& key, const energy::BmsFigures& figures,
                     std::chrono::system_clock::time_point at) override {
    next_.on_bms_energy(key, figures, at);
  }

 protected:
  StateSink& next() const noexcept { return next_; }

 private:
  StateSink& next_;
};

}  // namespace pmu::service
