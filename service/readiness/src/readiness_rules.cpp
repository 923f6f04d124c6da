#include "pmu/readiness/readiness_rules.hpp"

#include <algorithm>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <string>

#include "pmu/codec/messages.hpp"

namespace pmu::service {
namespace {

alarms::DeviceKind source_of(DeviceKind k) {
  switch (k) {
    case DeviceKind::Battery: return alarms::DeviceKind::Battery;
    case DeviceKind::Mppt: return alarms::DeviceKind::Mppt;
    case DeviceKind::Pmu: break;
  }
  return alarms::DeviceKind::Pmu;
}

// "PMU 1", "battery 2", "MPPT 0": the device as a message names it.
std::string device_name(DeviceKind k, std::uint16_t address) {
  const char* kind = k == DeviceKind::Battery ? "battery " : k == DeviceKind::Mppt ? "MPPT " : "PMU ";
  return kind + std::to_string(address);
}

std::string version(codec::FirmwareVersion v) { return std::to_string(v.major) + "." + std::to_string(v.minor); }

std::string bounded(std::string s, std::size_t n) {
  if (s.size() > n) s.resize(n);
  return s;
}

constexpr std::size_t kMessage = 42;       // ArduPilot's pre-arm text
constexpr std::size_t kDescription = 127;  // pmu::v5::ReadinessReason's bound

// "config differs: avionics_voltage, outputs", or as many names as fit and "+N more"; with a
// shorter lead when even one long name and its count do not fit.
std::string drift_message(const std::vector<baseline::Difference>& diffs) {
  for (const char* lead : {"config differs: ", "differs: "}) {
    for (std::size_t shown = diffs.size(); shown > 0; --shown) {
      std::string m = lead;
      for (std::size_t i = 0; i < shown; ++i)
        m += (i ? ", " : "") + std::string(baseline::setting_name(diffs[i].setting));
      if (shown < diffs.size()) m += " +" + std::to_string(diffs.size() - shown) + " more";
      if (m.size() <= kMessage) return m;
    }
  }
  return bounded("config differs: " + std::to_string(diffs.size()) + " settings", kMessage);
}

// A mask's value as its number alone ("0x0F"), when its names do not fit; any other value as
// value_text gives it, which is short.
std::string compact_value(baseline::Setting s, std::uint32_t raw) {
  using baseline::Setting;
  if (s != Setting::Outputs && s != Setting::PacketsStreamed && s != Setting::PowerUpState)
    return baseline::value_text(s, raw);
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(raw & 0xFF));
  return hex;
}

// "avionics_voltage 24.0 V->22.0 V; outputs ... . pmuctl config diff / apply pmu1.yaml": each
// item device->baseline while they fit, a mask by its number when its names do not, then the
// way to fix it.
std::string drift_description(const std::vector<baseline::Difference>& diffs, const std::string& file) {
  const auto slash = file.rfind('/');
  std::string name = slash == std::string::npos ? file : file.substr(slash + 1);
  if (name.empty() || name.size() > 24) name = "FILE";
  const std::string fix = ". pmuctl config diff / apply " + name;
  std::string items;
  std::size_t shown = 0;
  for (const auto& d : diffs) {
    const std::string setting(baseline::setting_name(d.setting));
    const std::size_t left = diffs.size() - shown - 1;
    const std::string more = left ? "; +" + std::to_string(left) + " more" : "";
    const std::size_t used = (items.empty() ? 0 : items.size() + 2) + more.size() + fix.size();
    const std::size_t room = used < kDescription ? kDescription - used : 0;
    std::string item =
        setting + " " + baseline::value_text(d.setting, *d.device) + "->" + baseline::value_text(d.setting, d.file);
    if (item.size() > room)
      item = setting + " " + compact_value(d.setting, *d.device) + "->" + compact_value(d.setting, d.file);
    if (item.size() > room) break;
    items += (items.empty() ? "" : "; ") + item;
    ++shown;
  }
  if (shown == 0)
    items = std::to_string(diffs.size()) + (diffs.size() == 1 ? " setting differs" : " settings differ") +
            " from the baseline";
  else if (shown < diffs.size())
    items += "; +" + std::to_string(diffs.size() - shown) + " more";
  return bounded(items + fix, kDescription);
}

// "PMU 1 temperatures not received": one reason for each packet the PMU's alarms read that
// the service does not have fresh. An alarm without its input neither raises nor clears, so
// it would stay NORMAL and look like all clear (docs/safety.md H6, H3).
void missing_inputs(const std::string& bus, DeviceKind kind, std::uint16_t address, const std::string& name,
                    const DeviceView& d, std::chrono::steady_clock::time_point now, std::vector<ReadinessReason>& out) {
  for (std::size_t i = 0; i < codec::kGroupNames.size(); ++i) {
    const auto& packet = codec::kGroupNames[i];
    if (!(d.packets_needed & packet.bit)) continue;
    const auto& at = d.received[i];
    const char* what = nullptr;
    std::string description;
    if (!(d.packets_monitored & packet.bit)) {
      what = "not monitored";
      description = d.streaming
                        ? "The PMU does not stream it, so its alarms cannot be judged: add it to packets_streamed "
                          "(pmuctl config set)."
                        : "The service does not poll it, so its alarms cannot be judged: add it to the "
                          "device's packets: in the service's config.";
    } else if (!at || now - *at > d.max_age) {
      what = at ? "stale" : "not received";
      description = d.streaming ? "Its alarms cannot be judged without it: check packet_period and packets_streamed "
                                  "(pmuctl config get)."
                                : "Its alarms cannot be judged without it: the PMU does not answer the service's "
                                  "polls for it.";
    } else {
      continue;
    }
    out.push_back({"input_missing", alarms::Severity::Critical, bus, source_of(kind), address,
                   bounded(name + " " + std::string(packet.name) + " " + what, kMessage),
                   bounded(std::move(description), kDescription)});
  }
}

}  // namespace

