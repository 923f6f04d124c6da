#include "pmu/mavlink/crc.hpp"

namespace pmu::mavlink {

std::uint16_t crc_accumulate(const std::uint8_t* data, std::size_t size, std::uint16_t crc) noexcept {
  for (std::size_t i = 0; i < size; ++i) crc = crc_accumulate(data[i], crc);
  return crc;
}

}  // namespace pmu::mavlink
