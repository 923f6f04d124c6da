#pragma once
// Takes a state reader's samples, passing over health that is not recent. An agent's reader
// of health lingers matched between calls (ContextPool) and goes on receiving while no call
// runs; what it received long ago says nothing of now: during a radio dropout it still holds
// the last sample of every aircraft. A call on its own would not have heard from them.
//
//   StateSamples<pmu::v4::Health> s(kHealthFresh);
//   s.poll(reader, [&](const pmu::v4::Health& h, const SampleInfo& info) { ... });
//
// Taken, not read: Fast DDS 2.9.1 aborts (an assertion in StatefulReader::NotifyChanges)
// when a sample that arrived before a lost one was read and the lost one's repair then
// comes, which a lossy link makes common; a reader keeps nothing read.
// A plain value; the verb's thread, with a reader that outlives it.

#include <chrono>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <functional>
#include <optional>

namespace pmu::tools {

// How recent a pmu/health sample must be to count (the service publishes one a second; a
// lossy link's repair of a lost one takes another heartbeat period).
inline constexpr std::chrono::seconds kHealthFresh{5};

template <class T>
class StateSamples {
 public:
  using WallClock = std::function<std::chrono::system_clock::time_point()>;
  explicit StateSamples(std::optional<std::chrono::system_clock::duration> max_age = std::nullopt,
                        WallClock clock = [] { return std::chrono::system_clock::now(); })
      : max_age_(max_age), clock_(std::move(clock)) {}

  template <class F>
  void poll(eprosima::fastdds::dds::DataReader& reader, F&& on_sample) {
    T sample;
    eprosima::fastdds::dds::SampleInfo info;
    while (reader.take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK)
      if (!too_old(info)) on_sample(sample, info);
  }

 private:
  bool too_old(const eprosima::fastdds::dds::SampleInfo& info) const {
    if (!max_age_) return false;
    const auto& t = info.reception_timestamp;  // the system clock's, as Fast DDS stamps it
    const auto received = std::chrono::system_clock::time_point(std::chrono::duration_cast<std::chrono::system_clock::duration>(
        std::chrono::seconds(t.seconds()) + std::chrono::nanoseconds(t.nanosec())));
    return clock_() - received > *max_age_;
  }

  std::optional<std::chrono::system_clock::duration> max_age_;
  WallClock clock_;
};

}  // namespace pmu::tools
