#pragma once
// The PMU at the far end of the service's bus fd (a socketpair carrying struct can_frame
// records, the way the service reads a CAN_RAW socket). A thread runs the simulator model,
// which answers the service's gets and streams every packet once a second; the benchmark
// thread adds numbered voltages frames at a chosen rate and notes when each was written.
// For the scale rows the same thread runs several models (addresses 1..units) streaming
// every packet at a chosen period.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "pmu/transport/unique_fd.hpp"

namespace pmu::bench {

// Injected frames carry this avionics voltage (raw 171) and a number in the two battery
// voltage bytes (each 0..250, the field's range: base 250); the model's own frames read
// 12.0 V, so a reader tells them apart.
inline constexpr int kMarkerRaw = 171;
inline constexpr int kSeqBase = 250;
inline constexpr int kSeqSpace = kSeqBase * kSeqBase;

// steady_clock nanoseconds at which each numbered frame was written (0 = none pending).
class WriteTimes {
 public:
  void record(std::uint16_t seq, std::int64_t ns) noexcept { t_[seq].store(ns, std::memory_order_release); }
  // The write time of `seq`, once: a second sample with the same number is not counted.
  std::int64_t take(std::uint16_t seq) noexcept { return t_[seq].exchange(0, std::memory_order_acq_rel); }
  // Numbers written but never taken (samples that did not arrive).
  std::vector<std::uint16_t> pending() const {
    std::vector<std::uint16_t> out;
    for (std::size_t i = 0; i < t_.size(); ++i)
      if (t_[i].load() != 0) out.push_back(static_cast<std::uint16_t>(i));
    return out;
  }
  void clear() noexcept {
    for (auto& t : t_) t.store(0);
  }

 private:
  std::array<std::atomic<std::int64_t>, 65536> t_{};
};

struct Injection {
  std::uint64_t frames = 0;
  double seconds = 0;  // from the first write to the last
  double rate() const noexcept { return seconds > 0 ? static_cast<double>(frames - 1) / seconds : 0; }
};

// How many PMUs the far end simulates (addresses 1..units) and their packet period (PP,
// tenths of a second); each streams all five packets.
struct FakePmuLoad {
  std::uint16_t units = 1;
  std::uint32_t period_tenths = 10;
};

class FakePmu {
 public:
  explicit FakePmu(transport::UniqueFd fd, FakePmuLoad load = {});
  ~FakePmu();
  FakePmu(const FakePmu&) = delete;
  FakePmu& operator=(const FakePmu&) = delete;

  // Writes numbered voltages frames at `rate` per second for `duration` (or until `stop`),
  // paced by absolute sleeps; a late writer catches up without sleeping.
  Injection inject(double rate, std::chrono::nanoseconds duration, WriteTimes& times,
                   const std::atomic<bool>* stop = nullptr);
  // Writes one status frame (0x04) of PMU 1, engine running, with the thermal shutdown flag
  // as given; returns the steady_clock ns of the write. The model's own status frames (flag
  // clear) follow once a second.
  std::int64_t write_status(bool thermal_shutdown);
  std::uint64_t frames_from_service() const noexcept { return from_service_.load(); }

 private:
  void run();
  void write_raw(const void* frame);

  transport::UniqueFd fd_;
  FakePmuLoad load_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> from_service_{0};
  std::uint16_t seq_ = 0;
  std::mutex write_mutex_;
  std::thread thread_;
};

}  // namespace pmu::bench
