#pragma once
// Table 1 of protocol v1.9 as data: every packet's contract name, the length of a frame
// carrying values and whether a zero-length frame is a get. packet_name(), data_length(),
// has_zero_length_get() and the decoder's length check all read this one table, so adding
// or correcting a packet is one row.

#include <array>
#include <cstdint>
#include <string_view>

#include "pmu/codec/ids.hpp"

namespace pmu::codec {

struct PacketSpec {
  PacketId id;
  std::string_view name;  // interface.md (`pmuctl decode`, topic and Config names)
  std::uint8_t length;    // "Length" column; 0 for the data-less commands 0x24..0x26
  bool zero_length_get;   // a zero-length frame asks for the current value
};

// Protocol v1.9 table 1. Zero-length gets: every id up to 0x20 (table 1's rule), plus 0x23
// (section 5.21 says so although the rule stops at 0x20), 0x30 and 0x31; 0x21/0x22 have none.
inline constexpr std::array<PacketSpec, 26> kPacketTable{{
    {PacketId::Voltages, "voltages", 7, true},
    {PacketId::Currents, "currents", 6, true},
    {PacketId::BatteryEnergy, "battery_energy", 4, true},
    {PacketId::Temperatures, "temperatures", 5, true},
    {PacketId::Status, "status", 5, true},
    {PacketId::MeasurementRequest, "measurement_request", 1, true},
    {PacketId::AvionicsVoltage, "avionics_voltage", 1, true},
    {PacketId::PayloadVoltage, "payload_voltage", 1, true},
    {PacketId::ServoVoltage, "servo_voltage", 1, true},
    {PacketId::BatteryVoltage, "battery_voltage", 1, true},
    {PacketId::PacketPeriod, "packet_period", 1, true},
    {PacketId::PacketsStreamed, "packets_streamed", 1, true},
    {PacketId::TemperatureOffset, "temperature_offset", 1, true},
    {PacketId::UpperTemperatureLimit, "upper_temperature_limit", 1, true},
    {PacketId::PowerUpState, "power_up_state", 1, true},
    {PacketId::CrankingTime, "cranking_time", 1, true},
    {PacketId::CanAddress, "can_address", 2, true},
    {PacketId::Outputs, "outputs", 1, true},
    {PacketId::EnableOutputs, "enable_outputs", 1, false},
    {PacketId::DisableOutputs, "disable_outputs", 1, false},
    {PacketId::Generation, "generation", 1, true},
    {PacketId::EngineStart, "engine_start", 0, false},
    {PacketId::EngineStop, "engine_stop", 0, false},
    {PacketId::Reset, "reset", 0, false},
    {PacketId::Serial, "serial", 2, true},
    {PacketId::Firmware, "firmware", 6, true},
}};

namespace detail {
inline constexpr std::uint8_t kNoRow = 0xFF;
// Packet byte -> row, so a lookup on the frame path is one load rather than a search.
constexpr std::array<std::uint8_t, 256> make_packet_index() noexcept {
  std::array<std::uint8_t, 256> index{};
  for (auto& i : index) i = kNoRow;
  for (std::size_t row = 0; row < kPacketTable.size(); ++row)
    index[static_cast<std::uint8_t>(kPacketTable[row].id)] = static_cast<std::uint8_t>(row);
  return index;
}
inline constexpr std::array<std::uint8_t, 256> kPacketIndex = make_packet_index();
}  // namespace detail

// The row of `packet`; nullptr for an id outside table 1 (a PacketId made from a raw byte).
constexpr const PacketSpec* find_packet(PacketId packet) noexcept {
  const std::uint8_t row = detail::kPacketIndex[static_cast<std::uint8_t>(packet)];
  return row == detail::kNoRow ? nullptr : &kPacketTable[row];
}

}  // namespace pmu::codec
