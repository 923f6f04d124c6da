#include "pmu/redundancy/can_beat.hpp"

namespace pmu::redundancy {

std::array<std::uint8_t, kCanBeatLength> encode_can_beat(const CanBeat& beat) noexcept {
  return {kCanBeatLayout,
          static_cast<std::uint8_t>(beat.claim),
          beat.priority,
          static_cast<std::uint8_t>(beat.term >> 24),
          static_cast<std::uint8_t>(beat.term >> 16),
          static_cast<std::uint8_t>(beat.term >> 8),
          static_cast<std::uint8_t>(beat.term)};
}

std::optional<CanBeat> decode_can_beat(std::uint32_t id, bool extended, const std::uint8_t* data,
                                       std::size_t length) noexcept {
  if (!is_can_beat_id(id, extended) || data == nullptr || length != kCanBeatLength) return std::nullopt;
  if (data[0] != kCanBeatLayout) return std::nullopt;
  if (data[1] < static_cast<std::uint8_t>(CanClaim::Claiming) ||
      data[1] > static_cast<std::uint8_t>(CanClaim::Released))
    return std::nullopt;
  if (data[2] != static_cast<std::uint8_t>(id & 0xFFu)) return std::nullopt;
  CanBeat beat;
  beat.claim = static_cast<CanClaim>(data[1]);
  beat.priority = data[2];
  beat.term = (std::uint32_t{data[3]} << 24) | (std::uint32_t{data[4]} << 16) | (std::uint32_t{data[5]} << 8) |
              std::uint32_t{data[6]};
  return beat;
}

}  // namespace pmu::redundancy
