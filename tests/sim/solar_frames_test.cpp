// The battery's and the MPPTs' schedules: every value of the document's tables
// (spec/solar-boat-canopen-battery-mppt.txt) within one period, one frame at a time, each
// decoding with codec::canopen::decode; and the models' start-up checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "solar_harness.hpp"

namespace pmu::sim::test {
namespace {

// spec "Battery (MG) CAN-format": 0x302 subindex 0x01..0x05 and 0x07 (0x06 blank); 0x402
// 0x09, 0x0B..0x0F (0x0A blank); 0x482 one frame per cell, subindex = cell number; 0x202.
std::multiset<Key> battery_keys(std::uint16_t node, int cells) {
  std::multiset<Key> k;
  const auto id = [&](std::uint16_t function) { return static_cast<std::uint16_t>(function + node); };
  for (int s : {0x01, 0x02, 0x03, 0x04, 0x05, 0x07}) k.insert({id(0x300), static_cast<std::uint8_t>(s)});
  for (int s : {0x09, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F}) k.insert({id(0x400), static_cast<std::uint8_t>(s)});
  for (int c = 1; c <= cells; ++c) k.insert({id(0x480), static_cast<std::uint8_t>(c)});
  k.insert({id(0x200), 0});
  return k;
}

// spec "MPPT CAN-format": base 0x4E6 + 8 * device, subindex 0x00..0x06 and 0x08..0x0F; the
// third table (duty cycles 0x01..0x04, channel map 0x05) on base + 1 (canopen.hpp).
std::multiset<Key> mppt_keys(std::uint8_t device) {
  std::multiset<Key> k;
  const auto base = static_cast<std::uint16_t>(0x4E6 + 8 * device);
  for (std::uint8_t s = 0x00; s <= 0x0F; ++s)
    if (s != 0x07) k.insert({base, s});
  for (std::uint8_t s = 0x01; s <= 0x05; ++s) k.insert({static_cast<std::uint16_t>(base + 1), s});
  return k;
}

struct BatteryCase {
  int cells;
  Duration period;
};
const BatteryCase kBatteryCases[] = {{12, 1000ms}, {1, 100ms}, {4, 250ms}, {15, 2000ms}, {8, 5000ms}};

// Frames sent in [start, start + period): one period from power-up.
template <class Model>
std::vector<SentFrame> one_period(SolarHarness& h, Model& m, Duration period, Duration step) {
  h.run(period - 1ms, step);
  std::vector<SentFrame> s = h.sent;
  EXPECT_EQ(s.size(), m.frames_per_period());
  return s;
}

std::multiset<Key> keys(const std::vector<SentFrame>& sent) {
  std::multiset<Key> k;
  for (const auto& s : sent) {
    const auto m = codec::canopen::decode(s.frame);
    EXPECT_TRUE(m.ok()) << m.error().describe();
    if (m) k.insert(key_of(*m));
  }
  return k;
}

// A BMS sends its values one at a time: frame k at k * period / count, never two at once.
void expect_spread(const std::vector<SentFrame>& sent, TimePoint start, Duration period, Duration step) {
  ASSERT_FALSE(sent.empty());
  const auto n = static_cast<Duration::rep>(sent.size());
  for (std::size_t k = 0; k < sent.size(); ++k) {
    const TimePoint due = start + period * static_cast<Duration::rep>(k) / n;
    EXPECT_GE(sent[k].at, due) << k;
    EXPECT_LE(sent[k].at, due + step) << k << ": sent within one tick of its slot";
  }
}

TEST(SolarFrames, BatterySendsEveryValueOncePerPeriodSpreadOverIt) {
  for (const auto& c : kBatteryCases) {
    SCOPED_TRACE(std::to_string(c.cells) + " cells, " + std::to_string(c.period.count()) + " ns");
    SolarHarness h;
    BatterySimConfig cfg;
    cfg.cells = c.cells;
    cfg.period = std::chrono::duration_cast<std::chrono::milliseconds>(c.period);
    auto& b = h.add(cfg);
    EXPECT_EQ(b.frames_per_period(), 13u + static_cast<std::size_t>(c.cells));
    const Duration step = 1ms;
    const auto sent = one_period(h, b, c.period, step);
    EXPECT_EQ(keys(sent), battery_keys(2, c.cells));
    expect_spread(sent, h.start, c.period, step);
    // The next period repeats the whole table.
    h.sent.clear();
    h.run(c.period, step);
    EXPECT_EQ(keys(h.sent), battery_keys(2, c.cells));
  }
}

TEST(SolarFrames, BatteryOnAnotherNodeUsesItsFunctionCodes) {
  SolarHarness h;
  BatterySimConfig cfg;
  cfg.node = 5;
  cfg.cells = 3;
  auto& b = h.add(cfg);
  h.run(999ms);
  ASSERT_EQ(h.sent.size(), b.frames_per_period());
  // decode() knows only the document's ids (node 2): check the ids and bytes directly.
  std::multiset<Key> k;
  for (const auto& s : h.sent)
    k.insert({static_cast<std::uint16_t>(s.frame.id), s.frame.id == 0x205 ? std::uint8_t{0} : s.frame.data[3]});
  EXPECT_EQ(k, battery_keys(5, 3));
}

TEST(SolarFrames, EveryMpptDeviceSendsEveryValueOncePerPeriod) {
  for (std::uint8_t device = 0; device < 8; ++device) {
    SCOPED_TRACE(int{device});
    SolarHarness h;
    MpptSimConfig cfg;
    cfg.device = device;
    cfg.period = 500ms;
    auto& m = h.add(cfg);
    const auto sent = one_period(h, m, 500ms, 1ms);
    EXPECT_EQ(keys(sent), mppt_keys(device));
    expect_spread(sent, h.start, 500ms, 1ms);
    for (const auto& s : sent) EXPECT_EQ(codec::canopen::decode(s.frame)->device, device);
  }
}

TEST(SolarFrames, DevicesOnOnePlantKeepTheirOwnPeriods) {
  SolarHarness h;
  BatterySimConfig b;
  b.period = 2000ms;
  h.add(b);
  MpptSimConfig m0, m7;
  m0.period = 1000ms;
  m7.device = 7;
  m7.period = 250ms;
  h.add(m0);
  h.add(m7);
  h.run(1999ms);
  std::map<std::uint16_t, int> per_id;
  for (const auto& s : h.take()) ++per_id[s.cob_id];
  EXPECT_EQ(per_id[0x302] + per_id[0x402] + per_id[0x482] + per_id[0x202], 25);  // one period
  EXPECT_EQ(per_id[0x4E6] + per_id[0x4E7], 2 * 20);                              // two periods
  EXPECT_EQ(per_id[0x51E] + per_id[0x51F], 8 * 20);                              // eight periods
}

TEST(SolarFrames, NextDeadlineIsTheNextFrame) {
  SolarHarness h;
  BatterySimConfig cfg;
  cfg.cells = 7;  // 20 frames: one every 50 ms
  auto& b = h.add(cfg);
  EXPECT_EQ(b.next_deadline(), h.start);
  h.tick();
  EXPECT_EQ(h.sent.size(), 1u);
  EXPECT_EQ(b.next_deadline(), h.start + 50ms);
  h.now = h.start + 49ms;
  h.tick();
  EXPECT_EQ(h.sent.size(), 1u);
  h.now = b.next_deadline();
  h.tick();
  EXPECT_EQ(h.sent.size(), 2u);
  EXPECT_EQ(b.next_deadline(), h.start + 100ms);
}

TEST(SolarFrames, AStalledHarnessDoesNotGetABurst) {
  SolarHarness h;
  auto& m = h.add(MpptSimConfig{});
  h.tick();
  h.sent.clear();
  h.now += 10s;  // no ticks for ten periods
  h.tick();
  EXPECT_EQ(h.sent.size(), 1u) << "restarts its table now instead of sending ten periods at once";
  h.run(1s - 1ms, 1ms);
  EXPECT_EQ(h.sent.size(), m.frames_per_period());
}

struct BadBattery {
  const char* what;
  BatterySimConfig config;
};

TEST(SolarFrames, BadConfigsThrowAtStartUp) {
  const auto battery = [](auto change) {
    BatterySimConfig c;
    change(c);
    return c;
  };
  const BadBattery bad[] = {
      {"node 0", battery([](auto& c) { c.node = 0; })},
      {"node 128", battery([](auto& c) { c.node = 128; })},
      {"0 cells", battery([](auto& c) { c.cells = 0; })},
      {"16 cells", battery([](auto& c) { c.cells = 16; })},
      {"period 0", battery([](auto& c) { c.period = 0ms; })},
      {"capacity 0", battery([](auto& c) { c.capacity_ah = 0; })},
      {"soc 1.5", battery([](auto& c) { c.initial_soc = 1.5; })},
      {"3 cell voltages for 12 cells", battery([](auto& c) {
         c.cell_voltages = {3.9, 3.9, 3.9};
       })},
      {"a negative cell voltage", battery([](auto& c) {
         c.cells = 2;
         c.cell_voltages = {3.9, -0.1};
       })},
      {"a cell voltage 0x482 cannot carry", battery([](auto& c) {
         c.cells = 1;
         c.cell_voltages = {65.6};
       })},
  };
  for (const auto& b : bad) {
    SCOPED_TRACE(b.what);
    SolarHarness h;
    EXPECT_THROW(h.add(b.config), std::invalid_argument);
  }
  const auto mppt = [](auto change) {
    MpptSimConfig c;
    change(c);
    return c;
  };
  const MpptSimConfig bad_mppts[] = {mppt([](auto& c) { c.device = 8; }), mppt([](auto& c) { c.panels = 5; }),
                                     mppt([](auto& c) { c.period = -1ms; }), mppt([](auto& c) { c.panel_imp = -1; })};
  for (const auto& c : bad_mppts) {
    SolarHarness h;
    EXPECT_THROW(h.add(c), std::invalid_argument);
  }
  SolarHarness ok;
  EXPECT_NO_THROW(ok.add(battery([](auto& c) { c.cells = 15; })));
  EXPECT_NO_THROW(ok.add(mppt([](auto& c) { c.device = 7; })));
}

}  // namespace
}  // namespace pmu::sim::test
