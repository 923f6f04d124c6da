#pragma once
// A StateSink that keeps everything the service would have published.

#include <chrono>
#include <map>
#include <vector>

#include "pmu/session/state_sink.hpp"

namespace pmu::service::test {

class RecordingSink final : public StateSink {
 public:
  struct Telemetry {
    DeviceKey key;
    codec::PmuMessage message;
    std::chrono::system_clock::time_point received;
  };
  void on_telemetry(const DeviceKey& k, const codec::PmuMessage& m, std::chrono::system_clock::time_point t) override {
    telemetry.push_back({k, m, t});
    events.push_back({k, false});
  }
  void on_config(const DeviceKey& k, const ConfigState& c) override {
    configs.push_back({k, c});
    events.push_back({k, false});
  }
  void on_info(const DeviceKey& k, const InfoState& i) override {
    infos.push_back({k, i});
    events.push_back({k, false});
  }
  void on_health(const DeviceKey& k, const HealthReport& h) override {
    healths.push_back({k, h});
    events.push_back({k, false});
  }
  void on_gone(const DeviceKey& k) override {
    gone.push_back(k);
    events.push_back({k, true});
  }
  void on_battery(const DeviceKey& k, const BatteryState& b, std::chrono::system_clock::time_point t) override {
    batteries.push_back({k, b, t});
  }
  void on_battery_cells(const DeviceKey& k, const BatteryCellsState& c,
                        std::chrono::system_clock::time_point t) override {
    cells.push_back({k, c, t});
  }
  void on_mppt(const DeviceKey& k, const MpptState& m, std::chrono::system_clock::time_point t) override {
    mppts.push_back({k, m, t});
  }

  void on_alarm(const AlarmReport& a) override { alarms.push_back(a); }
  void on_readiness(const ReadinessReport& r) override { readiness.push_back(r); }
  struct Energy {
    DeviceKey key;
    energy::Figures figures;
    std::chrono::system_clock::time_point at;
  };
  void on_energy(const DeviceKey& k, const energy::Figures& f, std::chrono::system_clock::time_point at) override {
    energy.push_back({k, f, at});
  }
  struct BmsEnergy {
    DeviceKey key;
    energy::BmsFigures figures;
    std::chrono::system_clock::time_point at;
  };
  void on_bms_energy(const DeviceKey& k, const energy::BmsFigures& f,
                     std::chrono::system_clock::time_point at) override {
    bms_energy.push_back({k, f, at});
  }

  std::size_t count(codec::PacketId p, std::uint16_t address) const {
    std::size_t n = 0;
    for (const auto& t : telemetry) n += (t.message.packet == p && t.key.address == address) ? 1 : 0;
    return n;
  }
  const HealthReport* last_health(std::uint16_t address, DeviceKind kind = DeviceKind::Pmu) const {
    for (auto it = healths.rbegin(); it != healths.rend(); ++it)
      if (it->first.address == address && it->first.kind == kind) return &it->second;
    return nullptr;
  }

  std::vector<Telemetry> telemetry;
  std::vector<AlarmReport> alarms;
  std::vector<ReadinessReport> readiness;
  std::vector<Energy> energy;
  std::vector<BmsEnergy> bms_energy;
  std::vector<std::pair<DeviceKey, ConfigState>> configs;
  std::vector<std::pair<DeviceKey, InfoState>> infos;
  std::vector<std::pair<DeviceKey, HealthReport>> healths;
  std::vector<DeviceKey> gone;
  // Every PMU publication and disposal in order: what a DDS reader would hold now.
  struct Event {
    DeviceKey key;
    bool gone = false;
  };
  std::vector<Event> events;
  // PMU addresses with an instance on DDS now: published, and not gone since.
  std::vector<std::uint16_t> live_pmus() const {
    std::map<std::uint16_t, bool> last;
    for (const auto& e : events)
      if (e.key.kind == DeviceKind::Pmu) last[e.key.address] = !e.gone;
    std::vector<std::uint16_t> out;
    for (const auto& [a, live] : last)
      if (live) out.push_back(a);
    return out;
  }
  template <class State>
  struct Sample {
    DeviceKey key;
    State state;
    std::chrono::system_clock::time_point newest;
  };
  std::vector<Sample<BatteryState>> batteries;
  std::vector<Sample<BatteryCellsState>> cells;
  std::vector<Sample<MpptState>> mppts;
};

}  // namespace pmu::service::test
