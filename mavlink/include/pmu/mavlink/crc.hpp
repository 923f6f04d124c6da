#pragma once
// CRC-16/MCRF4XX, the checksum MAVLink calls X.25: polynomial 0x1021 reflected, initial value
// 0xFFFF, no final XOR. A frame's CRC covers the bytes after the start marker up to the end
// of the payload, then the message's CRC_EXTRA byte (message_table.hpp), which makes two
// sides with different definitions of a message disagree on every frame of it.

#include <cstddef>
#include <cstdint>

namespace pmu::mavlink {

inline constexpr std::uint16_t kCrcInit = 0xFFFF;

constexpr std::uint16_t crc_accumulate(std::uint8_t byte, std::uint16_t crc) noexcept {
  auto tmp = static_cast<std::uint8_t>(byte ^ static_cast<std::uint8_t>(crc & 0xFFU));
  tmp = static_cast<std::uint8_t>(tmp ^ static_cast<std::uint8_t>(tmp << 4));
  return static_cast<std::uint16_t>((crc >> 8) ^ (static_cast<unsigned>(tmp) << 8) ^ (static_cast<unsigned>(tmp) << 3) ^
                                    (static_cast<unsigned>(tmp) >> 4));
}

std::uint16_t crc_accumulate(const std::uint8_t* data, std::size_t size, std::uint16_t crc) noexcept;

}  // namespace pmu::mavlink
