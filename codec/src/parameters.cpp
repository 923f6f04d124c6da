#include "pmu/codec/parameters.hpp"

#include <cmath>
#include <limits>

#include "pmu/codec/packets.hpp"

namespace pmu::codec {
namespace {

using K = ParameterKind;

// Protocol v1.9, tables 8..18. Ranges are what a set may carry.
constexpr ParameterSpec kTable[kParameterCount] = {
    {Parameter::AvionicsVoltage, PacketId::AvionicsVoltage, "avionics_voltage", "V", K::Scaled, 10, 120, 240, 1},
    {Parameter::PayloadVoltage, PacketId::PayloadVoltage, "payload_voltage", "V", K::Scaled, 10, 120, 240, 1},
    {Parameter::ServoVoltage, PacketId::ServoVoltage, "servo_voltage", "V", K::Scaled, 10, 50, 120, 1},
    {Parameter::BatteryVoltage, PacketId::BatteryVoltage, "battery_voltage", "V", K::Scaled, 10, 200, 252, 1},
    // PP: 0.1..25.5 s; 0 is not allowed (it would stream continuously).
    {Parameter::PacketPeriod, PacketId::PacketPeriod, "packet_period", "s", K::Scaled, 10, 1, 255, 1},
    // PS: bits 0..4 (bits 5..7 "don't care").
    {Parameter::PacketsStreamed, PacketId::PacketsStreamed, "packets_streamed", "", K::Mask, 1, 0, 0x1F, 1},
    {Parameter::TemperatureOffset, PacketId::TemperatureOffset, "temperature_offset", "", K::Integer, 1, 0, 255, 1},
    {Parameter::UpperTemperatureLimit, PacketId::UpperTemperatureLimit, "upper_temperature_limit", "degC", K::Integer,
     1, 0, 255, 1},
    // S0: the defined bits depend on firmware (power_up_state_mask); 0x7F is the widest.
    {Parameter::PowerUpState, PacketId::PowerUpState, "power_up_state", "", K::Mask, 1, 0, 0x7F, 1},
    // CT: 0.1..25.5 s, and 0 disables the timeout (table 17).
    {Parameter::CrankingTime, PacketId::CrankingTime, "cranking_time", "s", K::Scaled, 10, 0, 255, 1},
    // CA: 0..65534; 65535 is the broadcast address (table 18).
    {Parameter::CanAddress, PacketId::CanAddress, "can_address", "", K::Integer, 1, 0, 65534, 2},
};

// The width is the packet's length in table 1; packets.hpp states it too, and they must agree.
constexpr bool widths_match_packet_table() noexcept {
  for (const auto& s : kTable) {
    // By row index, not find_packet's pointer: GCC's UBSan build does not take a pointer
    // compared with null as a constant expression.
    const std::uint8_t row = detail::kPacketIndex[static_cast<std::uint8_t>(s.packet)];
    if (row == detail::kNoRow || kPacketTable[row].length != s.width) return false;
  }
  return true;
}
static_assert(widths_match_packet_table());

}  // namespace

const ParameterSpec (&parameter_table() noexcept)[kParameterCount] { return kTable; }

const ParameterSpec& spec_of(Parameter p) noexcept { return kTable[static_cast<std::size_t>(p)]; }

std::optional<Parameter> parameter_from_packet(PacketId packet) noexcept {
  for (const auto& s : kTable)
    if (s.packet == packet) return s.parameter;
  return std::nullopt;
}

std::optional<Parameter> parameter_from_name(std::string_view name) noexcept {
  for (const auto& s : kTable)
    if (s.name == name) return s.parameter;
  return std::nullopt;
}

double parameter_value(Parameter p, std::uint32_t raw) noexcept {
  // Division (not multiplication by 0.1) so 123 -> 12.3 exactly as printed.
  return static_cast<double>(raw) / spec_of(p).divisor;
}

namespace {
bool is_duration(Parameter p) noexcept { return spec_of(p).unit == "s"; }
}  // namespace

double duration_value(Parameter p, std::chrono::milliseconds d) noexcept {
  if (!is_duration(p)) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(d.count()) / 1000.0;
}

std::chrono::milliseconds duration_of(Parameter p, std::uint32_t raw) noexcept {
  if (!is_duration(p)) return std::chrono::milliseconds::zero();
  return std::chrono::milliseconds(std::llround(parameter_value(p, raw) * 1000.0));
}

}  // namespace pmu::codec
