#pragma once
// The CAN heartbeat of the bus owner and of a claimant (docs/design.md, "The CAN heartbeat
// frame"): a 29-bit identifier in group 0x1F, which no PMU uses (a PMU's group is always 0x1E,
// protocol v1.9 section 4.1), and 7 data bytes. Pure: bytes in and out, no socket.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace pmu::redundancy {

enum class CanClaim : std::uint8_t { Claiming = 1, Active = 2, Released = 3 };

struct CanBeat {
  CanClaim claim = CanClaim::Active;
  std::uint8_t priority = 0;
  std::uint32_t term = 0;
};

inline constexpr std::uint32_t kCanBeatIdBase = 0x1FFFFF00;  // + the sender's priority
inline constexpr std::size_t kCanBeatLength = 7;
inline constexpr std::uint8_t kCanBeatLayout = 1;

constexpr std::uint32_t can_beat_id(std::uint8_t priority) noexcept { return kCanBeatIdBase | priority; }

// True for a 29-bit identifier of the heartbeat range; what the holder's receive filter passes.
constexpr bool is_can_beat_id(std::uint32_t id, bool extended) noexcept {
  return extended && (id & ~std::uint32_t{0xFF}) == kCanBeatIdBase;
}

std::array<std::uint8_t, kCanBeatLength> encode_can_beat(const CanBeat& beat) noexcept;

// A heartbeat, or nothing for any frame that is not one: another identifier, another length,
// layout or claim code, or a priority byte that differs from the identifier's. Total.
std::optional<CanBeat> decode_can_beat(std::uint32_t id, bool extended, const std::uint8_t* data,
                                       std::size_t length) noexcept;

}  // namespace pmu::redundancy
