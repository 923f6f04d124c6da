#include "pmu/alarms/alarm.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace pmu::alarms {

std::string_view to_string(AlarmState s) noexcept {
  switch (s) {
    case AlarmState::Normal: return "NORMAL";
    case AlarmState::ActiveUnacknowledged: return "ACTIVE_UNACKNOWLEDGED";
    case AlarmState::ActiveAcknowledged: return "ACTIVE_ACKNOWLEDGED";
    case AlarmState::ClearedUnacknowledged: return "CLEARED_UNACKNOWLEDGED";
  }
  return "?";
}

std::string_view to_string(AckResult r) noexcept {
  switch (r) {
    case AckResult::Acknowledged: return "acknowledged";
    case AckResult::NothingToAcknowledge: return "nothing to acknowledge";
    case AckResult::NotFound: return "no such alarm";
  }
  return "?";
}

Alarm::Alarm(const AlarmConfig& config) noexcept
    : config_(config),
      last_value_(std::numeric_limits<double>::quiet_NaN()),
      value_at_change_(std::numeric_limits<double>::quiet_NaN()) {}

// The limit itself belongs to the side that is not an alarm, so a deadband of 0 leaves no
// value between raising and clearing.
Alarm::Reading Alarm::classify(double value) const noexcept {
  if (std::isnan(value)) return Reading::Unknown;
  const double limit = config_.limit;
  const double band = config_.deadband;
  switch (config_.spec().condition) {
    case Condition::Flag: return value != 0 ? Reading::Holds : Reading::Gone;
    case Condition::Above:
      if (value > limit) return Reading::Holds;
      return value <= limit - band ? Reading::Gone : Reading::Between;
    case Condition::Below:
      if (value < limit) return Reading::Holds;
      return value >= limit + band ? Reading::Gone : Reading::Between;
  }
  return Reading::Unknown;
}

bool Alarm::observe(double value, Time now) noexcept {
  const Reading reading = classify(value);
  if (!std::isnan(value)) last_value_ = value;
  // Only a reading that says the opposite of the debounced condition starts (or continues)
  // the wait; anything else, the deadband and "not measured" included, restarts it.
  const bool opposes = condition_ ? reading == Reading::Gone : reading == Reading::Holds;
  if (!opposes)
    waiting_since_.reset();
  else if (!waiting_since_)
    waiting_since_ = now;
  return step(now);
}

bool Alarm::observe_flag(bool set, Time now) noexcept { return observe(set ? 1.0 : 0.0, now); }

bool Alarm::tick(Time now) noexcept { return step(now); }

bool Alarm::step(Time now) noexcept {
  if (!waiting_since_) return false;
  const auto delay = condition_ ? config_.off_delay : config_.on_delay;
  if (now - *waiting_since_ < delay) return false;
  waiting_since_.reset();
  condition_ = !condition_;
  if (condition_) return set_state(AlarmState::ActiveUnacknowledged, now);
  const bool latches = config_.severity == Severity::Critical && state_ == AlarmState::ActiveUnacknowledged;
  return set_state(latches ? AlarmState::ClearedUnacknowledged : AlarmState::Normal, now);
}

AckResult Alarm::acknowledge(Time now) noexcept {
  switch (state_) {
    case AlarmState::ActiveUnacknowledged:
      set_state(AlarmState::ActiveAcknowledged, now);
      return AckResult::Acknowledged;
    case AlarmState::ClearedUnacknowledged: set_state(AlarmState::Normal, now); return AckResult::Acknowledged;
    case AlarmState::Normal:
    case AlarmState::ActiveAcknowledged: break;
  }
  return AckResult::NothingToAcknowledge;
}

bool Alarm::set_state(AlarmState s, Time now) noexcept {
  if (s == state_) return false;
  state_ = s;
  since_ = now;
  value_at_change_ = last_value_;
  compose_message();
  return true;
}

void Alarm::compose_message() noexcept {
  const AlarmSpec& s = config_.spec();
  const int subject_length = static_cast<int>(s.subject.size());
  const int unit_length = static_cast<int>(s.unit.size());
  char* out = message_.data();
  const std::size_t size = message_.size();
  int n = 0;
  if (s.condition == Condition::Flag) {
    n = condition_ ? std::snprintf(out, size, "%.*s", subject_length, s.subject.data())
                   : std::snprintf(out, size, "%.*s cleared", subject_length, s.subject.data());
  } else if (condition_) {
    const char op = s.condition == Condition::Above ? '>' : '<';
    n = std::snprintf(out, size, "%.*s %.*f %.*s %c %.*f %.*s", subject_length, s.subject.data(), s.decimals,
                      value_at_change_, unit_length, s.unit.data(), op, s.decimals, config_.limit, unit_length,
                      s.unit.data());
  } else {
    n = std::snprintf(out, size, "%.*s back to %.*f %.*s", subject_length, s.subject.data(), s.decimals,
                      value_at_change_, unit_length, s.unit.data());
  }
  message_length_ = n < 0 ? 0 : std::min(static_cast<std::size_t>(n), kMaxMessageLength);
}

}  // namespace pmu::alarms
