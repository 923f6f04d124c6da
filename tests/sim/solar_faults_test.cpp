// Fault injection on the battery and MPPTs: silence (nothing sent, the world goes on) and
// garbled frames (wrong length, unknown subindex), and the recovery from each.
#include <gtest/gtest.h>

#include "solar_harness.hpp"

namespace pmu::sim::test {
namespace {

using codec::canopen::ErrorKind;

TEST(SolarFaults, SilenceStopsAllFramesButNotTheWorld) {
  SolarHarness h;
  h.plant->set_irradiance(0.0, h.now);
  auto& b = h.add(BatterySimConfig{});
  auto& m = h.add(MpptSimConfig{});
  h.run(1s);
  h.sent.clear();
  const double soc = *h.plant->state_of_charge(2);

  CanOpenFaults silent;
  silent.silent = true;
  b.set_faults(silent);
  m.set_faults(silent);
  EXPECT_TRUE(b.faults().silent);
  h.run(10s);
  EXPECT_TRUE(h.sent.empty());
  EXPECT_EQ(b.counters().suppressed, 10 * b.frames_per_period());
  EXPECT_EQ(m.counters().suppressed, 10 * m.frames_per_period());
  EXPECT_LT(*h.plant->state_of_charge(2), soc) << "the load kept drawing while the BMS was quiet";

  b.set_faults(CanOpenFaults{});
  m.set_faults(CanOpenFaults{});
  h.run(1s);
  EXPECT_EQ(h.sent.size(), b.frames_per_period() + m.frames_per_period()) << "back on schedule, no burst";
  EXPECT_EQ(h.take().size(), b.frames_per_period() + m.frames_per_period()) << "and every frame decodes";
}

TEST(SolarFaults, OneDeviceSilentTheOthersStillSend) {
  SolarHarness h;
  h.add(BatterySimConfig{});
  MpptSimConfig c0, c1;
  c1.device = 1;
  auto& m0 = h.add(c0);
  h.add(c1);
  CanOpenFaults silent;
  silent.silent = true;
  m0.set_faults(silent);
  h.run(1s - 1ms);
  std::map<std::uint16_t, int> per_id;
  for (const auto& m : h.take()) ++per_id[m.cob_id];
  EXPECT_EQ(per_id.count(0x4E6), 0u);
  EXPECT_EQ(per_id.count(0x4E7), 0u);
  EXPECT_EQ(per_id[0x4EE] + per_id[0x4EF], 20);
  EXPECT_EQ(per_id[0x302], 6);
}

struct GarbleCase {
  const char* what;
  Garble garble;
  // What decode() may say about a spoiled frame.
  std::set<ErrorKind> allowed;
};
const GarbleCase kGarbles[] = {
    {"wrong length", Garble::WrongLength, {ErrorKind::TooShort}},
    // 0x302/0x402/MPPT: a blank subindex; 0x482 (subindex = cell): an unknown index; 0x202
    // (checks neither): too short.
    {"unknown subindex",
     Garble::UnknownSubindex,
     {ErrorKind::UnknownSubindex, ErrorKind::UnknownIndex, ErrorKind::TooShort}},
};

TEST(SolarFaults, GarbledFramesNeverDecodeAndRecover) {
  for (const auto& g : kGarbles) {
    SCOPED_TRACE(g.what);
    SolarHarness h;
    auto& b = h.add(BatterySimConfig{});
    MpptSimConfig mc;
    mc.device = 6;
    auto& m = h.add(mc);
    CanOpenFaults f;
    f.garble = g.garble;
    b.set_faults(f);
    m.set_faults(f);
    h.run(1s - 1ms);
    const std::size_t total = b.frames_per_period() + m.frames_per_period();
    ASSERT_EQ(h.sent.size(), total) << "garbled frames are still sent";
    std::map<ErrorKind, int> kinds;
    std::set<std::uint32_t> ids;
    for (const auto& s : h.sent) {
      const auto d = codec::canopen::decode(s.frame);
      ASSERT_FALSE(d.ok()) << "frame " << std::hex << s.frame.id << " decoded";
      EXPECT_TRUE(g.allowed.count(d.error().kind)) << d.error().describe();
      ++kinds[d.error().kind];
      ids.insert(s.frame.id);
    }
    EXPECT_EQ(ids, (std::set<std::uint32_t>{0x202, 0x302, 0x402, 0x482, 0x516, 0x517})) << "still the devices' ids";
    if (g.garble == Garble::UnknownSubindex) {
      EXPECT_EQ(kinds[ErrorKind::UnknownSubindex], 12 + 20) << "0x302, 0x402 and the MPPT's";
      EXPECT_EQ(kinds[ErrorKind::UnknownIndex], 12) << "the cells";
      EXPECT_EQ(kinds[ErrorKind::TooShort], 1) << "0x202";
    }
    EXPECT_EQ(b.counters().garbled, b.frames_per_period());
    EXPECT_EQ(m.counters().garbled, m.frames_per_period());

    h.sent.clear();
    b.set_faults(CanOpenFaults{});
    m.set_faults(CanOpenFaults{});
    h.run(1s);
    EXPECT_EQ(h.take().size(), total) << "every frame decodes again";
    EXPECT_EQ(b.counters().encode_errors, 0u);
    EXPECT_EQ(m.counters().encode_errors, 0u);
  }
}

}  // namespace
}  // namespace pmu::sim::test
