#pragma once
// RoleGate: the state topics of one instance of a hot-standby pair (docs/design.md, "Hot
// standby", "One stream per device for consumers"). In front of the publishers, behind the
// trackers: the sessions, energy and readiness keep running in a standby, so its state is
// warm, and the gate passes their events on only while it is open (this instance owns the
// bus). While closed it keeps the newest of each state event (a device's config, info,
// health, battery, cells, MPPT, energy; each alarm; readiness) and drops telemetry, which
// is current again at the next frame. open() writes what it kept, so a new owner's first
// samples reach every reader, late joiners included, at once; close() calls `on_close`,
// which clears the publishers' histories, so a late joiner never gets a former owner's
// sample beside the new owner's.
//
// Threads: the StateSink members on the bus workers' threads, open() and close() from any
// thread; one mutex orders them, and the events passed on are passed with it held, so that
// nothing written while closing can slip past it. Lifetime: `next` must outlive the gate.

#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <tuple>

#include "pmu/session/state_sink.hpp"

namespace pmu::standby {

class RoleGate final : public service::StateSink {
 public:
  RoleGate(service::StateSink& next, std::function<void()> on_close);

  void open();
  void close();
  bool is_open() const;

  void on_telemetry(const service::DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override;
  void on_config(const service::DeviceKey& key, const service::ConfigState& config) override;
  void on_info(const service::DeviceKey& key, const service::InfoState& info) override;
  void on_health(const service::DeviceKey& key, const service::HealthReport& health) override;
  void on_gone(const service::DeviceKey& key) override;
  void on_battery(const service::DeviceKey& key, const service::BatteryState& battery,
                  std::chrono::system_clock::time_point newest) override;
  void on_battery_cells(const service::DeviceKey& key, const service::BatteryCellsState& cells,
                        std::chrono::system_clock::time_point newest) override;
  void on_mppt(const service::DeviceKey& key, const service::MpptState& mppt,
               std::chrono::system_clock::time_point newest) override;
  void on_alarm(const service::AlarmReport& alarm) override;
  void on_readiness(const service::ReadinessReport& readiness) override;
  void on_energy(const service::DeviceKey& key, const energy::Figures& figures,
                 std::chrono::system_clock::time_point at) override;
  void on_bms_energy(const service::DeviceKey& key, const energy::BmsFigures& figures,
                     std::chrono::system_clock::time_point at) override;

 private:
  using Key = std::tuple<std::string, service::DeviceKind, std::uint16_t>;
  static Key key_of(const service::DeviceKey& k) { return {k.bus, k.kind, k.address}; }
  template <class T>
  struct Stamped {
    T value;
    std::chrono::system_clock::time_point at;
  };
  struct Kept {
    service::DeviceKey key;
    std::optional<service::ConfigState> config;
    std::optional<service::InfoState> info;
    std::optional<service::HealthReport> health;
    std::optional<Stamped<service::BatteryState>> battery;
    std::optional<Stamped<service::BatteryCellsState>> cells;
    std::optional<Stamped<service::MpptState>> mppt;
    std::optional<Stamped<energy::Figures>> energy;
    std::optional<Stamped<energy::BmsFigures>> bms_energy;
  };
  Kept& kept(const service::DeviceKey& key);  // with mutex_ held

  service::StateSink& next_;
  std::function<void()> on_close_;
  mutable std::mutex mutex_;
  bool open_ = false;
  std::map<Key, Kept> devices_;
  std::map<std::tuple<std::string, alarms::DeviceKind, std::uint16_t, alarms::Code>, service::AlarmReport> alarms_;
  std::optional<service::ReadinessReport> readiness_;
};

}  // namespace pmu::standby
