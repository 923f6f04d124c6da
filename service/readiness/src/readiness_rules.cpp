#include "pmu/readiness/readiness_rules.hpp"

#include <algorithm>
#include <set>

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

}  // namespace

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
    if (d.bus_state != transport::BusState::Up && buses_reported.insert(bus).second) {
      const bool warning = d.bus_state == transport::BusState::ErrorWarning;
      out.push_back({"bus_not_up", warning ? Severity::Warning : Severity::Critical, bus, alarms::DeviceKind::Bus, 0,
                     bounded("bus " + bus + " " + std::string(transport::to_string(d.bus_state)), 42),
                     "The CAN controller reports errors: check termination, wiring and bit rate."});
    }
    if (d.firmware && d.min_firmware && d.firmware->ordinal() < d.min_firmware->ordinal())
      out.push_back({"firmware_below_minimum", Severity::Critical, bus, source_of(kind), address,
                     bounded(name + " firmware " + version(*d.firmware) + " < " + version(*d.min_firmware), 42),
                     "Update the unit's firmware, or lower min_firmware in the service's config."});
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
    return std::tie(cx, x.bus, x.source, x.device, x.code) < std::tie(cy, y.bus, y.source, y.device, y.code);
  });
  return out;
}

}  // namespace pmu::service
