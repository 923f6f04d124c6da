#pragma once
// Little-endian field access at a payload offset. The offsets in messages.cpp are the wire
// order of each definition (message_table.hpp says how it is derived); Payload is 255 bytes,
// so every offset of these messages is inside it.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include "pmu/mavlink/frame.hpp"

namespace pmu::mavlink::detail {

template <class T>
void put(Payload& out, std::size_t offset, T value) {
  static_assert(std::is_integral_v<T> || std::is_floating_point_v<T>);
  using U = std::conditional_t<sizeof(T) == 1, std::uint8_t,
                               std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                                  std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
  U bits = 0;
  std::memcpy(&bits, &value, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out[offset + i] = static_cast<std::uint8_t>((bits >> (8 * i)) & 0xFFU);
  }
}

template <class T>
T get(const Payload& in, std::size_t offset) {
  using U = std::conditional_t<sizeof(T) == 1, std::uint8_t,
                               std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                                  std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
  U bits = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    bits = static_cast<U>(bits | (static_cast<U>(in[offset + i]) << (8 * i)));
  }
  T value;
  std::memcpy(&value, &bits, sizeof(T));
  return value;
}

inline void put_chars(Payload& out, std::size_t offset, std::size_t size, const std::string& text) {
  const std::size_t n = std::min(size, text.size());
  std::memcpy(out.data() + offset, text.data(), n);
}

inline std::string get_chars(const Payload& in, std::size_t offset, std::size_t size) {
  const auto* begin = reinterpret_cast<const char*>(in.data() + offset);
  const auto* end = std::find(begin, begin + size, '\0');
  return std::string(begin, end);
}

}  // namespace pmu::mavlink::detail
