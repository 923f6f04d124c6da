#pragma once
// Frame -> typed value. Total over all inputs: every CanFrame gives a PmuMessage or a
// DecodeError, never an exception, a crash or a read past `length`.
//
// The PMU answers a get with the same packet id it was asked with, so a decoded frame does
// not say who sent it; `request` is true for the zero-length form (a get, or a data-less
// command), false for a frame carrying values.

#include <cstdint>
#include <optional>
#include <string>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/firmware.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/codec/messages.hpp"
#include "pmu/codec/result.hpp"

namespace pmu::codec {

enum class DecodeErrorKind : std::uint8_t {
  NotOurs,        // 11-bit id, or a 29-bit id outside group 0x1E
  UnknownPacket,  // group 0x1E, packet id not in table 1
  WrongLength,    // length not allowed for the packet
  RemoteFrame,    // the PMU protocol uses data frames only (v1.9 section 2)
  BadLength,      // length code above 8
};

struct DecodeError {
  DecodeErrorKind kind = DecodeErrorKind::NotOurs;
  std::uint32_t id = 0;
  std::uint8_t packet = 0;
  std::uint8_t length = 0;
  std::uint8_t expected = 0;  // WrongLength: the length a data frame of this packet has

  // "wrong length 3 for packet 0x00 voltages (expects 7, or 0 for a get)"
  std::string describe() const;
};

struct PmuMessage {
  PacketId packet = PacketId::Voltages;
  std::uint16_t address = 0;
  bool request = false;
  Payload payload;
  // Set for a 0x0F frame addressed to firmware that predates it (< 1.14): the frame is
  // well formed but the device ignores it.
  bool unsupported_by_firmware = false;
};

// `fw` is the firmware of the device at the frame's address when known; it selects the
// meaning of bit 6 of flag register 0 and whether 1.12+ fields exist. The meaning chosen is
// recorded in Status::interpretation.
Result<PmuMessage, DecodeError> decode(const CanFrame& frame,
                                       std::optional<FirmwareVersion> fw = std::nullopt) noexcept;

// The same for a frame whose id the caller has already parsed into `id` (parse_id(frame.id,
// frame.extended)): code that routes frames by address parses the id once, then decodes
// with the firmware of the device it routed to.
Result<PmuMessage, DecodeError> decode(const CanFrame& frame, const PmuId& id,
                                       std::optional<FirmwareVersion> fw) noexcept;

// Data length of a frame carrying values for `packet` (the "Length" column of table 1, as
// kPacketTable in packets.hpp); 0 for data-less commands and for unknown packets.
std::uint8_t data_length(PacketId packet) noexcept;

// True where a zero-length frame is a get that the PMU answers with the current value:
// every id up to 0x20, plus 0x23 (section 5.21), 0x30 and 0x31; false for unknown packets.
bool has_zero_length_get(PacketId packet) noexcept;

}  // namespace pmu::codec
