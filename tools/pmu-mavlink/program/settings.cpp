#include "program/settings.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

namespace pmu::mavlink_bridge {

namespace {

struct Ctx {
  const std::string& source;

  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    // yaml-cpp marks are 0-based; editors count from 1.
    const int line = at.IsDefined() && at.Mark().line >= 0 ? at.Mark().line + 1 : 1;
    throw SettingsError(source + ":" + std::to_string(line) + ": " + what);
  }

  std::string text(const YAML::Node& n, const char* name) const {
    if (!n.IsScalar()) fail(n, std::string(name) + ": expected a value");
    return n.Scalar();
  }

  long integer(const YAML::Node& n, const char* name, long lo, long hi) const {
    const std::string s = text(n, name);
    std::size_t used = 0;
    long v = 0;
    try {
      v = std::stol(s, &used, 10);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || s.empty() || v < lo || v > hi)
      fail(n,
           std::string(name) + ": '" + s + "' is not a whole number " + std::to_string(lo) + ".." + std::to_string(hi));
    return v;
  }

  double number(const YAML::Node& n, const char* name) const {
    const std::string s = text(n, name);
    std::size_t used = 0;
    double v = NAN;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || s.empty() || !std::isfinite(v))
      fail(n, std::string(name) + ": '" + s + "' is not a number");
    return v;
  }
};

const std::map<std::string, std::uint32_t>& rate_names() {
  static const std::map<std::string, std::uint32_t> names{
      {"heartbeat", pmu::mavlink::msgid::kHeartbeat},
      {"battery_status", pmu::mavlink::msgid::kBatteryStatus},
      {"generator_status", pmu::mavlink::msgid::kGeneratorStatus},
      {"relay_status", pmu::mavlink::msgid::kRelayStatus},
  };
  return names;
}

// Hz into an interval: 0 = off, else 0.01..50 Hz (a radio link has no room for more).
std::optional<std::chrono::microseconds> interval_of(double hz) {
  if (hz == 0.0) return std::chrono::microseconds(0);
  if (!(hz >= 0.01 && hz <= 50.0)) return std::nullopt;
  return std::chrono::microseconds(static_cast<std::int64_t>(std::llround(1e6 / hz)));
}

}  // namespace

std::optional<std::uint32_t> rate_message(const std::string& name) {
  const auto it = rate_names().find(name);
  if (it == rate_names().end()) return std::nullopt;
  return it->second;
}

std::optional<std::string> apply_confirm_option(const std::string& rule, Settings& into) {
  const auto set = pmu::mavlink_params::confirm_set({rule});
  if (!set) return "--confirm: " + set.error();
  for (std::size_t i = 0; i < set->size(); ++i) into.confirm[i] = into.confirm[i] || (*set)[i];
  return std::nullopt;
}

std::optional<std::string> apply_rate_option(const std::string& text, Settings& into) {
  const auto eq = text.find('=');
  const std::string name = eq == std::string::npos ? text : text.substr(0, eq);
  const auto id = rate_message(name);
  if (!id) return "--rate " + text + ": NAME is one of heartbeat, battery_status, generator_status, relay_status";
  double hz = NAN;
  try {
    std::size_t used = 0;
    hz = std::stod(text.substr(eq + 1), &used);
    if (used != text.size() - eq - 1) hz = NAN;
  } catch (const std::exception&) {
  }
  const auto interval = std::isfinite(hz) ? interval_of(hz) : std::nullopt;
  if (eq == std::string::npos || !interval) return "--rate " + text + ": HZ is 0 (off) or 0.01..50";
  into.intervals[*id] = *interval;
  return std::nullopt;
}

void read_settings(const std::string& text, const std::string& source, Settings& into) {
  const Ctx c{source};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SettingsError(source + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (root.IsNull()) return;
  if (!root.IsMap()) c.fail(root, "expected a mapping of settings");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    if (key == "udp") {
      auto r = parse_udp_address(c.text(v, "udp"));
      if (auto* e = std::get_if<std::string>(&r)) c.fail(v, "udp: " + *e);
      into.udp = std::get<UdpAddress>(r);
    } else if (key == "serial") {
      auto r = parse_serial_address(c.text(v, "serial"));
      if (auto* e = std::get_if<std::string>(&r)) c.fail(v, "serial: " + *e);
      into.serial = std::get<SerialAddress>(r);
    } else if (key == "system_id") {
      into.system_id = static_cast<std::uint8_t>(c.integer(v, "system_id", 1, 255));
    } else if (key == "component_id") {
      into.component_id = static_cast<std::uint8_t>(c.integer(v, "component_id", 1, 255));
    } else if (key == "domain") {
      into.domain = static_cast<int>(c.integer(v, "domain", 0, 232));
    } else if (key == "vehicle") {
      into.vehicle = c.text(v, "vehicle");
    } else if (key == "qos_file") {
      into.qos_file = c.text(v, "qos_file");
    } else if (key == "security_dir") {
      into.security_dir = c.text(v, "security_dir");
    } else if (key == "identity") {
      into.identity = c.text(v, "identity");
    } else if (key == "signing_key") {
      into.signing_key = c.text(v, "signing_key");
      if (into.signing_key.empty()) c.fail(v, "signing_key: expected the key file's path");
    } else if (key == "battery_ids") {
      if (!v.IsMap()) c.fail(v, "battery_ids: expected pmu: and bms:");
      for (const auto& b : v) {
        const std::string which = b.first.as<std::string>();
        if (which == "pmu") {
          into.pmu_battery_id = static_cast<std::uint8_t>(c.integer(b.second, "battery_ids.pmu", 0, 253));
        } else if (which == "bms") {
          into.bms_battery_id = static_cast<std::uint8_t>(c.integer(b.second, "battery_ids.bms", 0, 254));
        } else {
          c.fail(b.first, "battery_ids: unknown key '" + which + "' (pmu, bms)");
        }
      }
    } else if (key == "rates") {
      if (!v.IsMap()) c.fail(v, "rates: expected NAME: HZ");
      for (const auto& r : v) {
        const std::string name = r.first.as<std::string>();
        const auto id = rate_message(name);
        if (!id)
          c.fail(r.first,
                 "rates: unknown message '" + name + "' (heartbeat, battery_status, generator_status, relay_status)");
        const auto interval = interval_of(c.number(r.second, name.c_str()));
        if (!interval) c.fail(r.second, "rates." + name + ": 0 (off) or 0.01..50 Hz");
        into.intervals[*id] = *interval;
      }
    } else if (key == "confirm") {
      if (!v.IsSequence()) c.fail(v, "confirm: expected a list of rule names ([engine_start, reset])");
      for (const auto& rule : v) {
        const auto set = pmu::mavlink_params::confirm_set({c.text(rule, "confirm")});
        if (!set) c.fail(rule, "confirm: " + set.error());
        for (std::size_t i = 0; i < set->size(); ++i) into.confirm[i] = into.confirm[i] || (*set)[i];
      }
    } else {
      c.fail(kv.first, "unknown key '" + key +
                           "' (udp, serial, system_id, component_id, domain, vehicle, qos_file, security_dir, "
                           "identity, signing_key, battery_ids, rates, confirm)");
    }
  }
}

}  // namespace pmu::mavlink_bridge
