#include "pmu/codec/ids.hpp"

#include <array>

namespace pmu::codec {
namespace {

struct NamedPacket {
  PacketId id;
  std::string_view name;
};

// Names from interface.md (`pmuctl decode`): telemetry topics' last word, Config parameter
// names, and the command names.
constexpr std::array<NamedPacket, 26> kPackets{{
    {PacketId::Voltages, "voltages"},
    {PacketId::Currents, "currents"},
    {PacketId::BatteryEnergy, "battery_energy"},
    {PacketId::Temperatures, "temperatures"},
    {PacketId::Status, "status"},
    {PacketId::MeasurementRequest, "measurement_request"},
    {PacketId::AvionicsVoltage, "avionics_voltage"},
    {PacketId::PayloadVoltage, "payload_voltage"},
    {PacketId::ServoVoltage, "servo_voltage"},
    {PacketId::BatteryVoltage, "battery_voltage"},
    {PacketId::PacketPeriod, "packet_period"},
    {PacketId::PacketsStreamed, "packets_streamed"},
    {PacketId::TemperatureOffset, "temperature_offset"},
    {PacketId::UpperTemperatureLimit, "upper_temperature_limit"},
    {PacketId::PowerUpState, "power_up_state"},
    {PacketId::CrankingTime, "cranking_time"},
    {PacketId::CanAddress, "can_address"},
    {PacketId::Outputs, "outputs"},
    {PacketId::EnableOutputs, "enable_outputs"},
    {PacketId::DisableOutputs, "disable_outputs"},
    {PacketId::Generation, "generation"},
    {PacketId::EngineStart, "engine_start"},
    {PacketId::EngineStop, "engine_stop"},
    {PacketId::Reset, "reset"},
    {PacketId::Serial, "serial"},
    {PacketId::Firmware, "firmware"},
}};

}  // namespace

bool is_known_packet(std::uint8_t packet) noexcept {
  for (const auto& p : kPackets)
    if (static_cast<std::uint8_t>(p.id) == packet) return true;
  return false;
}

std::string_view packet_name(PacketId packet) noexcept {
  for (const auto& p : kPackets)
    if (p.id == packet) return p.name;
  return "unknown";
}

std::optional<PacketId> packet_from_name(std::string_view name) noexcept {
  for (const auto& p : kPackets)
    if (p.name == name) return p.id;
  return std::nullopt;
}

IdParse parse_id(std::uint32_t id, bool extended) noexcept {
  IdParse r;
  if (!extended || id > 0x1FFFFFFFu) {
    r.error = IdError::NotExtended;
    return r;
  }
  if ((id >> 24) != kGroupId) {
    r.error = IdError::ForeignGroup;
    return r;
  }
  r.raw_packet = static_cast<std::uint8_t>((id >> 16) & 0xFFu);
  if (!is_known_packet(r.raw_packet)) {
    r.error = IdError::UnknownPacket;
    return r;
  }
  r.id = PmuId{static_cast<PacketId>(r.raw_packet), static_cast<std::uint16_t>(id & 0xFFFFu)};
  return r;
}

}  // namespace pmu::codec
