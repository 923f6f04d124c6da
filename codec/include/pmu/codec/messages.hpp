#pragma once
// Typed contents of every PMU packet, in SI units (volts, amperes, degrees Celsius, rpm,
// mAh). Field names follow interface.md so the service and pmuctl map them one to one.

#include <array>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "pmu/codec/firmware.hpp"
#include "pmu/codec/packets.hpp"
#include "pmu/codec/parameters.hpp"

namespace pmu::codec {

// Output bits shared by 0x04 flag register 2, 0x18, 0x20, 0x21 and 0x22.
namespace output_bit {
inline constexpr std::uint8_t AvionicsServo = 1u << 0;
inline constexpr std::uint8_t Payload = 1u << 1;
inline constexpr std::uint8_t ChargerA = 1u << 2;
inline constexpr std::uint8_t ChargerB = 1u << 3;
inline constexpr std::uint8_t All = 0x0F;
}  // namespace output_bit

// Measurement group bits shared by 0x0F (MR) and 0x15 (PS).
namespace group_bit {
inline constexpr std::uint8_t Voltages = 1u << 0;
inline constexpr std::uint8_t Currents = 1u << 1;
inline constexpr std::uint8_t BatteryEnergy = 1u << 2;
inline constexpr std::uint8_t Temperatures = 1u << 3;
inline constexpr std::uint8_t Status = 1u << 4;
inline constexpr std::uint8_t All = 0x1F;
}  // namespace group_bit

// The contract's names of those bits (interface.md: pmuctl's verbs and `packets:` in the
// config, CommandReply reasons, the `*_on` fields), so every user of a name reads it here.
struct NamedBit {
  std::uint8_t bit;
  std::string_view name;
};

// Tables 19..21 (and flag register 2 of table 6), bit order.
inline constexpr std::array<NamedBit, 4> kOutputNames{{
    {output_bit::AvionicsServo, "avionics_servo"},
    {output_bit::Payload, "payload"},
    {output_bit::ChargerA, "charger_a"},
    {output_bit::ChargerB, "charger_b"},
}};

// Tables 7 and 13, bit order: a group is named after the packet it selects.
inline constexpr std::array<NamedBit, 5> kGroupNames{{
    {group_bit::Voltages, find_packet(PacketId::Voltages)->name},
    {group_bit::Currents, find_packet(PacketId::Currents)->name},
    {group_bit::BatteryEnergy, find_packet(PacketId::BatteryEnergy)->name},
    {group_bit::Temperatures, find_packet(PacketId::Temperatures)->name},
    {group_bit::Status, find_packet(PacketId::Status)->name},
}};

// "payload" -> output_bit::Payload; nullopt for a name the table lacks.
template <std::size_t N>
constexpr std::optional<std::uint8_t> bit_named(const std::array<NamedBit, N>& table, std::string_view name) noexcept {
  for (const auto& b : table)
    if (b.name == name) return b.bit;
  return std::nullopt;
}

// The names of the bits set in `mask`, in bit order, between `separator`s; "" for none.
// names_of(kOutputNames, 0x05) -> "avionics_servo,charger_a".
template <std::size_t N>
std::string names_of(const std::array<NamedBit, N>& table, std::uint8_t mask, std::string_view separator = ",") {
  std::string s;
  for (const auto& b : table) {
    if (!(mask & b.bit)) continue;
    if (!s.empty()) s += separator;
    s += b.name;
  }
  return s;
}

// A mask as a person reads it, the same in every view: "avionics_servo,payload (0x03)",
// "none (0x00)", a bit the table does not name as "bit7".
inline std::string mask_text(const NamedBit* names, std::size_t count, std::uint8_t mask) {
  std::string s;
  for (unsigned bit = 0; bit < 8; ++bit) {
    const auto b = static_cast<std::uint8_t>(1u << bit);
    if (!(mask & b)) continue;
    std::string name = "bit" + std::to_string(bit);
    for (std::size_t i = 0; i < count; ++i)
      if (names[i].bit == b) name = std::string(names[i].name);
    s += (s.empty() ? "" : ",") + name;
  }
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(mask));
  return (s.empty() ? std::string("none") : s) + " (" + hex + ")";
}
template <std::size_t N>
std::string mask_text(const std::array<NamedBit, N>& names, std::uint8_t mask) {
  return mask_text(names.data(), N, mask);
}

