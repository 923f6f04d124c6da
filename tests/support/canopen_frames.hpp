#pragma once
// Battery and MPPT frames built byte by byte from spec/solar-boat-canopen-battery-mppt.txt:
// Data[0] command byte, Data[1..2] index (little-endian), Data[3] subindex, Data[4..7] the
// value (little-endian), as codec/canopen.hpp reads the document.
#include <cstdint>
#include <initializer_list>

#include "pmu/codec/can_frame.hpp"

namespace pmu::service::test {

inline constexpr std::uint8_t kSdoCommandByte = 0x43;  // not checked by the codec

// `value`: the value's bytes as they are on the wire (already little-endian).
inline codec::CanFrame canopen_frame(std::uint16_t cob_id, std::uint16_t index, std::uint8_t subindex,
                                     std::initializer_list<std::uint8_t> value) {
  codec::CanFrame f;
  f.id = cob_id;
  f.data[0] = kSdoCommandByte;
  f.data[1] = static_cast<std::uint8_t>(index & 0xFF);
  f.data[2] = static_cast<std::uint8_t>(index >> 8);
  f.data[3] = subindex;
  std::uint8_t n = 4;
  for (const auto b : value) f.data[n++] = b;
  f.length = n;
  return f;
}

// The MPPT's first and second COB-ID of `device` (0x4E6 + 8 x device, and the next).
inline std::uint16_t mppt_id(std::uint8_t device, std::uint8_t second = 0) {
  return static_cast<std::uint16_t>(0x4E6 + 8 * device + second);
}

}  // namespace pmu::service::test