baseline::Settings settings_of(const ConfigState& config) {
  baseline::Settings s;
  for (std::size_t i = 0; i < codec::kParameterCount; ++i) s.raw[i] = config.raw[i];
  if (config.outputs) s[baseline::Setting::Outputs] = *config.outputs;
  if (config.generation_enabled) s[baseline::Setting::GenerationEnabled] = *config.generation_enabled ? 1u : 0u;
  return s;
}

std::vector<baseline::Difference> drift(const DeviceView& d) {
  if (!d.baseline) return {};
  auto diffs = baseline::differences(d.settings, *d.baseline);
  diffs.erase(std::remove_if(diffs.begin(), diffs.end(), [](const baseline::Difference& x) { return !x.device; }),
              diffs.end());
  return diffs;
}

bool serial_differs(const DeviceView& d) {
  return d.baseline && d.baseline->header.serial && d.serial && *d.serial != *d.baseline->header.serial;
}

std::optional<codec::FirmwareVersion> min_firmware(const DeviceView& d) {
  const auto pin = d.baseline ? d.baseline->header.min_firmware : std::nullopt;
  if (!pin) return d.min_firmware;
  if (!d.min_firmware) return pin;
  return pin->ordinal() > d.min_firmware->ordinal() ? pin : d.min_firmware;
}

std::vector<ReadinessReason> readiness_reasons(const ReadinessInput& in) {
  using alarms::Severity;
  std::vector<ReadinessReason> out;
  std::set<std::string> buses_reported;
  for (const auto& [key, d] : in.devices) {
    const auto& [bus, kind, address] = key;
    const std::string name = device_name(kind, address);
    if (d.state != HealthState::Online)
      out.push_back({"device_not_online", Severity::Critical, bus, source_of(kind), address,
                     bounded(name + " on " + bus + " " + to_string(d.state), 42),
                     "No recent frame from it: check its power and CAN wiring (pmuctl health)."});
    else
      missing_inputs(bus, kind, address, name, d, in.now, out);
    if (d.bus_state != transport::BusState::Up && buses_reported.insert(bus).second) {
      const bool warning = d.bus_state == transport::BusState::ErrorWarning;
      out.push_back({"bus_not_up", warning ? Severity::Warning : Severity::Critical, bus, alarms::DeviceKind::Bus, 0,
                     bounded("bus " + bus + " " + std::string(transport::to_string(d.bus_state)), 42),
                     "The CAN controller reports errors: check termination, wiring and bit rate."});
    }
    const auto minimum = min_firmware(d);
    if (d.firmware && minimum && d.firmware->ordinal() < minimum->ordinal()) {
      const bool pinned = minimum != d.min_firmware;  // the baseline's is the higher
      out.push_back({"firmware_below_minimum", Severity::Critical, bus, source_of(kind), address,
                     bounded(name + " firmware " + version(*d.firmware) + " < " + version(*minimum), kMessage),
                     pinned ? "Update the unit's firmware, or lower min_firmware in its baseline file."
                            : "Update the unit's firmware, or lower min_firmware in the service's config."});
    }
    if (serial_differs(d))
      out.push_back({"serial_differs", Severity::Critical, bus, source_of(kind), address,
                     bounded(name + " serial " + std::to_string(*d.serial) + ", baseline " +
                                 std::to_string(*d.baseline->header.serial),
                             kMessage),
                     "Another unit answers here: fit the baseline's unit, or make a baseline of this one "
                     "(pmuctl config snapshot)."});
    if (const auto diffs = drift(d); !diffs.empty())
      out.push_back({"config_differs", Severity::Critical, bus, source_of(kind), address, drift_message(diffs),
                     drift_description(diffs, d.baseline_file)});
  }
  for (const auto& a : in.alarms) {
    if (a.state == alarms::AlarmState::Normal) continue;
    const bool waiting = a.state == alarms::AlarmState::ClearedUnacknowledged;
    std::string description = waiting ? "Cleared; a critical alarm blocks until acknowledged: pmuctl alarms ack " +
                                            std::string(alarms::to_string(a.code)) + "."
                                      : "Active: see pmuctl alarms for its value and limit.";
    out.push_back({std::string(alarms::to_string(a.code)), a.severity, a.bus, a.source, a.device,
                   bounded(waiting ? a.message + " (unacknowledged)" : a.message, 42), std::move(description)});
  }
  std::sort(out.begin(), out.end(), [](const ReadinessReason& x, const ReadinessReason& y) {
    const int cx = x.severity == Severity::Critical ? 0 : 1, cy = y.severity == Severity::Critical ? 0 : 1;
    // The message last: one device's input_missing reasons differ only in it.
    return std::tie(cx, x.bus, x.source, x.device, x.code, x.message) <
           std::tie(cy, y.bus, y.source, y.device, y.code, y.message);
  });
  return out;
}

}  // namespace pmu::service
