#pragma once
// What the service knows of one PMU (and, canopen_state.hpp, of batteries and MPPTs), in codec terms. Conversion to the DDS types of
// interface.md happens in dds/ only; the rest of the service and its tests use these.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pmu/alarms/alarm.hpp"
#include "pmu/codec/decode.hpp"
#include "pmu/codec/parameters.hpp"
#include "pmu/energy/figures.hpp"
#include "pmu/idl_tables/device_key.hpp"
#include "pmu/session/canopen_state.hpp"
#include "pmu/transport/can_bus.hpp"

namespace pmu::service {

// "pmu", "battery", "mppt" (DeviceKind and DeviceKey: pmu/idl_tables/device_key.hpp).
const char* to_string(DeviceKind k) noexcept;

// Stored parameters as last read from (or verified on) the device, raw wire values.
struct ConfigState {
  std::array<std::optional<std::uint32_t>, codec::kParameterCount> raw{};
  std::optional<std::uint8_t> outputs;
  std::optional<bool> generation_enabled;

  bool complete() const noexcept {
    for (const auto& r : raw)
      if (!r) return false;
    return outputs.has_value() && generation_enabled.has_value();
  }
  double value(codec::Parameter p) const noexcept {
    const auto& r = raw[static_cast<std::size_t>(p)];
    return r ? codec::parameter_value(p, *r) : 0.0;
  }
};

struct InfoState {
  std::uint16_t serial_number = 0;
  codec::FirmwareInfo firmware;
  // The serial reply comes first: until the firmware reply, `firmware` reads 0.0, which is
  // no real version and would decode telemetry as pre-1.12 (no external temperatures).
  bool firmware_known = false;
};

enum class HealthState : std::uint8_t { Unknown, Online, Stale, Offline };
const char* to_string(HealthState s) noexcept;

// For people reading a log or a status: `last frame 3.5 s ago`, or `no frame yet` for an age
// below 0 (HealthReport's "never"), which is no age to print.
std::string last_frame_text(double age_s);

struct HealthReport {
  HealthState state = HealthState::Unknown;
  transport::BusState bus_state = transport::BusState::Up;
  double last_frame_age = -1;  // s; -1 = no frame yet
  std::uint64_t frames_received = 0;
  std::uint64_t frames_sent = 0;
  std::uint64_t decode_errors = 0;
  std::uint64_t bus_errors = 0;
  std::uint64_t rx_dropped = 0;
  std::uint64_t timeouts = 0;
  std::uint64_t reconnects = 0;
};

// An alarm that changed state (interface.md 1.6): the alarms room's Alarm, with where it
// belongs and its times on the wall clock.
struct AlarmReport {
  std::string bus;
  alarms::DeviceKind source = alarms::DeviceKind::Pmu;  // Pmu, Battery, Mppt, or Bus for the bus's own
  std::uint16_t device = 0;                             // the device's address, node or MPPT device id; 0 for the bus
  alarms::Code code{};
  alarms::Severity severity = alarms::Severity::Warning;
  alarms::AlarmState state = alarms::AlarmState::Normal;
  double value = 0;  // at the last change, in the table's unit; NaN for a flag or unknown
  double limit = 0;
  std::chrono::system_clock::time_point since{};  // the last change of state
  std::string message;                            // at most 42 characters
};

// The vehicle's readiness (interface.md 1.7): made by the ReadinessTracker from health,
// identity and alarms.
struct ReadinessReason {
  std::string code;  // an alarm's code, or a readiness code (device_not_online, ...)
  alarms::Severity severity = alarms::Severity::Critical;
  std::string bus;  // "" for the service's own
  alarms::DeviceKind source = alarms::DeviceKind::Pmu;
  std::uint16_t device = 0;
  std::string message;      // at most 42 characters
  std::string description;  // at most 127 characters: what to do about it
};
struct ReadinessReport {
  bool ready = true;                              // no critical reason
  std::chrono::system_clock::time_point since{};  // the last change of `ready`
  std::vector<ReadinessReason> reasons;           // critical first, then by bus, device, code
  bool warnings() const noexcept { return !reasons.empty(); }
};

}  // namespace pmu::service
