#pragma once
// When a state verb (list, health, info, config get) has the whole fleet's current state.
//
// Each pmu-service has one writer per state topic, TRANSIENT_LOCAL: once a writer's first
// sample arrives, the rest of that service's state comes in the same burst. A fleet is
// several services, matched one after another as discovery finds them: over a slow radio
// link the second service's burst can come a second after the first's. So the verb settles
// only when every expected writer has been heard from and nothing new (a match, a service
// discovered, a writer's first sample) happened for the quiet time; the caller's deadline
// bounds the wait anyway. Expected: the writers matched, plus the services discovered whose
// writer discovery has not reported yet (a participant's announcement comes before its
// endpoints', which over a slow link take seconds).
//
//   StateSettle s(300ms);
//   s.observe(t, writers_expected, writers_heard);   // after every poll
//   if (s.settled(t)) ...                            // the state is complete
//
// A plain value: used by one thread, the verb's.

#include <chrono>
#include <cstddef>

namespace pmu::tools {

class StateSettle {
 public:
  using Clock = std::chrono::steady_clock;
  explicit StateSettle(Clock::duration quiet) : quiet_(quiet) {}

  // `expected`: writers of the topic expected now (above); `heard`: distinct writers whose
  // samples (valid or not) have arrived so far.
  void observe(Clock::time_point now, std::size_t expected, std::size_t heard) {
    if (expected != expected_ || heard != heard_) last_change_ = now;
    expected_ = expected;
    heard_ = heard;
  }
  bool settled(Clock::time_point now) const {
    return heard_ > 0 && heard_ >= expected_ && now - last_change_ >= quiet_;
  }

 private:
  Clock::duration quiet_;
  std::size_t expected_ = 0;
  std::size_t heard_ = 0;
  Clock::time_point last_change_{};
};

}  // namespace pmu::tools
