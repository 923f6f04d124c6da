#pragma once
// A classic CAN 2.0 data frame as the codec sees it: no timestamps, no interface, no I/O.
// transport/ converts to and from `struct can_frame`; this header stays free of Linux headers
// so the codec builds anywhere.

#include <array>
#include <cstdint>

namespace pmu::codec {

inline constexpr std::uint32_t kMaxExtendedId = 0x1FFFFFFFu;  // 29 bits
inline constexpr std::uint32_t kMaxStandardId = 0x7FFu;       // 11 bits
inline constexpr std::uint8_t kMaxDataLength = 8;

struct CanFrame {
  std::uint32_t id = 0;     // 11-bit or 29-bit identifier, without any flag bits
  bool extended = false;    // true for a 29-bit identifier (CAN 2.0B)
  bool remote = false;      // remote transmission request (the PMU never uses these)
  std::uint8_t length = 0;  // data length code, 0..8
  std::array<std::uint8_t, kMaxDataLength> data{};

  friend bool operator==(const CanFrame& a, const CanFrame& b) noexcept {
    if (a.id != b.id || a.extended != b.extended || a.remote != b.remote || a.length != b.length) return false;
    for (std::uint8_t i = 0; i < a.length && i < kMaxDataLength; ++i)
      if (a.data[i] != b.data[i]) return false;
    return true;
  }
  friend bool operator!=(const CanFrame& a, const CanFrame& b) noexcept { return !(a == b); }
};

}  // namespace pmu::codec
