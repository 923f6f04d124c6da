#include "pmuctl/view/alarm_marker.hpp"

#include <cmath>
#include <tuple>

namespace pmu::tools {
namespace {

nlohmann::ordered_json number_or_null(float v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

// Larger is worse (alarm_marker's order); the code breaks ties the other way round, so that
// one device's marker does not flip between equal alarms as their samples come.
std::tuple<bool, bool, bool> badness(const AlarmEntry& a) {
  const bool active = a.state == AlarmStatus::ActiveUnacknowledged || a.state == AlarmStatus::ActiveAcknowledged;
  return {a.critical, active, a.state != AlarmStatus::ActiveAcknowledged};
}

const char* ack_text(AlarmStatus s) {
  switch (s) {
    case AlarmStatus::ActiveAcknowledged: return "acked";
    case AlarmStatus::ClearedUnacknowledged: return "cleared unacked";
    case AlarmStatus::ActiveUnacknowledged:
    case AlarmStatus::Normal: break;
  }
  return "unacked";
}

}  // namespace

const char* to_string(AlarmStatus s) {
  switch (s) {
    case AlarmStatus::ActiveUnacknowledged: return "ACTIVE_UNACKNOWLEDGED";
    case AlarmStatus::ActiveAcknowledged: return "ACTIVE_ACKNOWLEDGED";
    case AlarmStatus::ClearedUnacknowledged: return "CLEARED_UNACKNOWLEDGED";
    case AlarmStatus::Normal: break;
  }
  return "NORMAL";
}

std::string alarm_source(const AlarmEntry& a) {
  std::string s = a.vehicle.empty() ? std::string() : a.vehicle + "/";
  s += a.bus;
  if (a.kind == "bus") return s;
  return s + "/" + (a.kind == "pmu" ? std::string() : a.kind) + std::to_string(a.device);
}

nlohmann::ordered_json alarm_json(const AlarmEntry& a, int contract) {
  return nlohmann::ordered_json{{"topic", "alarms"},
                                {"vehicle", a.vehicle},
                                {"bus", a.bus},
                                {"kind", a.kind},
                                {"device", a.device},
                                {"code", a.code},
                                {"severity", a.critical ? "critical" : "warning"},
                                {"state", to_string(a.state)},
                                {"value", number_or_null(a.value)},
                                {"limit", number_or_null(a.limit)},
                                {"since", static_cast<double>(a.since) / 1e9},
                                {"message", a.message},
                                {"contract", contract}};
}

std::string alarm_marker(const std::vector<AlarmEntry>& alarms) {
  const AlarmEntry* worst = nullptr;
  std::size_t count = 0;
  for (const auto& a : alarms) {
    if (a.state == AlarmStatus::Normal) continue;
    ++count;
    if (!worst || badness(a) > badness(*worst) || (badness(a) == badness(*worst) && a.code < worst->code)) worst = &a;
  }
  if (!worst) return {};
  return "ALARM " + std::to_string(count) + (worst->critical ? " CRIT " : " WARN ") + ack_text(worst->state) + " (" +
         worst->code + ")";
}

std::vector<AlarmEntry> alarms_of(const std::vector<AlarmEntry>& alarms, const std::string& source) {
  std::vector<AlarmEntry> of;
  for (const auto& a : alarms)
    if (alarm_source(a) == source) of.push_back(a);
  return of;
}

}  // namespace pmu::tools
