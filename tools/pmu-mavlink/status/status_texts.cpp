#include "status/status_texts.hpp"

namespace pmu::mavlink_bridge {

namespace nm = pmu::mavlink;

std::string fit_statustext(std::string text) {
  if (text.size() > nm::Statustext::kTextLength) text.resize(nm::Statustext::kTextLength);
  return text;
}

std::uint8_t alarm_severity(const pmu::v5::Alarm& alarm) noexcept {
  switch (alarm.state()) {
    case pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED:
    case pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED:
      return alarm.severity() == pmu::v5::SEVERITY_CRITICAL ? nm::mav_severity::kCritical : nm::mav_severity::kWarning;
    case pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED:
    case pmu::v5::ALARM_NORMAL: break;
  }
  return nm::mav_severity::kNotice;
}

nm::Statustext alarm_text(const pmu::v5::Alarm& alarm) {
  nm::Statustext t;
  t.severity = alarm_severity(alarm);
  const std::string message =
      alarm.message().to_string().empty() ? alarm.code().to_string() : alarm.message().to_string();
  switch (alarm.state()) {
    case pmu::v5::ALARM_ACTIVE_UNACKNOWLEDGED: t.text = "PMU: " + message; break;
    case pmu::v5::ALARM_ACTIVE_ACKNOWLEDGED: t.text = "PMU: " + message + " acked"; break;
    case pmu::v5::ALARM_CLEARED_UNACKNOWLEDGED: t.text = "PMU cleared: " + alarm.code().to_string(); break;
    case pmu::v5::ALARM_NORMAL: t.text = "PMU normal: " + alarm.code().to_string(); break;
  }
  t.text = fit_statustext(t.text);
  return t;
}

AlarmTexts::Key AlarmTexts::key_of(const pmu::v5::Alarm& a) {
  return Key{a.vehicle().to_string(), a.bus().to_string(), a.device(), static_cast<int>(a.kind()),
             a.code().to_string()};
}

std::optional<nm::Statustext> AlarmTexts::on_sample(const pmu::v5::Alarm& alarm) {
  const Key key = key_of(alarm);
  const auto it = said_.find(key);
  const pmu::v5::AlarmState before = it == said_.end() ? pmu::v5::ALARM_NORMAL : it->second;
  said_[key] = alarm.state();
  if (alarm.state() == before) return std::nullopt;
  return alarm_text(alarm);
}

void AlarmTexts::forget(const pmu::v5::Alarm& key) { said_.erase(key_of(key)); }

std::vector<nm::Statustext> prearm_lines(const pmu::v5::Readiness& readiness) {
  std::vector<nm::Statustext> out;
  for (const auto& r : readiness.reasons()) {
    nm::Statustext t;
    t.severity = nm::mav_severity::kCritical;
    const std::string message = r.message().to_string().empty() ? r.code().to_string() : r.message().to_string();
    t.text = fit_statustext("PreArm: " + message);
    out.push_back(std::move(t));
  }
  if (readiness.reasons_total() > readiness.reasons().size()) {
    nm::Statustext t;
    t.severity = nm::mav_severity::kCritical;
    t.text = "PreArm: +" + std::to_string(readiness.reasons_total() - readiness.reasons().size()) + " more";
    out.push_back(std::move(t));
  }
  return out;
}

std::optional<nm::Statustext> ReadinessTexts::on_sample(const pmu::v5::Readiness& readiness) {
  if (said_ && *said_ == readiness.ready()) return std::nullopt;
  said_ = readiness.ready();
  nm::Statustext t;
  if (readiness.ready()) {
    t.severity = nm::mav_severity::kInfo;
    t.text = "PMU: ready";
  } else {
    t.severity = nm::mav_severity::kWarning;
    t.text = fit_statustext("PMU: not ready, " + std::to_string(readiness.reasons_total()) + " reasons");
  }
  return t;
}

}  // namespace pmu::mavlink_bridge
