#pragma once
// One alarm's state machine, after ISA-18.2: NORMAL, ACTIVE_UNACKNOWLEDGED,
// ACTIVE_ACKNOWLEDGED, CLEARED_UNACKNOWLEDGED.
//
// The condition (value past the limit, or the flag set) must hold for on_delay to raise the
// alarm, and be gone (the value back past the limit by the deadband, or the flag clear) for
// off_delay to clear it; anything else in between restarts the wait. A warning does not
// latch: when it clears it is NORMAL, acknowledged or not. A critical latches: cleared before
// anyone acknowledged it, it waits in CLEARED_UNACKNOWLEDGED until someone does.
//
// Pure: time comes in with every call, and nothing here throws or allocates after
// construction. Every input returns whether the state changed, so a publisher writes only
// then; value(), limit() and message() are those of the last change.

#include <array>
#include <chrono>
#include <optional>
#include <string_view>

#include "pmu/alarms/settings.hpp"

namespace pmu::alarms {

using Time = std::chrono::steady_clock::time_point;

enum class AlarmState : std::uint8_t { Normal, ActiveUnacknowledged, ActiveAcknowledged, ClearedUnacknowledged };
std::string_view to_string(AlarmState s) noexcept;  // "NORMAL", "ACTIVE_UNACKNOWLEDGED", ...

// What an acknowledge did, so a command can say so in its reply. NotFound comes only from an
// AlarmSet: the device has no such alarm (or it is disabled).
enum class AckResult : std::uint8_t { Acknowledged, NothingToAcknowledge, NotFound };
std::string_view to_string(AckResult r) noexcept;

inline constexpr std::size_t kMaxMessageLength = 42;

class Alarm {
 public:
  explicit Alarm(const AlarmConfig& config) noexcept;

  // A measured value in the row's unit (for a flag, non-zero is set); NaN (not measured)
  // holds the state and restarts any wait, so it never raises nor clears.
  bool observe(double value, Time now) noexcept;
  // A flag's input; for a value alarm it is observe(1 or 0).
  bool observe_flag(bool set, Time now) noexcept;
  // Lets a wait that has run out take effect without a new input.
  bool tick(Time now) noexcept;
  AckResult acknowledge(Time now) noexcept;

  Code code() const noexcept { return config_.code; }
  Severity severity() const noexcept { return config_.severity; }
  AlarmState state() const noexcept { return state_; }
  const AlarmConfig& config() const noexcept { return config_; }
  // The value and the limit at the last change (NaN before the first one).
  double value() const noexcept { return value_at_change_; }
  double limit() const noexcept { return config_.limit; }
  // The time of the last change of state; the construction time (Time{}) before the first.
  Time since() const noexcept { return since_; }
  // At most kMaxMessageLength characters: "battery A 20.1 V < 21.0 V", "thermal shutdown".
  std::string_view message() const noexcept { return {message_.data(), message_length_}; }

 private:
  // What the last input said about the condition.
  enum class Reading : std::uint8_t { Unknown, Holds, Gone, Between };

  Reading classify(double value) const noexcept;
  bool step(Time now) noexcept;
  bool set_state(AlarmState s, Time now) noexcept;
  void compose_message() noexcept;

  AlarmConfig config_;
  AlarmState state_ = AlarmState::Normal;
  bool condition_ = false;  // the debounced condition: raised and not yet cleared
  double last_value_;
  std::optional<Time> waiting_since_;  // since when the reading has said the condition changed
  double value_at_change_;
  Time since_{};
  std::array<char, kMaxMessageLength + 1> message_{};
  std::size_t message_length_ = 0;
};

}  // namespace pmu::alarms
