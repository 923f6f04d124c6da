#pragma once
// Decoding of the solar-boat battery (MG) and MPPT frames
// (spec/solar-boat-canopen-battery-mppt.txt). These share a bus with the PMU on some
// airframes; the service reads them, never writes them. The simulator builds them with
// canopen_encode.hpp, from the same rows (src/canopen_table.hpp).
//
// Where the document is ambiguous we take the CANopen reading, and tests pin each choice:
//  * Byte order: little-endian for the index (Data[1] low, Data[2] high) and for values in
//    Data[4..7], as CANopen SDO/PDO data is. The document never says.
//  * Data[0]: the document calls it "Node-ID"; in CANopen it is the SDO command specifier
//    and the node id is in the COB-ID. We report it as `command_byte` and do not check it.
//  * Index/subindex select the value. Where the document says "Don't Care" for the index
//    (0x202, MPPT), it is not checked; otherwise a frame with another index is an error.
//  * 0x202 "Power Level" has no subindex: its value is Data[4].
//  * 0x482 carries one cell voltage per frame, the subindex being the cell number.
//  * MPPT: COB-ID 0x4E6 + 8 * device_id (device 0..7). The document lists three tables
//    under that one id, and the third (duty cycles, channel map: subindex 0x01..0x05)
//    collides with the first (subindex 0x00..0x06). We read the first two on the base id
//    and the third on base + 1, the next id of the device's block of eight.
//  * MPPT voltages and currents have no resolution in the document: they are reported as raw
//    counts, with names ending in `_raw`, rather than guessed into volts.
//  * Subindex 0x06 (battery 0x302) and 0x0A (0x402) are blank in the document: errors.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::codec::canopen {

enum class Source : std::uint8_t { Battery, Mppt };

struct Field {
  std::string_view name;  // e.g. "voltage", "cell_temperature_high", "voltage_output_raw"
  double value = 0;
  std::string_view unit;  // "V", "A", "%", "degC", "min", "" (raw or state)
};

struct CanOpenMessage {
  Source source = Source::Battery;
  std::uint16_t cob_id = 0;
  std::uint8_t device = 0;  // MPPT device id 0..7; 0 for the battery
  std::uint8_t command_byte = 0;
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::array<Field, 4> fields{};  // up to four values (4x uint8 collections)
  std::uint8_t field_count = 0;
};

enum class ErrorKind : std::uint8_t { NotOurs, TooShort, UnknownIndex, UnknownSubindex, RemoteFrame };

struct Error {
  ErrorKind kind = ErrorKind::NotOurs;
  std::uint16_t cob_id = 0;
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint8_t length = 0;
  std::uint8_t needed = 0;
  std::string describe() const;
};

// The COB-IDs of the document: the battery's four, and per MPPT device (0..7) a block of
// kMpptStride ids from 0x4E6 + 8 * device of which the first two are used (see above).
// Bus filters are built from these.
inline constexpr std::array<std::uint16_t, 4> kBatteryCobIds{{0x202, 0x302, 0x402, 0x482}};
inline constexpr std::uint16_t kMpptBase = 0x4E6;
inline constexpr std::uint16_t kMpptStride = 8;
inline constexpr std::uint8_t kMpptDevices = 8;
inline constexpr std::uint8_t kMpptIdsUsed = 2;
inline constexpr std::uint16_t kMpptLastId = kMpptBase + kMpptStride * (kMpptDevices - 1) + kMpptIdsUsed - 1;

// True for 11-bit ids this module decodes (0x202, 0x302, 0x402, 0x482, MPPT blocks).
bool is_canopen_id(std::uint32_t id, bool extended) noexcept;

Result<CanOpenMessage, Error> decode(const CanFrame& frame) noexcept;

}  // namespace pmu::codec::canopen
