#pragma once
// Reads a state reader's samples without taking them. An agent's readers of health and device
// info linger matched between calls (ContextPool), holding the fleet's current state, which
// their writers (TRANSIENT_LOCAL) sent once: a call that took the samples would leave the
// next one nothing of the devices whose state did not change since.
//
//   StateSamples<pmu::v4::Health> s;
//   s.poll(reader, [&](const pmu::v4::Health& h, const SampleInfo& info) { ... });
//
// The first poll gives every sample the reader holds, later ones those received since.
// With a `max_age`, a sample received longer ago than that is passed over: the reader may
// have lingered through a radio dropout, and health the service publishes every second
// that stopped coming says the aircraft is out of reach, not how it is.
// A plain value; the verb's thread, with a reader that outlives it.

#include <chrono>
#include <fastdds/dds/core/LoanableSequence.hpp>
#include <functional>
#include <optional>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/InstanceState.hpp>
#include <fastdds/dds/subscriber/SampleState.hpp>
#include <fastdds/dds/subscriber/ViewState.hpp>

namespace pmu::tools {

// How recent a pmu/health sample must be to count (the service publishes one a second; a
// lossy link's repair of a lost one takes another heartbeat period, 1 s).
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
    using namespace eprosima::fastdds::dds;
    const SampleStateMask states = first_ ? SampleStateMask{ANY_SAMPLE_STATE} : SampleStateMask{NOT_READ_SAMPLE_STATE};
    first_ = false;
    // Instance by instance: one read() lends at most max_samples_per_read samples, and
    // reading the first ones again would never reach the others.
    InstanceHandle_t previous = HANDLE_NIL;
    for (;;) {
      LoanableSequence<T> samples;
      SampleInfoSeq infos;
      if (reader.read_next_instance(samples, infos, LENGTH_UNLIMITED, previous, states, ANY_VIEW_STATE,
                                    ANY_INSTANCE_STATE) != ReturnCode_t::RETCODE_OK)
        return;  // no further instance with samples (new ones, after the first poll)
      for (LoanableCollection::size_type i = 0; i < infos.length(); ++i) {
        previous = infos[i].instance_handle;
        if (!too_old(infos[i])) on_sample(samples[i], infos[i]);
      }
      (void)reader.return_loan(samples, infos);
    }
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
  bool first_ = true;
};

}  // namespace pmu::tools
