#pragma once
// STATUSTEXT (253) lines for the service's alarms (interface.md 1.6) and readiness (1.7).
// Pure: samples in, texts out; AlarmTexts and ReadinessTexts keep what they said last, so
// each change is said once.
// One thread: the program's loop owns them.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "pmu/idl/alarms.h"
#include "pmu/mavlink/messages.hpp"

namespace pmu::mavlink_bridge {

// Severity of an alarm's line: an active critical is MAV_SEVERITY_CRITICAL and an active
// warning MAV_SEVERITY_WARNING (QGroundControl pops up ERROR and worse, shows the rest in its
// message list); a clear, an acknowledgement or a return to normal is NOTICE.
std::uint8_t alarm_severity(const pmu::v5::Alarm& alarm) noexcept;

// The line of an alarm in its present state: "PMU: battery A 20.1 V < 21.0 V" while active
// (the service's own message, which carries device and value), "PMU: ... acked" once
// acknowledged, "PMU cleared: <code>" when cleared but still unacknowledged, "PMU normal:
// <code>" back at normal. At most 50 characters, STATUSTEXT's field.
pmu::mavlink::Statustext alarm_text(const pmu::v5::Alarm& alarm);

class AlarmTexts {
 public:
  // The line to say for this sample, or nothing when its state is the one said last for its
  // key (a repeat of the same state, or NORMAL for an alarm never said).
  std::optional<pmu::mavlink::Statustext> on_sample(const pmu::v5::Alarm& alarm);
  // The instance was disposed (its device is gone): forget it.
  void forget(const pmu::v5::Alarm& key);

 private:
  using Key = std::tuple<std::string, std::string, std::uint16_t, int, std::string>;
  static Key key_of(const pmu::v5::Alarm& a);
  std::map<Key, pmu::v5::AlarmState> said_;
};

// The pre-arm lines of a readiness sample, in the form ground stations already show for an
// autopilot's pre-arm failures ("PreArm: <reason>", MAV_SEVERITY_CRITICAL as ArduPilot sends
// them): one line per reason carried, critical and warning alike, then "PreArm: +N more" when
// the service counted more reasons than it carried. A ready vehicle without reasons gives no
// line: the caller says "PMU: ready" (ReadinessTexts) and the command's ACK says the rest.
std::vector<pmu::mavlink::Statustext> prearm_lines(const pmu::v5::Readiness& readiness);

class ReadinessTexts {
 public:
  // "PMU: ready" (INFO) or "PMU: not ready, N reasons" (WARNING) when `ready` differs from
  // the one said last (the first sample is always said); nothing otherwise.
  std::optional<pmu::mavlink::Statustext> on_sample(const pmu::v5::Readiness& readiness);

 private:
  std::optional<bool> said_;
};

// `text` cut to STATUSTEXT's 50 characters.
std::string fit_statustext(std::string text);

}  // namespace pmu::mavlink_bridge
