#pragma once
// Alarm latency: when a status frame with the thermal shutdown flag was written to the
// service's bus, when its pmu/status sample arrived, and when the thermal_shutdown alarm it
// raises arrived on pmu/alarms. The status sample is the reference: the same frame, through
// the same service, without the alarm's evaluation and its reliable topic.

#include <atomic>
#include <chrono>
#include <cstdint>

#include "pmu/dds/dds_context.hpp"

namespace pmu::bench {

// dds must outlive the probe (its readers stay in the context; the destructor detaches their
// listeners). The listeners run on Fast DDS's threads; the rest is called from the driver's.
class AlarmProbe {
 public:
  explicit AlarmProbe(pmu::dds::DdsContext& dds);
  ~AlarmProbe();
  AlarmProbe(const AlarmProbe&) = delete;
  AlarmProbe& operator=(const AlarmProbe&) = delete;

  // Forgets what arrived, before the next frame.
  void reset() noexcept;
  // steady_clock ns at which a status sample with the flag set, and a thermal_shutdown alarm
  // sample in state ACTIVE_UNACKNOWLEDGED, arrived since reset(); 0 while none.
  std::int64_t status_at() const noexcept { return status_at_.load(); }
  std::int64_t alarm_at() const noexcept { return alarm_at_.load(); }
  bool wait_matched(std::chrono::milliseconds timeout);

 private:
  struct Listeners;
  pmu::dds::DdsContext& dds_;
  std::atomic<std::int64_t> status_at_{0};
  std::atomic<std::int64_t> alarm_at_{0};
  Listeners* listeners_;
};

}  // namespace pmu::bench
