#pragma once
// DdsPublisher: the StateSink that puts the service's view of each PMU on the contract's
// topics. With telemetry_samples.hpp (whose fill() it uses for the telemetry packets), the
// only place that converts codec values to the generated DDS types.
//
// Nothing is dropped silently: a write Fast DDS refuses is counted (pmu/health's
// publish_failures) and logged at most once every few seconds with the running count, and a
// PMU beyond the capacity the writers are sized for (kMaxDevicesPerService, e.g. found by
// discovery) is not published, said in the log the same way, and counted too.
//
// Lifetime: the DdsContext given to the constructor must outlive the publisher: the
// publisher keeps the DataWriters the context's participant owns (main.cpp makes the context
// first and destroys it last). The publisher must outlive every BusWorker and
// DdsCommandEndpoint that writes through it.
// Threads: the StateSink members from any bus worker thread at once (Writers::mutex
// serialises the writes); count_failed_write() and the counters from any thread.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pmu/config/config.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/session/state_sink.hpp"

namespace pmu::service {

class DdsPublisher final : public StateSink {
 public:
  // Creates the topics and writers. `telemetry_deadline` is the writers' DEADLINE
  // (3 x the longest packet period served). Throws dds::DdsError at start-up.
  // `vehicle`: the first key of every sample (vehicle.hpp). `low_rate_period` > 0: also the
  // low-rate telemetry topics, one sample per device and packet per period (low_rate.hpp),
  // and pmu/low_rate/health, written when a device's state or bus state changes.
  // `canopen_deadline`: DEADLINE of pmu/battery, pmu/battery_cells and pmu/mppt (3 x the
  // longest battery/MPPT period, or the publish period if longer); nullopt: a service that
  // serves no battery or MPPT does not offer those topics nor pmu/bms_energy, so DDS-Security
  // permissions made before they existed still let it start.
  DdsPublisher(dds::DdsContext& dds, std::chrono::milliseconds telemetry_deadline, std::string vehicle = {},
               std::chrono::milliseconds low_rate_period = {},
               std::optional<std::chrono::milliseconds> canopen_deadline = std::chrono::seconds(3));
  ~DdsPublisher() override;

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override;
  void on_config(const DeviceKey& key, const ConfigState& config) override;
  void on_info(const DeviceKey& key, const InfoState& info) override;
  void on_health(const DeviceKey& key, const HealthReport& health) override;
  // Unregisters (and so disposes: the writers autodispose) `key`'s instance on every topic
  // it can have one on, and frees its place among the kMaxDevicesPerService admitted.
  void on_gone(const DeviceKey& key) override;
  void on_battery(const DeviceKey& key, const BatteryState& battery,
                  std::chrono::system_clock::time_point newest) override;
  void on_battery_cells(const DeviceKey& key, const BatteryCellsState& cells,
                        std::chrono::system_clock::time_point newest) override;
  void on_mppt(const DeviceKey& key, const MpptState& mppt, std::chrono::system_clock::time_point newest) override;
  void on_alarm(const AlarmReport& alarm) override;
  void on_readiness(const ReadinessReport& readiness) override;
  void on_energy(const DeviceKey& key, const energy::Figures& figures,
                 std::chrono::system_clock::time_point at) override;
  void on_bms_energy(const DeviceKey& key, const energy::BmsFigures& figures,
                     std::chrono::system_clock::time_point at) override;

  // pmu/baseline: one sample per configured PMU with a `baseline:`, written once at start
  // (interface.md 1.9); the state profile keeps it for late joiners. Not from a session:
  // the baseline is the config's. Every other PMU's instance is disposed: the configured
  // ones here, one found on the bus when it is first published. Call before the bus workers
  // start.
  void publish_baselines(const std::vector<BusConfig>& buses);

  // Empties every writer's history but pmu/baseline's (the config's, the same on both
  // instances of a hot-standby pair): a late joiner gets nothing of this service until it
  // writes again. A standby calls it when it stops owning the bus (docs/design.md, "Hot
  // standby"). Thread-safe.
  void clear_histories();

  // A write to another of the service's topics (pmu/command_reply) failed: counted in
  // publish_failures and logged like the publisher's own. Thread-safe.
  void count_failed_write(const char* topic, const DeviceKey& key, const char* why);

  // Samples written, and samples not published: writes Fast DDS refused plus samples of PMUs
  // beyond the capacity. Read from any thread while the bus workers write.
  std::uint64_t samples_written() const noexcept { return written_.load(std::memory_order_relaxed); }
  std::uint64_t write_failures() const noexcept { return failures_.load(std::memory_order_relaxed); }
  // Samples (counted in write_failures too) of PMUs not published because
  // kMaxDevicesPerService others are.
  std::uint64_t samples_over_capacity() const noexcept { return refused_.load(std::memory_order_relaxed); }

 private:
  struct Writers;
  // These called with Writers::mutex held.
  bool admit(const DeviceKey& key);
  void dispose_baseline(const DeviceKey& key);
  // Writes with a source timestamp and counts the result.
  void write_at(eprosima::fastdds::dds::DataWriter* writer, void* sample, const DeviceKey& key,
                std::chrono::system_clock::time_point when);
  void count(bool ok, const char* topic, const DeviceKey& key, const char* why);
  std::unique_ptr<Writers> w_;
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> failures_{0};
  std::atomic<std::uint64_t> refused_{0};
};

}  // namespace pmu::service
