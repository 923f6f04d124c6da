#pragma once
// The PMU's 29-bit CAN identifier (protocol v1.9 section 4):
//
//   bits 28..24  group id   (always 0x1E for the PMU)
//   bits 23..16  packet id  (table 1)
//   bits 15..0   address    (0..65534 a device, 0xFFFF broadcast)
//
// Worked examples (also in tests/codec/ids_test.cpp):
//   0x1E000001 -> group 0x1E, packet 0x00 (voltages), address 1
//   0x1E31FFFF -> packet 0x31 (firmware), broadcast
//   0x1F000001 -> not ours (group 0x1F)
//   standard (11-bit) 0x202 -> not a PMU frame (may be a CANopen battery frame)

#include <cstdint>
#include <optional>
#include <string_view>

namespace pmu::codec {

inline constexpr std::uint8_t kGroupId = 0x1E;
inline constexpr std::uint16_t kBroadcastAddress = 0xFFFF;
inline constexpr std::uint16_t kMaxDeviceAddress = 0xFFFE;
inline constexpr std::uint16_t kDefaultAddress = 1;

// Every packet id of table 1. The underlying value is the packet id on the wire.
enum class PacketId : std::uint8_t {
  Voltages = 0x00,
  Currents = 0x01,
  BatteryEnergy = 0x02,
  Temperatures = 0x03,
  Status = 0x04,  // "Miscellaneous" in the spec
  MeasurementRequest = 0x0F,
  AvionicsVoltage = 0x10,
  PayloadVoltage = 0x11,
  ServoVoltage = 0x12,
  BatteryVoltage = 0x13,
  PacketPeriod = 0x14,
  PacketsStreamed = 0x15,
  TemperatureOffset = 0x16,
  UpperTemperatureLimit = 0x17,
  PowerUpState = 0x18,
  CrankingTime = 0x19,
  CanAddress = 0x1B,
  Outputs = 0x20,
  EnableOutputs = 0x21,
  DisableOutputs = 0x22,
  Generation = 0x23,
  EngineStart = 0x24,
  EngineStop = 0x25,
  Reset = 0x26,
  Serial = 0x30,
  Firmware = 0x31,
};

// True for the ids listed in table 1.
bool is_known_packet(std::uint8_t packet) noexcept;

// The contract's name of a packet (interface.md, `pmuctl decode`): "voltages",
// "avionics_voltage", "outputs", "engine_start", ...; "unknown" for ids not in table 1.
std::string_view packet_name(PacketId packet) noexcept;
std::optional<PacketId> packet_from_name(std::string_view name) noexcept;

struct PmuId {
  PacketId packet;
  std::uint16_t address;
};

// The identifier of a frame to or from `address` carrying `packet`.
constexpr std::uint32_t make_id(PacketId packet, std::uint16_t address) noexcept {
  return (std::uint32_t{kGroupId} << 24) | (std::uint32_t{static_cast<std::uint8_t>(packet)} << 16) | address;
}

// Bits 15..0 of an identifier, the address field. Readable without parse_id: a frame whose
// packet byte is unknown still says which device it is for, and a log line needs the
// address (to pick that device's firmware) before it can be decoded.
constexpr std::uint16_t address_of_id(std::uint32_t id) noexcept { return static_cast<std::uint16_t>(id & 0xFFFFu); }

enum class IdError : std::uint8_t {
  NotExtended,    // an 11-bit identifier: never a PMU frame
  ForeignGroup,   // 29-bit, but the group is not 0x1E
  UnknownPacket,  // group 0x1E, packet id not in table 1
};

struct IdParse {
  std::optional<PmuId> id;
  IdError error = IdError::NotExtended;  // meaningful only when !id
  std::uint8_t raw_packet = 0;           // the packet byte, for error messages
};

IdParse parse_id(std::uint32_t id, bool extended) noexcept;

}  // namespace pmu::codec
