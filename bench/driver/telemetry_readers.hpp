#pragma once
// A subscriber to the five telemetry topics (what `pmuctl watch` reads), counting samples
// and the units they come from, with instance limits for `max_units` units whatever the
// QoS file's telemetry profile allows: the scale rows measure the writer, so the reader
// must not be what drops samples. Used in the driver and in `pmu_bench peer-reader`.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "pmu/dds/dds_context.hpp"

namespace pmu::bench {

class TelemetryReaders {
 public:
  // Throws std::runtime_error when a reader cannot be created.
  TelemetryReaders(pmu::dds::DdsContext& dds, int max_units);
  ~TelemetryReaders();
  TelemetryReaders(const TelemetryReaders&) = delete;
  TelemetryReaders& operator=(const TelemetryReaders&) = delete;

  std::uint64_t received() const noexcept { return received_.load(std::memory_order_relaxed); }
  // Distinct addresses seen on pmu/voltages.
  std::size_t units_seen() const noexcept { return units_.load(std::memory_order_relaxed); }
  // Waits until every topic has a matched writer.
  bool wait_matched(std::chrono::milliseconds timeout);
  // Waits until `units` distinct addresses have been seen.
  bool wait_units(std::size_t units, std::chrono::milliseconds timeout) const;

  struct Shared {
    std::atomic<std::uint64_t>& received;
    std::atomic<std::size_t>& units;
    std::array<std::atomic<bool>, 65536>& seen;
  };

 private:
  pmu::dds::DdsContext& dds_;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> listeners_;
  std::vector<eprosima::fastdds::dds::DataReader*> readers_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::size_t> units_{0};
  std::array<std::atomic<bool>, 65536> seen_{};
};

}  // namespace pmu::bench