// S0 bits (table 16). Bits 4 and 6 exist only on newer firmware, see firmware.hpp.
namespace power_up_bit {
inline constexpr std::uint8_t AvionicsServo = 1u << 0;
inline constexpr std::uint8_t Payload = 1u << 1;
inline constexpr std::uint8_t ChargerA = 1u << 2;
inline constexpr std::uint8_t ChargerB = 1u << 3;
inline constexpr std::uint8_t BatteryDisconnectDetect = 1u << 4;
inline constexpr std::uint8_t PayloadShedding = 1u << 5;
inline constexpr std::uint8_t SoaManagement = 1u << 6;
}  // namespace power_up_bit

// Table 16: bits 0..3 are the outputs of tables 19..21, named as they are.
inline constexpr std::array<NamedBit, 7> kPowerUpNames{{
    {power_up_bit::AvionicsServo, kOutputNames[0].name},
    {power_up_bit::Payload, kOutputNames[1].name},
    {power_up_bit::ChargerA, kOutputNames[2].name},
    {power_up_bit::ChargerB, kOutputNames[3].name},
    {power_up_bit::BatteryDisconnectDetect, "battery_disconnect_detect"},
    {power_up_bit::PayloadShedding, "payload_shedding"},
    {power_up_bit::SoaManagement, "soa_management"},
}};
static_assert(kOutputNames[0].bit == power_up_bit::AvionicsServo && kOutputNames[3].bit == power_up_bit::ChargerB);

inline constexpr double kNoSensor = std::numeric_limits<double>::quiet_NaN();

struct Voltages {  // 0x00, table 2
  double avionics = 0, output_28v = 0, payload = 0, servo = 0, battery_a = 0, battery_b = 0, generator = 0;
};

struct Currents {  // 0x01, table 3
  double avionics = 0, output_28v = 0, payload = 0, servo = 0, battery_a = 0, battery_b = 0;
};

struct BatteryEnergy {  // 0x02, table 4
  std::int16_t battery_a_mah = 0, battery_b_mah = 0;
};

struct Temperatures {  // 0x03, table 5; NaN = "no sensor" (-128 on the wire)
  double internal = 0, battery_a = kNoSensor, battery_b = kNoSensor, generator = kNoSensor, starter = 0;
};

struct Status {  // 0x04 "Miscellaneous", table 6
  std::uint16_t generator_rpm = 0;
  bool generation_enabled = false;
  bool thermal_shutdown = false;
  bool soa_shutdown = false;  // bit 6 from firmware 1.16
  bool start_button = false;  // bit 6 before firmware 1.16
  bool payload_shed = false;
  bool starter_ready = false;
  std::uint8_t outputs = 0;  // flag register 2, output_bit::*
  FlagInterpretation interpretation{Bit6Meaning::SoaShutdown, false};

  bool avionics_servo_on() const noexcept { return outputs & output_bit::AvionicsServo; }
  bool payload_on() const noexcept { return outputs & output_bit::Payload; }
  bool charger_a_on() const noexcept { return outputs & output_bit::ChargerA; }
  bool charger_b_on() const noexcept { return outputs & output_bit::ChargerB; }
};

struct MeasurementRequest {  // 0x0F, table 7
  std::uint8_t groups = group_bit::All;
};

struct ParameterValue {  // 0x10..0x1B: a set, or the device's answer to a get
  Parameter parameter = Parameter::AvionicsVoltage;
  std::uint32_t raw = 0;
  double value = 0;  // engineering units of spec_of(parameter).unit
};

struct OutputStates {  // 0x20, table 19
  std::uint8_t mask = 0;
};
struct EnableOutputs {  // 0x21, table 20
  std::uint8_t mask = 0;
};
struct DisableOutputs {  // 0x22, table 21
  std::uint8_t mask = 0;
};
struct GenerationState {  // 0x23, table 22
  bool enabled = false;
};
struct SerialNumber {  // 0x30, table 23
  std::uint16_t serial_number = 0;
};
struct FirmwareInfo {  // 0x31, table 24
  std::uint8_t firmware_major = 0, firmware_minor = 0, build_day = 0, build_month = 0;
  std::uint16_t build_year = 0;
  FirmwareVersion version() const noexcept { return {firmware_major, firmware_minor}; }
};

// A frame with no payload: a zero-length get, the 0x0F "all measurements" form, or the
// data-less commands 0x24..0x26.
struct NoPayload {};

using Payload =
    std::variant<NoPayload, Voltages, Currents, BatteryEnergy, Temperatures, Status, MeasurementRequest, ParameterValue,
                 OutputStates, EnableOutputs, DisableOutputs, GenerationState, SerialNumber, FirmwareInfo>;

}  // namespace pmu::codec
