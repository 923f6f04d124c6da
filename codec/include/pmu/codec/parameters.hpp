#pragma once
// The stored (non-volatile) parameters 0x10..0x1B, protocol v1.9 tables 8..18, with the
// ranges the spec allows a set to take. The table is the single source for encoding,
// decoding, validation in the service, and `pmuctl config set` names.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string_view>

#include "pmu/codec/ids.hpp"

namespace pmu::codec {

enum class Parameter : std::uint8_t {
  AvionicsVoltage,        // 0x10 V_A
  PayloadVoltage,         // 0x11 V_P
  ServoVoltage,           // 0x12 V_S
  BatteryVoltage,         // 0x13 V_B
  PacketPeriod,           // 0x14 PP
  PacketsStreamed,        // 0x15 PS
  TemperatureOffset,      // 0x16 T0
  UpperTemperatureLimit,  // 0x17 T_U
  PowerUpState,           // 0x18 S0
  CrankingTime,           // 0x19 CT
  CanAddress,             // 0x1B CA
};

enum class ParameterKind : std::uint8_t {
  Scaled,   // engineering value = raw / divisor (volts, seconds)
  Integer,  // engineering value = raw
  Mask,     // a bit mask; valid bits depend on the parameter (and for S0 on firmware)
};

struct ParameterSpec {
  Parameter parameter;
  PacketId packet;
  std::string_view name;  // contract name (interface.md `Config`)
  std::string_view unit;  // "V", "s", "degC", "" for masks and numbers
  ParameterKind kind;
  double divisor;         // raw = value * divisor (1 for Integer and Mask)
  std::uint32_t raw_min;  // inclusive range a set may carry, in raw units
  std::uint32_t raw_max;
  std::uint8_t width;  // bytes on the wire: 1, or 2 for CA
};

inline constexpr std::size_t kParameterCount = 11;
const ParameterSpec (&parameter_table() noexcept)[kParameterCount];

const ParameterSpec& spec_of(Parameter p) noexcept;
std::optional<Parameter> parameter_from_packet(PacketId packet) noexcept;
std::optional<Parameter> parameter_from_name(std::string_view name) noexcept;

// Engineering value of a raw parameter value as read from the device.
double parameter_value(Parameter p, std::uint32_t raw) noexcept;

// PP and CT are durations (unit "s"; tables 12 and 17). A duration as such a parameter's
// engineering value, ready for to_raw/encode_set: 1500 ms -> 1.5. NaN, which encoding
// refuses, for a parameter that is not a duration.
double duration_value(Parameter p, std::chrono::milliseconds d) noexcept;
// The duration a raw PP or CT value stands for: 15 -> 1500 ms; zero for other parameters.
std::chrono::milliseconds duration_of(Parameter p, std::uint32_t raw) noexcept;

}  // namespace pmu::codec
