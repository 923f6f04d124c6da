// Protocol v1.9 section 4: the 29-bit identifier, group 0x1E, packet id, address.
#include <gtest/gtest.h>

#include "pmu/codec/ids.hpp"

namespace pmu::codec {
namespace {

struct IdCase {
  std::uint32_t id;
  bool extended;
  bool ours;
  IdError error;
  PacketId packet;
  std::uint16_t address;
};

// Worked examples from ids.hpp, plus the edges of each field.
const IdCase kIdCases[] = {
    {0x1E000001, true, true, {}, PacketId::Voltages, 1},
    {0x1E31FFFF, true, true, {}, PacketId::Firmware, 0xFFFF},
    {0x1E1B0000, true, true, {}, PacketId::CanAddress, 0},
    {0x1E26FFFE, true, true, {}, PacketId::Reset, 0xFFFE},
    {0x1F000001, true, false, IdError::ForeignGroup, {}, 0},
    {0x0E000001, true, false, IdError::ForeignGroup, {}, 0},
    {0x1E050001, true, false, IdError::UnknownPacket, {}, 0},
    {0x1E1A0001, true, false, IdError::UnknownPacket, {}, 0},  // 0x1A is not in table 1
    {0x1EFF0001, true, false, IdError::UnknownPacket, {}, 0},
    {0x202, false, false, IdError::NotExtended, {}, 0},
    {0x1E000001, false, false, IdError::NotExtended, {}, 0},  // same number, 11-bit frame
    {0x3E000001, true, false, IdError::NotExtended, {}, 0},   // more than 29 bits
};

TEST(Ids, ParseTable) {
  for (const auto& c : kIdCases) {
    SCOPED_TRACE(testing::Message() << std::hex << c.id);
    const IdParse r = parse_id(c.id, c.extended);
    ASSERT_EQ(r.id.has_value(), c.ours);
    if (c.ours) {
      EXPECT_EQ(r.id->packet, c.packet);
      EXPECT_EQ(r.id->address, c.address);
      EXPECT_EQ(make_id(c.packet, c.address), c.id);
    } else {
      EXPECT_EQ(r.error, c.error);
    }
  }
}

// Table 1: every packet id is known, and nothing else in 0x00..0xFF is.
TEST(Ids, KnownPacketsAreExactlyTable1) {
  const std::uint8_t table1[] = {0x00, 0x01, 0x02, 0x03, 0x04, 0x0F, 0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16,
                                 0x17, 0x18, 0x19, 0x1B, 0x20, 0x21, 0x22, 0x23, 0x24, 0x25, 0x26, 0x30, 0x31};
  int known = 0;
  for (int p = 0; p < 256; ++p) known += is_known_packet(static_cast<std::uint8_t>(p)) ? 1 : 0;
  EXPECT_EQ(known, 26);
  for (auto p : table1) EXPECT_TRUE(is_known_packet(p)) << int(p);
}

TEST(Ids, NamesRoundTrip) {
  const std::pair<PacketId, const char*> names[] = {
      {PacketId::Voltages, "voltages"},
      {PacketId::BatteryEnergy, "battery_energy"},
      {PacketId::Status, "status"},
      {PacketId::MeasurementRequest, "measurement_request"},
      {PacketId::CanAddress, "can_address"},
      {PacketId::Outputs, "outputs"},
      {PacketId::EnableOutputs, "enable_outputs"},
      {PacketId::EngineStop, "engine_stop"},
      {PacketId::Serial, "serial"},
      {PacketId::Firmware, "firmware"},
  };
  for (const auto& [id, name] : names) {
    EXPECT_EQ(packet_name(id), name);
    EXPECT_EQ(packet_from_name(name), id);
  }
  EXPECT_FALSE(packet_from_name("volts").has_value());
}

}  // namespace
}  // namespace pmu::codec
