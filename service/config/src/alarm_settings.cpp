#include "alarm_settings.hpp"

#include <algorithm>

#include "pmu/config/config.hpp"
#include "pmu/dds_settings/quoted.hpp"

namespace pmu::service {
namespace {

using dds::quoted;

constexpr const char* kKeys[] = {"limit", "deadband", "on_delay", "off_delay", "severity", "enabled"};

[[noreturn]] void fail(const std::string& source, const YAML::Node& at, const std::string& what) {
  // yaml-cpp marks are 0-based; editors count from 1.
  const int line = at.IsDefined() && at.Mark().line >= 0 ? at.Mark().line + 1 : 1;
  throw ConfigError(source + ":" + std::to_string(line) + ": " + what);
}

std::string codes_of(alarms::DeviceKind kind) {
  std::string s;
  for (const auto& row : alarms::alarm_table())
    if (alarms::applies_to(row, kind)) s += (s.empty() ? "" : ", ") + std::string(row.name);
  return s;
}

double number_at(const std::string& source, const YAML::Node& n, const std::string& what) {
  if (!n.IsScalar()) fail(source, n, what + " must be a number");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    fail(source, n, what + " must be a number, not " + quoted(n.Scalar()));
  }
}

// One field at a time through resolve(), so a refusal is reported at its own line, in
// resolve()'s words.
void check(const std::string& source, const YAML::Node& at, alarms::Code code, const alarms::AlarmOverride& one) {
  if (auto r = alarms::resolve(code, one); !r) fail(source, at, r.error());
}

alarms::AlarmOverride parse_override(const std::string& source, const YAML::Node& n, alarms::Code code) {
  const std::string name(alarms::to_string(code));
  if (n.IsNull()) return {};
  if (!n.IsMap()) fail(source, n, name + " must be a mapping, e.g. {limit: 20.5, on_delay: 10}");
  alarms::AlarmOverride o;
  for (const auto& kv : n) {
    const auto key = kv.first.Scalar();
    const auto& v = kv.second;
    alarms::AlarmOverride one;
    if (key == "limit") {
      one.limit = o.limit = number_at(source, v, name + ": limit");
    } else if (key == "deadband") {
      one.deadband = o.deadband = number_at(source, v, name + ": deadband");
    } else if (key == "on_delay") {
      one.on_delay_s = o.on_delay_s = number_at(source, v, name + ": on_delay");
    } else if (key == "off_delay") {
      one.off_delay_s = o.off_delay_s = number_at(source, v, name + ": off_delay");
    } else if (key == "severity") {
      const std::string s = v.IsScalar() ? v.Scalar() : std::string();
      if (s == "warning")
        one.severity = o.severity = alarms::Severity::Warning;
      else if (s == "critical")
        one.severity = o.severity = alarms::Severity::Critical;
      else
        fail(source, v, name + ": severity must be warning or critical" + (v.IsScalar() ? ", not " + quoted(s) : ""));
    } else if (key == "enabled") {
      bool b = false;
      if (!v.IsScalar() || !YAML::convert<bool>::decode(v, b))
        fail(source, v, name + ": enabled must be true or false" + (v.IsScalar() ? ", not " + quoted(v.Scalar()) : ""));
      one.enabled = o.enabled = b;
    } else {
      std::string known;
      for (const char* k : kKeys) known += std::string(known.empty() ? "" : ", ") + k;
      fail(source, kv.first, "unknown key " + quoted(key) + " in " + name + " (known: " + known + ")");
    }
    check(source, v, code, one);
  }
  return o;
}

}  // namespace

alarms::DeviceSettings parse_alarm_settings(const YAML::Node& n, alarms::DeviceKind kind, const std::string& source) {
  alarms::DeviceSettings settings;
  if (n.IsNull()) return settings;
  if (!n.IsMap())
    fail(source, n, "alarms must be a mapping of alarm code: settings, e.g. {battery_a_low_voltage: {limit: 20.5}}");
  for (const auto& kv : n) {
    const auto name = kv.first.Scalar();
    const auto code = alarms::code_named(name);
    if (!code)
      fail(source, kv.first,
           "unknown alarm code " + quoted(name) + " (alarms of a " + std::string(alarms::to_string(kind)) + ": " +
               codes_of(kind) + ")");
    if (!alarms::applies_to(alarms::spec_of(*code), kind)) {
      // resolve() says it in the words every such refusal uses.
      alarms::DeviceSettings only;
      only[*code].enabled = true;
      const auto r = alarms::resolve(kind, only);
      fail(source, kv.first, r ? name + ": not an alarm of a " + std::string(alarms::to_string(kind)) : r.error());
    }
    settings[*code] = parse_override(source, kv.second, *code);
  }
  if (auto r = alarms::resolve(kind, settings); !r) fail(source, n, r.error());
  return settings;
}

}  // namespace pmu::service
