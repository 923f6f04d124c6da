#include "pmu/alarms/settings.hpp"

#include <cmath>
#include <cstdio>

namespace pmu::alarms {
namespace {

using Unexpected = codec::Unexpected<std::string>;

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string problem(Code code, const char* field, const std::string& what) {
  return std::string(to_string(code)) + ": " + field + " " + what;
}

std::chrono::steady_clock::duration to_duration(double seconds) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

// The empty string when `seconds` is a delay the alarm can run with.
std::string delay_problem(double seconds) {
  if (!std::isfinite(seconds)) return "is not a number of seconds";
  if (seconds < 0) return number(seconds) + " s is negative";
  if (seconds > kMaxDelaySeconds) return number(seconds) + " s is longer than a day";
  return {};
}

}  // namespace

AlarmConfig default_config(Code code) noexcept {
  const AlarmSpec& s = spec_of(code);
  AlarmConfig c;
  c.code = code;
  c.severity = s.severity;
  c.limit = s.limit;
  c.deadband = s.deadband;
  c.on_delay = s.on_delay;
  c.off_delay = s.off_delay;
  return c;
}

codec::Result<AlarmConfig, std::string> resolve(Code code, const AlarmOverride& o) {
  AlarmConfig c = default_config(code);
  const bool flag = spec_of(code).condition == Condition::Flag;
  if (o.limit) {
    if (flag) return Unexpected{problem(code, "limit", "cannot be set: the alarm is a flag")};
    if (!std::isfinite(*o.limit)) return Unexpected{problem(code, "limit", "is not a finite number")};
    c.limit = *o.limit;
  }
  if (o.deadband) {
    if (flag) return Unexpected{problem(code, "deadband", "cannot be set: the alarm is a flag")};
    if (!std::isfinite(*o.deadband)) return Unexpected{problem(code, "deadband", "is not a finite number")};
    if (*o.deadband < 0) return Unexpected{problem(code, "deadband", number(*o.deadband) + " is negative")};
    c.deadband = *o.deadband;
  }
  if (o.on_delay_s) {
    if (auto p = delay_problem(*o.on_delay_s); !p.empty()) return Unexpected{problem(code, "on_delay", p)};
    c.on_delay = to_duration(*o.on_delay_s);
  }
  if (o.off_delay_s) {
    if (auto p = delay_problem(*o.off_delay_s); !p.empty()) return Unexpected{problem(code, "off_delay", p)};
    c.off_delay = to_duration(*o.off_delay_s);
  }
  if (o.severity) c.severity = *o.severity;
  if (o.enabled) c.enabled = *o.enabled;
  return c;
}

codec::Result<std::vector<AlarmConfig>, std::string> resolve(DeviceKind kind, const DeviceSettings& settings) {
  std::vector<AlarmConfig> out;
  for (const auto& row : alarm_table()) {
    const AlarmOverride& o = settings[row.code];
    if (!applies_to(row, kind)) {
      if (!o.empty()) return Unexpected{std::string(row.name) + ": not an alarm of a " + std::string(to_string(kind))};
      continue;
    }
    auto c = resolve(row.code, o);
    if (!c) return Unexpected{c.error()};
    out.push_back(*c);
  }
  return out;
}

std::uint8_t packets_read(const DeviceSettings& settings) {
  const auto rows = resolve(DeviceKind::Pmu, settings);
  std::uint8_t packets = 0;
  for (const auto& row : alarm_table())
    if (applies_to(row, DeviceKind::Pmu)) packets = static_cast<std::uint8_t>(packets | row.packets);
  if (!rows.ok()) return packets;
  packets = 0;
  for (const auto& a : *rows)
    if (a.enabled) packets = static_cast<std::uint8_t>(packets | a.spec().packets);
  return packets;
}

}  // namespace pmu::alarms
