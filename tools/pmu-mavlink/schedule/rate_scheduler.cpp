#include "schedule/rate_scheduler.hpp"

#include <cmath>

#include "pmu/mavlink/constants.hpp"

namespace pmu::mavlink_bridge {

RateScheduler::RateScheduler(std::map<std::uint32_t, std::chrono::microseconds> defaults) {
  for (const auto& [id, interval] : defaults) {
    Stream s;
    s.default_interval = interval.count() > 0 ? interval : std::chrono::microseconds(0);
    s.interval = s.default_interval;
    streams_.emplace(id, s);
  }
}

std::vector<std::uint32_t> RateScheduler::due(Clock::time_point now) {
  std::vector<std::uint32_t> out;
  for (auto& [id, s] : streams_) {
    if (s.interval.count() <= 0) continue;
    if (!s.started) {
      s.started = true;
      s.next = now;
    }
    if (now < s.next) continue;
    out.push_back(id);
    s.next += s.interval;
    if (s.next <= now) s.next = now + s.interval;
  }
  return out;
}

std::uint8_t RateScheduler::set_interval(float message_id, float interval_us, Clock::time_point now) {
  namespace result = pmu::mavlink::mav_result;
  if (!std::isfinite(message_id) || message_id < 0.0F || message_id > 16777215.0F ||
      std::floor(message_id) != message_id)
    return result::kUnsupported;
  const auto it = streams_.find(static_cast<std::uint32_t>(message_id));
  if (it == streams_.end()) return result::kUnsupported;
  if (!std::isfinite(interval_us) || std::floor(interval_us) != interval_us || interval_us < -1.0F)
    return result::kDenied;
  Stream& s = it->second;
  if (interval_us == -1.0F) {
    s.interval = std::chrono::microseconds(0);
  } else if (interval_us == 0.0F) {
    s.interval = s.default_interval;
  } else {
    s.interval = std::chrono::microseconds(static_cast<std::int64_t>(interval_us));
  }
  // The new rate starts now: a GCS that asks for a faster rate sees it at once.
  s.started = true;
  s.next = now;
  return result::kAccepted;
}

std::int64_t RateScheduler::interval_us(std::uint32_t message_id) const {
  const auto it = streams_.find(message_id);
  return it == streams_.end() ? -1 : it->second.interval.count();
}

}  // namespace pmu::mavlink_bridge
