#pragma once
// Which periodic messages are due, per message id, with MAV_CMD_SET_MESSAGE_INTERVAL (511)
// applied. Pure: the time is passed in (steady clock), so tests step it.
// One thread: the program's loop owns it.
#include <chrono>
#include <cstdint>
#include <map>
#include <vector>

namespace pmu::mavlink_bridge {

class RateScheduler {
 public:
  using Clock = std::chrono::steady_clock;

  // `defaults`: message id -> interval; zero or less disables the message by default.
  explicit RateScheduler(std::map<std::uint32_t, std::chrono::microseconds> defaults);

  // The messages due at `now`, each once, in message-id order; each is then due again one
  // interval after the time it was due (not after `now`), so a late loop keeps the rate
  // without sending a burst: a message more than one interval late is due once and rescheduled
  // from `now`. A message becomes due at once the first time it is asked about.
  std::vector<std::uint32_t> due(Clock::time_point now);

  // MAV_CMD_SET_MESSAGE_INTERVAL's param1 (message id) and param2 (-1 disable, 0 the default,
  // > 0 the interval in microseconds): the MAV_RESULT to answer. UNSUPPORTED for a message
  // this program does not stream; DENIED for any other param2 (below -1 or not a whole number).
  std::uint8_t set_interval(float message_id, float interval_us, Clock::time_point now);

  // The interval in force (zero: disabled), or -1 for a message not streamed here.
  std::int64_t interval_us(std::uint32_t message_id) const;

 private:
  struct Stream {
    std::chrono::microseconds default_interval{0};
    std::chrono::microseconds interval{0};
    bool started = false;
    Clock::time_point next{};
  };
  std::map<std::uint32_t, Stream> streams_;
};

}  // namespace pmu::mavlink_bridge
