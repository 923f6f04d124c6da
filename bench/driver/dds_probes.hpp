#pragma once
// The benchmark's DDS ends, in the driver process: a pmu/voltages reader that times each
// sample, and a command client that times each request/reply round trip.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "fake_pmu.hpp"
#include "pmu/dds/dds_context.hpp"

namespace pmu::bench {

// The reference writer has no CAN frame to number: it spreads its steady_clock write time
// over four float fields, 16 bits each (exact in a float), and marks battery_a.
inline constexpr float kEmbeddedMarker = 99.0f;

class VoltagesProbe : public eprosima::fastdds::dds::DataReaderListener {
 public:
  // Service mode: samples of injected frames are matched to `times`. Embedded mode
  // (`times` null): the write time travels in the sample.
  VoltagesProbe(pmu::dds::DdsContext& dds, WriteTimes* times);
  ~VoltagesProbe() override;

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
  // Fast DDS reports a gap in a writer's sequence numbers: samples the writer wrote that
  // never reached this reader (lost in delivery, not before the write).
  void on_sample_lost(eprosima::fastdds::dds::DataReader* reader,
                      const eprosima::fastdds::dds::SampleLostStatus& status) override;

  // Latencies (ns) of the samples received since the last call; counting restarts.
  std::vector<std::int64_t> take_latencies();
  std::uint64_t received() const noexcept { return received_.load(); }
  // Samples of any writer on the topic that Fast DDS reported lost, since creation.
  std::uint64_t lost_in_delivery() const noexcept { return lost_.load(); }
  // steady_clock ns of the first timed sample since reset_first(); 0 while none.
  std::int64_t first_sample_ns() const noexcept { return first_.load(); }
  void reset_first() noexcept { first_ = 0; }
  // steady_clock ns of the latest timed sample.
  std::int64_t last_sample_ns() const noexcept { return last_.load(); }
  // Waits until a writer is matched.
  bool wait_matched(std::chrono::milliseconds timeout);

 private:
  pmu::dds::DdsContext& dds_;
  WriteTimes* times_;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::mutex mutex_;
  std::vector<std::int64_t> latencies_;
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> lost_{0};
  std::atomic<std::int64_t> first_{0};
  std::atomic<std::int64_t> last_{0};
};

// Sequential commands (GET outputs) to one device, one in flight at a time.
class CommandClient : public eprosima::fastdds::dds::DataReaderListener {
 public:
  explicit CommandClient(pmu::dds::DdsContext& dds);
  ~CommandClient() override;
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;

  bool wait_matched(std::chrono::milliseconds timeout);
  struct Result {
    std::vector<std::int64_t> rtt_ns;
    std::map<std::string, int> results;  // result name -> count, for anything not COMPLETED
    int timeouts = 0;
  };
  Result run(int count, const std::string& bus, std::uint16_t address, std::chrono::milliseconds each_timeout);

 private:
  pmu::dds::DdsContext& dds_;
  eprosima::fastdds::dds::DataReader* replies_ = nullptr;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::string waiting_for_;
  bool answered_ = false;
  int result_ = -1;
};

}  // namespace pmu::bench
