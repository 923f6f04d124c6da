#pragma once
// Frames built byte by byte in the tests, independent of FrameWriter: any id, payload,
// flags and CRC_EXTRA, so frames the writer never makes (unknown ids, MAVLink 1, unknown
// incompat flags, over-long payloads) can be fed to the parser.

#include <cstdint>
#include <variant>
#include <vector>

#include "pmu/mavlink/crc.hpp"
#include "pmu/mavlink/parser.hpp"

namespace pmu::mavlink::test {

inline std::vector<std::uint8_t> raw_v2(std::uint32_t msgid, const std::vector<std::uint8_t>& payload,
                                        std::uint8_t crc_extra, std::uint8_t incompat = 0, std::uint8_t sysid = 1,
                                        std::uint8_t compid = 1, std::uint8_t seq = 0) {
  std::vector<std::uint8_t> out{0xFD,
                                static_cast<std::uint8_t>(payload.size()),
                                incompat,
                                0,
                                seq,
                                sysid,
                                compid,
                                static_cast<std::uint8_t>(msgid & 0xFFU),
                                static_cast<std::uint8_t>((msgid >> 8) & 0xFFU),
                                static_cast<std::uint8_t>((msgid >> 16) & 0xFFU)};
  out.insert(out.end(), payload.begin(), payload.end());
  std::uint16_t crc = crc_accumulate(out.data() + 1, out.size() - 1, kCrcInit);
  crc = crc_accumulate(crc_extra, crc);
  out.push_back(static_cast<std::uint8_t>(crc & 0xFFU));
  out.push_back(static_cast<std::uint8_t>(crc >> 8));
  return out;
}

inline std::vector<std::uint8_t> raw_v1(std::uint8_t msgid, const std::vector<std::uint8_t>& payload,
                                        std::uint8_t crc_extra, std::uint8_t sysid = 1, std::uint8_t compid = 1) {
  std::vector<std::uint8_t> out{0xFE, static_cast<std::uint8_t>(payload.size()), 0, sysid, compid, msgid};
  out.insert(out.end(), payload.begin(), payload.end());
  std::uint16_t crc = crc_accumulate(out.data() + 1, out.size() - 1, kCrcInit);
  crc = crc_accumulate(crc_extra, crc);
  out.push_back(static_cast<std::uint8_t>(crc & 0xFFU));
  out.push_back(static_cast<std::uint8_t>(crc >> 8));
  return out;
}

// Everything the parser gives for these bytes, pushed in chunks of `chunk` bytes.
inline std::vector<ParseResult> parse_all(Parser& parser, const std::vector<std::uint8_t>& bytes,
                                          std::size_t chunk = 1 << 20) {
  std::vector<ParseResult> out;
  for (std::size_t at = 0; at < bytes.size(); at += chunk) {
    const std::size_t n = std::min(chunk, bytes.size() - at);
    parser.push(bytes.data() + at, n);
    while (auto r = parser.next()) out.push_back(std::move(*r));
  }
  return out;
}

inline std::vector<std::uint8_t> concat(std::initializer_list<std::vector<std::uint8_t>> parts) {
  std::vector<std::uint8_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace pmu::mavlink::test
