// Identifier filters: the worked examples of filters.hpp, and agreement with the codec,
// so the transport never discards a frame the codec would decode.

#include <gtest/gtest.h>

#include "pmu/codec/canopen.hpp"
#include "pmu/codec/ids.hpp"
#include "pmu/transport/filters.hpp"

namespace pmu::transport {
namespace {

codec::CanFrame frame_with(std::uint32_t id, bool extended) {
  codec::CanFrame frame;
  frame.id = id;
  frame.extended = extended;
  return frame;
}

struct FilterCase {
  std::uint32_t id;
  bool extended;
  bool pmu;      // accepted by default_filters(false)
  bool canopen;  // accepted by default_filters(true)
};

// Protocol v1.9 section 4 (the PMU's group 0x1E); solar-boat CANopen document (battery
// 0x202/0x302/0x402/0x482, MPPT 0x4E6 + 8n, n = 0..7, two ids each).
constexpr FilterCase kCases[] = {
    {0x1E000001, true, true, true},     // voltages, address 1
    {0x1E31FFFF, true, true, true},     // firmware, broadcast
    {0x1EFFFFFF, true, true, true},     // unknown packet: still the PMU's group (codec decides)
    {0x1F000001, true, false, false},   // group 0x1F
    {0x0E000001, true, false, false},   // group 0x0E
    {0x0000001E, false, false, false},  // 11-bit: never a PMU frame
    {0x202, false, false, true},       {0x302, false, false, true},
    {0x402, false, false, true},       {0x482, false, false, true},
    {0x203, false, false, false},      {0x202, true, false, false},  // an extended 0x202 is not the battery
    {0x4E5, false, false, false},      {0x4E6, false, false, true},
    {0x51F, false, false, true},       {0x520, false, false, false},
};

TEST(Filters, WorkedExamples) {
  const auto pmu = default_filters(false);
  const auto both = default_filters(true);
  for (const auto& c : kCases) {
    SCOPED_TRACE(::testing::Message() << std::hex << c.id << (c.extended ? " ext" : " std"));
    EXPECT_EQ(accepts(pmu, frame_with(c.id, c.extended)), c.pmu);
    EXPECT_EQ(accepts(both, frame_with(c.id, c.extended)), c.canopen);
  }
}

TEST(Filters, EveryCanopenIdTheCodecDecodesPassesAndNoOtherElevenBitIdOutsideTheRange) {
  const auto filters = canopen_filters();
  for (std::uint32_t id = 0; id <= codec::kMaxStandardId; ++id) {
    const bool passes = accepts(filters, frame_with(id, false));
    if (codec::canopen::is_canopen_id(id, false)) {
      EXPECT_TRUE(passes) << std::hex << id;
    }
    const bool in_listed_ranges =
        id == 0x202 || id == 0x302 || id == 0x402 || id == 0x482 || (id >= 0x4E6 && id <= 0x51F);
    EXPECT_EQ(passes, in_listed_ranges) << std::hex << id;
  }
}

TEST(Filters, CanopenFiltersAreTheFewestAlignedBlocks) {
  // What a kernel filter list for the document's ids should be: the four battery ids, and
  // 0x4E6..0x51F as 2 + 8 + 16 + 32 ids.
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> want = {
      {0x202, 0x7FF}, {0x302, 0x7FF}, {0x402, 0x7FF}, {0x482, 0x7FF},
      {0x4E6, 0x7FE}, {0x4E8, 0x7F8}, {0x4F0, 0x7F0}, {0x500, 0x7E0},
  };
  const auto filters = canopen_filters();
  ASSERT_EQ(filters.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(filters[i].id, want[i].first) << i;
    EXPECT_EQ(filters[i].mask, want[i].second) << i;
    EXPECT_FALSE(filters[i].extended) << i;
  }
}

TEST(Filters, ThePmuFilterPassesExactlyTheIdsOfTheGroup) {
  const IdFilter pmu = pmu_filter();
  // Every group value, a few packet/address patterns each.
  for (std::uint32_t group = 0; group <= 0x1F; ++group) {
    for (const std::uint32_t low : {0x000000u, 0x00FFFFu, 0x310001u, 0xFFFFFFu}) {
      const std::uint32_t id = (group << 24) | low;
      const auto parsed = codec::parse_id(id, true);
      const bool codec_says_foreign = !parsed.id && parsed.error == codec::IdError::ForeignGroup;
      EXPECT_EQ(pmu.matches(frame_with(id, true)), !codec_says_foreign) << std::hex << id;
    }
  }
}

TEST(Filters, AnEmptyListAcceptsEverything) {
  EXPECT_TRUE(accepts({}, frame_with(0x123, false)));
  EXPECT_TRUE(accepts({}, frame_with(0x1F000000, true)));
}

}  // namespace
}  // namespace pmu::transport
