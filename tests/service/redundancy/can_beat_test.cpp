// The CAN heartbeat frame: its identifier is never a PMU's (group 0x1F, not 0x1E) nor a
// battery's or MPPT's (11-bit), its bytes both ways, and every other frame refused.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "pmu/codec/ids.hpp"
#include "pmu/redundancy/can_beat.hpp"

namespace pmu::redundancy {
namespace {

TEST(CanBeat, ItsIdentifierIsNoPmuFrame) {
  for (const std::uint8_t priority : {std::uint8_t{1}, std::uint8_t{2}, std::uint8_t{255}}) {
    const std::uint32_t id = can_beat_id(priority);
    EXPECT_LE(id, 0x1FFFFFFFu);  // 29 bits
    EXPECT_EQ(id >> 24, 0x1Fu);
    const auto parsed = codec::parse_id(id, true);
    EXPECT_FALSE(parsed.id.has_value());
    EXPECT_EQ(parsed.error, codec::IdError::ForeignGroup);
    EXPECT_TRUE(is_can_beat_id(id, true));
    EXPECT_FALSE(is_can_beat_id(id, false));
  }
  // Every PMU identifier, and the 11-bit ones, are outside the range.
  EXPECT_FALSE(is_can_beat_id(codec::make_id(codec::PacketId::Firmware, codec::kBroadcastAddress), true));
  EXPECT_FALSE(is_can_beat_id(0x1E000001, true));
  EXPECT_FALSE(is_can_beat_id(0x202, false));
  EXPECT_FALSE(is_can_beat_id(0x1FFFFE01, true));
}

TEST(CanBeat, BothWays) {
  const CanBeat beat{CanClaim::Claiming, 7, 0x01020304};
  const auto bytes = encode_can_beat(beat);
  EXPECT_EQ(bytes, (std::array<std::uint8_t, 7>{1, 1, 7, 1, 2, 3, 4}));
  const auto back = decode_can_beat(can_beat_id(7), true, bytes.data(), bytes.size());
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->claim, CanClaim::Claiming);
  EXPECT_EQ(back->priority, 7);
  EXPECT_EQ(back->term, 0x01020304u);
}

TEST(CanBeat, EveryOtherFrameIsNoHeartbeat) {
  const std::array<std::uint8_t, 8> good{1, 2, 7, 0, 0, 0, 9, 0};
  struct Case {
    const char* what;
    std::uint32_t id;
    bool extended;
    std::array<std::uint8_t, 8> data;
    std::size_t length;
  };
  const Case cases[] = {
      {"a PMU identifier", 0x1E000007, true, good, 7},
      {"11-bit", 0x107, false, good, 7},
      {"6 bytes", can_beat_id(7), true, good, 6},
      {"8 bytes", can_beat_id(7), true, good, 8},
      {"another layout", can_beat_id(7), true, {2, 2, 7, 0, 0, 0, 9, 0}, 7},
      {"claim 0", can_beat_id(7), true, {1, 0, 7, 0, 0, 0, 9, 0}, 7},
      {"claim 4", can_beat_id(7), true, {1, 4, 7, 0, 0, 0, 9, 0}, 7},
      {"priority not the identifier's", can_beat_id(8), true, good, 7},
  };
  for (const auto& c : cases)
    EXPECT_FALSE(decode_can_beat(c.id, c.extended, c.data.data(), c.length).has_value()) << c.what;
  EXPECT_TRUE(decode_can_beat(can_beat_id(7), true, good.data(), 7).has_value());
  EXPECT_FALSE(decode_can_beat(can_beat_id(7), true, nullptr, 7).has_value());
}

}  // namespace
}  // namespace pmu::redundancy
