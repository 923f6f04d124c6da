#pragma once
// Reading and writing one telemetry field (telemetry.hpp) in a frame's data, private to the
// codec. Callers have checked the frame's length against table 1 before any read.

#include <cstdint>

#include "bytes.hpp"
#include "pmu/codec/telemetry.hpp"

namespace pmu::codec {

constexpr std::int32_t read_field(WireType w, const std::uint8_t* d) noexcept {
  switch (w) {
    case WireType::U8: return d[0];
    case WireType::S8: return as_signed(d[0]);
    case WireType::U16BE: return be16(d);
    case WireType::S16BE: return as_signed16(be16(d));
  }
  return 0;
}

// `raw` is in the field's range (or kNoSensorRaw); the low bytes are its two's complement.
constexpr void write_field(WireType w, std::uint8_t* d, long raw) noexcept {
  switch (w) {
    case WireType::U8:
    case WireType::S8: d[0] = static_cast<std::uint8_t>(raw & 0xFF); return;
    case WireType::U16BE:
    case WireType::S16BE: put_be16(d, static_cast<std::uint16_t>(raw & 0xFFFF)); return;
  }
}

}  // namespace pmu::codec
