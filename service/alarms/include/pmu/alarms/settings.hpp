#pragma once
// Per-device alarm settings: what a site changes of the table's defaults, and the total
// function that merges them over the defaults. The config room reads the YAML into these
// structs, calls resolve() and puts FILE:LINE before an error; nothing here reads a file.

#include <array>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "pmu/alarms/alarm_table.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::alarms {

// Unset fields keep the table's default. Delays in seconds, as a config file writes them.
struct AlarmOverride {
  std::optional<double> limit;
  std::optional<double> deadband;
  std::optional<double> on_delay_s;
  std::optional<double> off_delay_s;
  std::optional<Severity> severity;
  std::optional<bool> enabled;

  bool empty() const noexcept { return !limit && !deadband && !on_delay_s && !off_delay_s && !severity && !enabled; }
};

// One device's overrides, by code.
struct DeviceSettings {
  std::array<AlarmOverride, kCodeCount> overrides{};

  AlarmOverride& operator[](Code c) noexcept { return overrides[static_cast<std::size_t>(c)]; }
  const AlarmOverride& operator[](Code c) const noexcept { return overrides[static_cast<std::size_t>(c)]; }
};

// One alarm as it runs: the table's row with a device's overrides applied, checked.
struct AlarmConfig {
  Code code = Code::ThermalShutdown;
  Severity severity = Severity::Warning;
  double limit = 0;
  double deadband = 0;
  std::chrono::steady_clock::duration on_delay{};
  std::chrono::steady_clock::duration off_delay{};
  bool enabled = true;  // false: the device's AlarmSet leaves it out

  const AlarmSpec& spec() const noexcept { return spec_of(code); }
};

// The longest delay a setting may ask for. Past a day an alarm is no longer an alarm, and
// the bound keeps the conversion to steady_clock ticks in range.
inline constexpr double kMaxDelaySeconds = 86400;

// The defaults of `code`, no override.
AlarmConfig default_config(Code code) noexcept;

// `code`'s row with `o` applied, or an error naming the code and the field:
// "battery_a_low_voltage: deadband -0.5 is negative". A flag has no limit or deadband to set.
codec::Result<AlarmConfig, std::string> resolve(Code code, const AlarmOverride& o);

// Every row that applies to `kind`, disabled ones included (enabled = false), with
// `settings` applied; an error for the first bad override, or for an override of a code that
// does not apply to `kind` ("cell_low: not an alarm of a pmu").
codec::Result<std::vector<AlarmConfig>, std::string> resolve(DeviceKind kind, const DeviceSettings& settings);

// The PMU packets (codec::group_bit) the enabled rows of a PMU with `settings` read: what the
// service must receive from it for its alarms to judge anything. Settings resolve() refuses
// count as the table's defaults, as AlarmFeed runs them.
std::uint8_t packets_read(const DeviceSettings& settings);

}  // namespace pmu::alarms
