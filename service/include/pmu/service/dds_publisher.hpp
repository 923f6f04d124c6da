#pragma once
// DdsPublisher: the StateSink that puts the service's view of each PMU on the contract's
// topics. The only place that converts codec values to the generated DDS types.

#include <chrono>
#include <memory>

#include "pmu/service/dds_context.hpp"
#include "pmu/service/device_state.hpp"

namespace pmu::service {

class DdsPublisher final : public StateSink {
 public:
  // Creates the topics and writers. `telemetry_deadline` is the writers' DEADLINE
  // (3 x the longest packet period served). Throws dds::DdsError at start-up.
  DdsPublisher(dds::DdsContext& dds, std::chrono::milliseconds telemetry_deadline);
  ~DdsPublisher() override;

  void on_telemetry(const DeviceKey& key, const codec::PmuMessage& message,
                    std::chrono::system_clock::time_point received) override;
  void on_config(const DeviceKey& key, const ConfigState& config) override;
  void on_info(const DeviceKey& key, const InfoState& info) override;
  void on_health(const DeviceKey& key, const HealthReport& health) override;

  // Samples written, and writes Fast DDS refused (counted, logged by the caller's loop).
  std::uint64_t samples_written() const noexcept { return written_; }
  std::uint64_t write_failures() const noexcept { return failures_; }

 private:
  void count(bool ok) noexcept;
  struct Writers;
  std::unique_ptr<Writers> w_;
  std::uint64_t written_ = 0;
  std::uint64_t failures_ = 0;
};

}  // namespace pmu::service
