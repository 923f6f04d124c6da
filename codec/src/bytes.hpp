#pragma once
// Byte helpers private to the codec. The PMU sends 2-byte quantities big-endian (v1.9 §5);
// CANopen sends them little-endian.

#include <cstdint>

namespace pmu::codec {

constexpr std::uint16_t be16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }
constexpr std::uint16_t le16(const std::uint8_t* p) noexcept { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
constexpr std::uint32_t le32(const std::uint8_t* p) noexcept {
  return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) | (std::uint32_t{p[3]} << 24);
}
constexpr void put_be16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v & 0xFF);
}
// Two's complement reinterpretation, well defined for every input.
constexpr std::int8_t as_signed(std::uint8_t b) noexcept { return static_cast<std::int8_t>(b >= 0x80 ? b - 0x100 : b); }
constexpr std::int16_t as_signed16(std::uint16_t v) noexcept {
  return static_cast<std::int16_t>(v >= 0x8000 ? static_cast<int>(v) - 0x10000 : static_cast<int>(v));
}

}  // namespace pmu::codec
