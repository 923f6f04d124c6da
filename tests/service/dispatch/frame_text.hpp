#pragma once
// A CAN frame as cansend writes it ("1E210001#03"), for byte-for-byte comparisons whose
// failure message a person can read against candump.
#include <cstdio>
#include <string>

#include "pmu/codec/can_frame.hpp"

namespace pmu::service {

inline std::string hex(const codec::CanFrame& f) {
  char buf[40];
  int n = std::snprintf(buf, sizeof buf, "%08X#", f.id);
  for (std::uint8_t i = 0; i < f.length; ++i)
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n), "%02X", f.data[i]);
  return buf;
}

}  // namespace pmu::service
