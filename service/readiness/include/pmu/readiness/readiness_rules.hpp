#pragma once
// The readiness rules (interface.md 1.7), pure: what the service knows of each device and the
// latest state of each alarm in, the reasons out. A critical reason makes the vehicle not
// ready; a warning is shown and lets it fly.
//
//   device_not_online        critical  a device served (configured or found) is not ONLINE
//   bus_not_up               critical  a bus is ERROR_PASSIVE, BUS_OFF or DOWN (warning at
//                                      ERROR_WARNING), once per bus
//   firmware_below_minimum   critical  a PMU's firmware is older than its `min_firmware`, or
//                                      than its baseline's device.min_firmware (the higher)
//   config_differs           critical  a setting its `baseline:` file sets, once read from the
//                                      PMU, differs on the wire's value
//   serial_differs           critical  the PMU's serial, once read, is not its baseline's
//                                      device.serial: another unit answers at that address
//   <alarm code>             the alarm's severity, while it is not NORMAL: a critical blocks
//                                      until it has cleared and been acknowledged
//
// Reasons come sorted: critical first, then by bus, kind of source, device and code, so two
// reports of the same situation are equal and a reader sees the worst first.

#include <map>
#include <optional>
#include <tuple>
#include <vector>

#include "pmu/baseline/config_diff.hpp"
#include "pmu/session/device_state.hpp"

namespace pmu::service {

struct DeviceView {
  HealthState state = HealthState::Unknown;
  transport::BusState bus_state = transport::BusState::Up;
  std::optional<codec::FirmwareVersion> firmware;      // once read
  std::optional<codec::FirmwareVersion> min_firmware;  // the config's
  std::optional<std::uint16_t> serial;                 // once read
  baseline::Settings settings;                         // as last read; one not read yet is empty
  // The PMU's `baseline:` (interface.md 4.1), and its path for the description; none for a
  // device without one (a discovered PMU, a battery, an MPPT).
  std::optional<baseline::ConfigFile> baseline;
  std::string baseline_file;
};

// A PMU's settings as pmu::baseline compares them: Setting's order is codec::Parameter's,
// then outputs and generation.
baseline::Settings settings_of(const ConfigState& config);

// The settings of `d`'s baseline that differ from the device's, among those read: a setting
// not read yet is no drift.
std::vector<baseline::Difference> drift(const DeviceView& d);
// `d`'s serial, once read, is not its baseline's device.serial.
bool serial_differs(const DeviceView& d);
// The minimum `d`'s firmware must meet: the higher of the config's and the baseline's pin.
std::optional<codec::FirmwareVersion> min_firmware(const DeviceView& d);

struct ReadinessInput {
  std::map<std::tuple<std::string, DeviceKind, std::uint16_t>, DeviceView> devices;  // (bus, kind, address)
  std::vector<AlarmReport> alarms;  // the latest report of each alarm
};

std::vector<ReadinessReason> readiness_reasons(const ReadinessInput& input);

}  // namespace pmu::service
