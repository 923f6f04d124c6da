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
//   input_missing            critical  an ONLINE PMU's packet that its alarms read is not
//                                      monitored, not received, or stale: one reason a packet.
//                                      Unknown is never OK (docs/safety.md H6, H3): an alarm
//                                      with no input holds NORMAL and would show all clear
//   <alarm code>             the alarm's severity, while it is not NORMAL: a critical blocks
//                                      until it has cleared and been acknowledged
//
// Reasons come sorted: critical first, then by bus, kind of source, device and code, so two
// reports of the same situation are equal and a reader sees the worst first.

#include <array>
#include <chrono>
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
  // A PMU's packets (codec::group_bit): those its alarms read (alarms::packets_read), those
  // the service gets from it (streaming: its PS as read, else the config's packets; polling:
  // the config's packets), when each last came (steady time, by packet id) and how old one
  // may be before it is stale (stale_periods x the period it comes at). None for a battery
  // or an MPPT, whose health covers their frames.
  std::uint8_t packets_needed = 0;
  std::uint8_t packets_monitored = 0;
  bool streaming = true;  // how the service gets them, for what the reason says to do
  std::array<std::optional<std::chrono::steady_clock::time_point>, 5> received{};
  std::chrono::steady_clock::duration max_age{};
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
  std::vector<AlarmReport> alarms;                                                   // the latest report of each alarm
  std::chrono::steady_clock::time_point now{};  // what `received` is judged against
};

std::vector<ReadinessReason> readiness_reasons(const ReadinessInput& input);

}  // namespace pmu::service
