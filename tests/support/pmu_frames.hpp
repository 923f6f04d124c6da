#pragma once
// A PMU frame from packet id, address and bytes, written the way the spec's tables read:
// for the codec's tests and the service's (what a command puts on the bus).

#include <cstdint>
#include <initializer_list>

#include "pmu/codec/can_frame.hpp"
#include "pmu/codec/ids.hpp"

namespace pmu::codec::test {

inline CanFrame pmu_frame(std::uint8_t packet, std::uint16_t address, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = (0x1Eu << 24) | (std::uint32_t{packet} << 16) | address;
  f.extended = true;
  f.length = static_cast<std::uint8_t>(bytes.size());
  std::uint8_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  return f;
}

}  // namespace pmu::codec::test
