#pragma once
// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320): the checksum MCAP puts in chunks,
// DataEnd and the Footer. Incremental like zlib's crc32(): crc32(crc32(0, a), b) == crc32(0, a+b).

#include <cstddef>
#include <cstdint>

namespace pmu::mcap {

std::uint32_t crc32(std::uint32_t crc, const std::uint8_t* data, std::size_t size) noexcept;

}  // namespace pmu::mcap
