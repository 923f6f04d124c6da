#pragma once
// The alarm codes and their defaults: one row per code, written once in alarm_table.cpp and
// read by the alarms, the settings' validation, the tests and whatever publishes or names
// them. The code text is part of the contract a ground station reads, so it never changes
// once published; a new alarm is a new code.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string_view>

namespace pmu::alarms {

enum class Code : std::uint8_t {
  ThermalShutdown,
  SoaShutdown,
  PayloadShed,
  BatteryALowVoltage,
  BatteryACriticalVoltage,
  BatteryBLowVoltage,
  BatteryBCriticalVoltage,
  InternalOverTemperature,
  StarterOverTemperature,
  GeneratorOverTemperature,
  BatteryAOverTemperature,
  BatteryBOverTemperature,
  GeneratorNotProducing,
  UncommandedEngineStop,
  BmsLowSoc,
  BmsCriticalSoc,
  CellLow,
  CellImbalance,
  BmsOverTemperature,
  MpptFault,
  DeviceStale,
  DeviceOffline,
  BusErrorPassive,
  BusOff,
};
inline constexpr std::size_t kCodeCount = 24;

// What an alarm set is built for. AnyDevice rows join the set of every PMU, battery and MPPT;
// a bus is not a device, so its set holds only the Bus rows.
enum class DeviceKind : std::uint8_t { Pmu, Battery, Mppt, Bus, AnyDevice };

enum class Severity : std::uint8_t { Warning, Critical };

// Flag: the input is a boolean (observe_flag). Above / Below: a value against the limit.
enum class Condition : std::uint8_t { Flag, Above, Below };

// Where a row's limit comes from: the device's document, or chosen here (the row's comment
// says why).
enum class Basis : std::uint8_t { Documented, Chosen };

struct AlarmSpec {
  Code code;
  std::string_view name;     // lower_snake, stable: "battery_a_low_voltage"
  std::string_view subject;  // the start of the message: "battery A"
  DeviceKind device;
  Severity severity;
  Condition condition;
  double limit;                         // in `unit`; 0 and unused for a flag
  std::string_view unit;                // "V", "degC", "%", "" for a flag
  int decimals;                         // digits after the point in messages
  double deadband;                      // in `unit`, >= 0: how far past the limit the value must come back
  std::chrono::milliseconds on_delay;   // the condition must hold this long to raise
  std::chrono::milliseconds off_delay;  // ... and be gone this long to clear
  Basis basis;
  // The PMU packets the row reads (codec::group_bit: 0x00 voltages, 0x03 temperatures, 0x04
  // status), so that a packet not received, stale or not monitored is a readiness reason of
  // its own (input_missing, interface.md 1.7) instead of an alarm that silently holds, and a
  // change of packets_streamed that drops one needs confirm (blind_monitoring, 2.2). 0 for
  // rows fed by the session's health, the bus, or CANopen frames.
  std::uint8_t packets;
};

const std::array<AlarmSpec, kCodeCount>& alarm_table() noexcept;
const AlarmSpec& spec_of(Code c) noexcept;
std::string_view to_string(Code c) noexcept;
// "battery_a_low_voltage" -> Code; nullopt for a name the table lacks.
std::optional<Code> code_named(std::string_view name) noexcept;

std::string_view to_string(DeviceKind k) noexcept;  // "pmu", "battery", "mppt", "bus", "any device"
std::string_view to_string(Severity s) noexcept;    // "warning", "critical"

// Whether a set for `kind` holds the row.
bool applies_to(const AlarmSpec& spec, DeviceKind kind) noexcept;

}  // namespace pmu::alarms
