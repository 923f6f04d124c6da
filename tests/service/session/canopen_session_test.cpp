// Batteries and MPPTs (canopen_session.hpp) with a fake clock: every value of the document's
// tables reaches its contract field in the contract's unit, a value not received is NaN,
// samples are rate-limited and carry the newest frame's time, and OFFLINE forgets the values.
#include <gtest/gtest.h>

#include <cmath>

#include "support/canopen_frames.hpp"
#include "pmu/session/canopen_session.hpp"
#include "support/recording_sink.hpp"

namespace pmu::service::test {
namespace {

using namespace std::chrono_literals;
using Steady = std::chrono::steady_clock::time_point;
using Wall = std::chrono::system_clock::time_point;

const Steady t0 = Steady{} + 1h;
const Wall w0 = Wall{} + std::chrono::hours(24 * 365 * 50);

struct Row {
  const char* section;  // the document's table the row comes from
  std::uint16_t cob_id;
  std::uint16_t index;
  std::uint8_t subindex;
  std::initializer_list<std::uint8_t> bytes;  // the value as on the wire
  const char* field;                          // the contract's field (= codec's value name)
  double value;                               // in the contract's unit
};

// "Battery (MG) CAN-format": index, subindex, type and resolution of each value.
const Row kBatteryRows[] = {
    {"0x302 0x2005/0x01 uint16 1 mV", 0x302, 0x2005, 0x01, {0x39, 0x30}, "voltage", 12.345},         // 12345 mV
    {"0x302 0x2005/0x02 int16 10 mA", 0x302, 0x2005, 0x02, {0x2E, 0xFB}, "current", -12.34},         // -1234
    {"0x302 0x2005/0x03 int16 10 mA", 0x302, 0x2005, 0x03, {0xF4, 0x01}, "current_discharge", 5.0},  // 500
    {"0x302 0x2005/0x04 int16 10 mA", 0x302, 0x2005, 0x04, {0xFA, 0x00}, "current_charge", 2.5},     // 250
    {"0x302 0x2005/0x05 int8 1 %", 0x302, 0x2005, 0x05, {0x57}, "state_of_charge", 87},
    {"0x302 0x2005/0x07 uint16 1 min", 0x302, 0x2005, 0x07, {0x5F, 0x00}, "time_to_go", 95 * 60.0},  // s
    {"0x402 0x2005/0x09 int8 1 degC", 0x402, 0x2005, 0x09, {0xFB}, "cell_temperature_high", -5},
    {"0x402 0x2005/0x0B int8 1 degC", 0x402, 0x2005, 0x0B, {0xEC}, "cell_temperature_low", -20},
    {"0x402 0x2005/0x0C uint16 1 mV", 0x402, 0x2005, 0x0C, {0x36, 0x10}, "cell_voltage_high", 4.150},
    {"0x402 0x2005/0x0D uint16 1 mV", 0x402, 0x2005, 0x0D, {0x3C, 0x0F}, "cell_voltage_low", 3.900},
    {"0x402 0x2005/0x0E uint32", 0x402, 0x2005, 0x0E, {0x04, 0x03, 0x02, 0x01}, "bms_state", 0x01020304},
    {"0x402 0x2005/0x0F 4x uint8 1 degC", 0x402, 0x2005, 0x0F, {20, 21, 22, 23}, "temperature_1", 20},
    {"0x402 0x2005/0x0F byte 2", 0x402, 0x2005, 0x0F, {20, 21, 22, 23}, "temperature_2", 21},
    {"0x402 0x2005/0x0F byte 3", 0x402, 0x2005, 0x0F, {20, 21, 22, 23}, "temperature_3", 22},
    {"0x402 0x2005/0x0F byte 4", 0x402, 0x2005, 0x0F, {20, 21, 22, 23}, "temperature_4", 23},
    {"0x202 uint8 1 % (index and subindex: don't care)", 0x202, 0x1234, 0x56, {0x4D}, "power_level", 77},
};

// "MPPT CAN-format", device 3: 0x4E6 + 3 x 8 = 0x4FE, and the duty-cycle table on 0x4FF.
const Row kMpptRows[] = {
    {"sub 0x00 int16", 0x4FE, 0, 0x00, {0x9C, 0xFF}, "voltage_output_raw", -100},
    {"sub 0x01 int16", 0x4FE, 0, 0x01, {0x10, 0x27}, "current_output_raw", 10000},
    {"sub 0x02 int16", 0x4FE, 0, 0x02, {0x01, 0x80}, "voltage_out_sw_raw", -32767},
    {"sub 0x03 uint8", 0x4FE, 0, 0x03, {0x02}, "mppt_state", 2},
    {"sub 0x04 bool", 0x4FE, 0, 0x04, {0x01}, "safety_enabled", 1},
    {"sub 0x05 bool", 0x4FE, 0, 0x05, {0x01}, "pwm_enabled", 1},
    {"sub 0x06 int8 1 degC", 0x4FE, 0, 0x06, {0xF6}, "temperature", -10},
    {"sub 0x08 int16", 0x4FE, 0, 0x08, {0x01, 0x01}, "voltage_panel_1_raw", 257},
    {"sub 0x09 int16", 0x4FE, 0, 0x09, {0x02, 0x01}, "current_panel_1_raw", 258},
    {"sub 0x0A int16", 0x4FE, 0, 0x0A, {0x03, 0x01}, "voltage_panel_2_raw", 259},
    {"sub 0x0B int16", 0x4FE, 0, 0x0B, {0x04, 0x01}, "current_panel_2_raw", 260},
    {"sub 0x0C int16", 0x4FE, 0, 0x0C, {0x05, 0x01}, "voltage_panel_3_raw", 261},
    {"sub 0x0D int16", 0x4FE, 0, 0x0D, {0x06, 0x01}, "current_panel_3_raw", 262},
    {"sub 0x0E int16", 0x4FE, 0, 0x0E, {0x07, 0x01}, "voltage_panel_4_raw", 263},
    {"sub 0x0F int16", 0x4FE, 0, 0x0F, {0x08, 0x01}, "current_panel_4_raw", 264},
    {"second id sub 0x01 uint8 1 %", 0x4FF, 0, 0x01, {31}, "duty_cycle_panel_1", 31},
    {"second id sub 0x02 uint8 1 %", 0x4FF, 0, 0x02, {32}, "duty_cycle_panel_2", 32},
    {"second id sub 0x03 uint8 1 %", 0x4FF, 0, 0x03, {33}, "duty_cycle_panel_3", 33},
    {"second id sub 0x04 uint8 1 %", 0x4FF, 0, 0x04, {34}, "duty_cycle_panel_4", 34},
    {"second id sub 0x05 4x uint8", 0x4FF, 0, 0x05, {1, 0, 1, 0}, "channel_1_active", 1},
    {"second id sub 0x05 byte 2", 0x4FF, 0, 0x05, {1, 0, 1, 0}, "channel_2_active", 0},
    {"second id sub 0x05 byte 3", 0x4FF, 0, 0x05, {1, 0, 1, 0}, "channel_3_active", 1},
    {"second id sub 0x05 byte 4", 0x4FF, 0, 0x05, {1, 0, 1, 0}, "channel_4_active", 0},
};

Timeouts thresholds() {
  Timeouts t;
  t.stale_periods = 3;
  t.offline_periods = 10;
  return t;
}

DeviceKey battery_key() { return {"can0", 2, DeviceKind::Battery}; }
DeviceKey mppt_key(std::uint8_t device) { return {"can0", device, DeviceKind::Mppt}; }

template <std::size_t N>
void expect_only(const CanOpenValues<N>& state, const CanOpenValue (&table)[N], const Row& row,
                 std::initializer_list<const char*> also_received) {
  for (std::size_t i = 0; i < N; ++i) {
    SCOPED_TRACE(table[i].name);
    const bool mine = table[i].name == row.field;
    bool other = false;
    for (const char* a : also_received) other |= table[i].name == a;
    if (mine) {
      EXPECT_NEAR(state.values[i], row.value, 1e-9);
    } else if (!other) {
      EXPECT_TRUE(std::isnan(state.values[i])) << "not received, so NaN, never 0";
    }
  }
}

TEST(CanOpenSession, EveryBatteryValueOfTheDocumentReachesItsFieldInItsUnit) {
  for (const auto& row : kBatteryRows) {
    SCOPED_TRACE(std::string(row.section) + " -> " + row.field);
    RecordingSink sink;
    CanOpenSession s(battery_key(), 1s, 200ms, thresholds(), sink, t0);
    s.on_frame(canopen_frame(row.cob_id, row.index, row.subindex, row.bytes), t0, w0);
    s.tick(t0, {});
    ASSERT_EQ(sink.batteries.size(), 1u);
    EXPECT_TRUE(sink.cells.empty());
    EXPECT_EQ(sink.batteries[0].key, battery_key());
    const bool collection = std::string(row.field).rfind("temperature_", 0) == 0;
    expect_only(sink.batteries[0].state, kBatteryValues, row,
                collection ? std::initializer_list<const char*>{"temperature_1", "temperature_2", "temperature_3",
                                                                "temperature_4"}
                           : std::initializer_list<const char*>{});
    EXPECT_EQ(sink.batteries[0].newest, w0);
  }
}

TEST(CanOpenSession, EveryMpptValueOfTheDocumentReachesItsField) {
  for (const auto& row : kMpptRows) {
    SCOPED_TRACE(std::string(row.section) + " -> " + row.field);
    RecordingSink sink;
    CanOpenSession s(mppt_key(3), 1s, 200ms, thresholds(), sink, t0);
    ASSERT_EQ(canopen_device("can0", canopen_frame(row.cob_id, 0, row.subindex, row.bytes)), mppt_key(3));
    s.on_frame(canopen_frame(row.cob_id, row.index, row.subindex, row.bytes), t0, w0);
    s.tick(t0, {});
    ASSERT_EQ(sink.mppts.size(), 1u);
    const bool map = std::string(row.field).rfind("channel_", 0) == 0;
    expect_only(sink.mppts[0].state, kMpptValues, row,
                map ? std::initializer_list<const char*>{"channel_1_active", "channel_2_active", "channel_3_active",
                                                         "channel_4_active"}
                    : std::initializer_list<const char*>{});
  }
}

TEST(CanOpenSession, TheTablesNameEveryValueTheCodecDecodes) {
  // Each table row is one slot: a codec name no slot takes would be dropped silently.
  for (const auto& row : kBatteryRows) EXPECT_TRUE(battery_slot(row.field).has_value()) << row.field;
  for (const auto& row : kMpptRows) EXPECT_TRUE(mppt_slot(row.field).has_value()) << row.field;
  EXPECT_EQ(std::size(kBatteryRows), kBatteryValueCount);
  EXPECT_EQ(std::size(kMpptRows), kMpptValueCount);
}

TEST(CanOpenSession, DevicesAreFoundByTheirCobIds) {
  const struct {
    std::uint16_t id;
    bool extended;
    std::optional<DeviceKey> key;
  } cases[] = {
      {0x202, false, battery_key()}, {0x302, false, battery_key()}, {0x402, false, battery_key()},
      {0x482, false, battery_key()}, {0x4E6, false, mppt_key(0)},   {0x4E7, false, mppt_key(0)},
      {0x4E8, false, std::nullopt},  {0x51E, false, mppt_key(7)},   {0x51F, false, mppt_key(7)},
      {0x4E5, false, std::nullopt},  {0x203, false, std::nullopt},  {0x302, true, std::nullopt},
  };
  for (const auto& c : cases) {
    codec::CanFrame f;
    f.id = c.id;
    f.extended = c.extended;
    EXPECT_EQ(canopen_device("can0", f), c.key) << std::hex << c.id;
  }
}

TEST(CanOpenSession, CellVoltagesGoToTheirOwnTopicByCellNumber) {
  RecordingSink sink;
  CanOpenSession s(battery_key(), 1s, 200ms, thresholds(), sink, t0);
  s.on_frame(canopen_frame(0x482, 0x2000, 1, {0xE5, 0x0C}), t0, w0);         // cell 1: 3301 mV
  s.on_frame(canopen_frame(0x482, 0x2000, 12, {0xE7, 0x0C}), t0, w0 + 1ms);  // cell 12: 3303 mV
  s.tick(t0, {});
  EXPECT_TRUE(sink.batteries.empty()) << "cells are not battery values";
  ASSERT_EQ(sink.cells.size(), 1u);
  const auto& v = sink.cells[0].state.volts;
  EXPECT_NEAR(v[1], 3.301, 1e-9);
  EXPECT_NEAR(v[12], 3.303, 1e-9);
  std::size_t received = 0;
  for (const double x : v) received += std::isnan(x) ? 0u : 1u;
  EXPECT_EQ(received, 2u);
  EXPECT_EQ(sink.cells[0].newest, w0 + 1ms);
}

TEST(CanOpenSession, OneSamplePerPublishPeriodWithTheNewestFramesTime) {
  RecordingSink sink;
  CanOpenSession s(battery_key(), 1s, 200ms, thresholds(), sink, t0);
  // A burst in one turn: one sample with both values and the later frame's time.
  s.on_frame(canopen_frame(0x302, 0x2005, 0x01, {0x39, 0x30}), t0, w0 + 5ms);
  s.on_frame(canopen_frame(0x302, 0x2005, 0x05, {50}), t0, w0 + 7ms);
  s.tick(t0, {});
  ASSERT_EQ(sink.batteries.size(), 1u);
  EXPECT_EQ(sink.batteries[0].newest, w0 + 7ms);
  EXPECT_NEAR(sink.batteries[0].state.values[*battery_slot("voltage")], 12.345, 1e-9);
  EXPECT_EQ(sink.batteries[0].state.values[*battery_slot("state_of_charge")], 50);
  // Within the period: held back, not lost.
  s.on_frame(canopen_frame(0x302, 0x2005, 0x05, {49}), t0 + 50ms, w0 + 55ms);
  s.tick(t0 + 50ms, {});
  s.tick(t0 + 199ms, {});
  EXPECT_EQ(sink.batteries.size(), 1u);
  s.tick(t0 + 200ms, {});
  ASSERT_EQ(sink.batteries.size(), 2u);
  EXPECT_EQ(sink.batteries[1].state.values[*battery_slot("state_of_charge")], 49);
  EXPECT_EQ(sink.batteries[1].newest, w0 + 55ms);
  // Nothing new: nothing published.
  s.tick(t0 + 1000ms, {});
  EXPECT_EQ(sink.batteries.size(), 2u);
  // A frame whose receive time is older than one already in the state keeps the newest time.
  s.on_frame(canopen_frame(0x302, 0x2005, 0x01, {0x3A, 0x30}), t0 + 1100ms, w0 + 40ms);
  s.tick(t0 + 1100ms, {});
  ASSERT_EQ(sink.batteries.size(), 3u);
  EXPECT_EQ(sink.batteries[2].newest, w0 + 55ms);
}

TEST(CanOpenSession, AfterOfflineEveryValueIsForgotten) {
  RecordingSink sink;
  CanOpenSession s(battery_key(), 1s, 200ms, thresholds(), sink, t0);
  s.on_frame(canopen_frame(0x302, 0x2005, 0x01, {0x39, 0x30}), t0, w0);
  s.tick(t0, {});
  s.tick(t0 + 10001ms, {});  // 10 periods of 1 s without a frame
  EXPECT_EQ(s.health().state, HealthState::Offline);
  s.on_frame(canopen_frame(0x302, 0x2005, 0x05, {40}), t0 + 12s, w0 + 12s);
  s.tick(t0 + 12s, {});
  ASSERT_EQ(sink.batteries.size(), 2u);
  const auto& after = sink.batteries[1].state;
  EXPECT_TRUE(std::isnan(after.values[*battery_slot("voltage")])) << "the old unit's voltage must not survive";
  EXPECT_EQ(after.values[*battery_slot("state_of_charge")], 40);
  EXPECT_EQ(after.received_mask(), 1u << *battery_slot("state_of_charge"));
  EXPECT_EQ(s.health().state, HealthState::Online);
  EXPECT_EQ(s.health().reconnects, 1u);
}

TEST(CanOpenSession, HealthFollowsTheConfiguredPeriod) {
  RecordingSink sink;
  CanOpenSession s(battery_key(), 2s, 200ms, thresholds(), sink, t0);
  s.tick(t0, {});
  EXPECT_EQ(s.health().state, HealthState::Unknown);
  s.tick(t0 + 20001ms, {});  // never heard: OFFLINE after offline_periods x period
  EXPECT_EQ(s.health().state, HealthState::Offline);
  const Steady t1 = t0 + 30s;
  s.on_frame(canopen_frame(0x202, 0, 0, {80}), t1, w0);
  s.tick(t1, {});
  EXPECT_EQ(s.health().state, HealthState::Online);
  s.tick(t1 + 6000ms, {});  // 3 x 2 s: still ONLINE
  EXPECT_EQ(s.health().state, HealthState::Online);
  s.tick(t1 + 6001ms, {});  // a silent BMS is noticed after stale_periods x period
  EXPECT_EQ(s.health().state, HealthState::Stale);
  s.tick(t1 + 20001ms, {});
  EXPECT_EQ(s.health().state, HealthState::Offline);
  ASSERT_FALSE(sink.healths.empty());
  EXPECT_EQ(sink.healths.back().first, battery_key());
  EXPECT_EQ(sink.healths.back().second.state, HealthState::Offline);
}

TEST(CanOpenSession, AFrameThatDoesNotDecodeCountsAndPublishesNothing) {
  RecordingSink sink;
  CanOpenSession s(battery_key(), 1s, 200ms, thresholds(), sink, t0);
  s.on_frame(canopen_frame(0x302, 0x2005, 0x06, {1, 2}), t0, w0);  // 0x06 is blank in the document
  s.on_frame(canopen_frame(0x302, 0x2005, 0x01, {}), t0, w0);      // too short for a value
  s.tick(t0, {});
  EXPECT_TRUE(sink.batteries.empty());
  EXPECT_EQ(s.health().decode_errors, 2u);
  EXPECT_EQ(s.health().frames_received, 2u);
  EXPECT_EQ(s.health().state, HealthState::Online) << "it speaks, even if not what we understand";
}

}  // namespace
}  // namespace pmu::service::test
