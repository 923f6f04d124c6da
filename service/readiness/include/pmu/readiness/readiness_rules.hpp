#pragma once
// The readiness rules (interface.md 1.7), pure: what the service knows of each device and the
// latest state of each alarm in, the reasons out. A critical reason makes the vehicle not
// ready; a warning is shown and lets it fly.
//
//   device_not_online        critical  a device served (configured or found) is not ONLINE
//   bus_not_up               critical  a bus is ERROR_PASSIVE, BUS_OFF or DOWN (warning at
//                                      ERROR_WARNING), once per bus
//   firmware_below_minimum   critical  a PMU's firmware is older than its `min_firmware`
//   <alarm code>             the alarm's severity, while it is not NORMAL: a critical blocks
//                                      until it has cleared and been acknowledged
//
// Reasons come sorted: critical first, then by bus, kind of source, device and code, so two
// reports of the same situation are equal and a reader sees the worst first.

#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include "pmu/session/device_state.hpp"

namespace pmu::service {

struct DeviceView {
  HealthState state = HealthState::Unknown;
  transport::BusState bus_state = transport::BusState::Up;
  std::optional<codec::FirmwareVersion> firmware;      // once read
  std::optional<codec::FirmwareVersion> min_firmware;  // the config's
};

struct ReadinessInput {
  std::map<std::tuple<std::string, DeviceKind, std::uint16_t>, DeviceView> devices;  // (bus, kind, address)
  std::vector<AlarmReport> alarms;  // the latest report of each alarm
};

std::vector<ReadinessReason> readiness_reasons(const ReadinessInput& input);

}  // namespace pmu::service
