// The alarms of batteries, MPPTs (canopen_session.cpp) and of the bus itself (bus_worker.cpp),
// through the bus worker on the fake clock, with battery and MPPT frames sent by a node of the
// test's own as canopen_worker_test does.
#include <gtest/gtest.h>

#include <functional>
#include <optional>

#include "support/canopen_frames.hpp"
#include "support/harness.hpp"

namespace pmu::service::test {
namespace {

using alarms::AlarmState;
using alarms::Code;

std::optional<AlarmState> last(const RecordingSink& sink, Code code, alarms::DeviceKind source) {
  std::optional<AlarmState> s;
  for (const auto& a : sink.alarms)
    if (a.code == code && a.source == source) s = a.state;
  return s;
}

// What the BMS reports; sent whole once a second.
struct Bms {
  int soc = 80;                                     // %
  std::uint16_t cell_high = 3950, cell_low = 3900;  // mV
  int cell_temperature_high = 25;                   // degC
};

struct BatteryBench {
  BatteryBench() : h(bus_of(), {pmu(1)}), node(h.network().attach("bms")) {}
  static BusConfig bus_of() {
    BusConfig b = sim_bus({device(1)});
    b.batteries.push_back(BatteryConfig{2, 1000ms, {}, {}});
    return b;
  }
  void send() {
    auto u8 = [](int v) { return static_cast<std::uint8_t>(v); };
    ASSERT_TRUE(node->send(canopen_frame(0x302, 0x2005, 0x05, {u8(bms.soc)}), 0ms).ok());
    ASSERT_TRUE(node->send(canopen_frame(0x402, 0x2005, 0x09, {u8(bms.cell_temperature_high)}), 0ms).ok());
    ASSERT_TRUE(
        node->send(canopen_frame(0x402, 0x2005, 0x0C, {u8(bms.cell_high & 0xFF), u8(bms.cell_high >> 8)}), 0ms).ok());
    ASSERT_TRUE(
        node->send(canopen_frame(0x402, 0x2005, 0x0D, {u8(bms.cell_low & 0xFF), u8(bms.cell_low >> 8)}), 0ms).ok());
  }
  // `total` of BMS life, its frames once a second from the start.
  void run_for(std::chrono::milliseconds total) {
    for (auto t = 0ms; t < total; t += 1000ms) {
      send();
      h.run_for(std::min(1000ms, total - t), 50ms);
    }
  }
  std::optional<AlarmState> last(Code code) const { return test::last(h.sink, code, alarms::DeviceKind::Battery); }

  Harness h;
  std::unique_ptr<transport::CanBus> node;
  Bms bms;
};

struct BatteryCase {
  const char* name;
  Code code;
  std::function<void(Bms&)> raise;
  std::chrono::milliseconds on_delay;
  AlarmState after_clear;
};

const BatteryCase kBattery[] = {
    {"SOC 10 %", Code::BmsLowSoc, [](Bms& b) { b.soc = 10; }, 10000ms, AlarmState::Normal},
    {"SOC 5 %", Code::BmsCriticalSoc, [](Bms& b) { b.soc = 5; }, 10000ms, AlarmState::ClearedUnacknowledged},
    {"lowest cell 3.20 V", Code::CellLow, [](Bms& b) { b.cell_low = 3200; }, 10000ms, AlarmState::Normal},
    {"cells 3.95 and 3.75 V", Code::CellImbalance, [](Bms& b) { b.cell_low = 3750; }, 30000ms, AlarmState::Normal},
    {"cells at 65 degC", Code::BmsOverTemperature, [](Bms& b) { b.cell_temperature_high = 65; }, 5000ms,
     AlarmState::ClearedUnacknowledged},
};

TEST(CanOpenAlarms, EachBatteryCodeIsRaisedByWhatTheBmsReports) {
  for (const auto& c : kBattery) {
    SCOPED_TRACE(c.name);
    BatteryBench b;
    b.run_for(3s);
    ASSERT_TRUE(b.h.sink.alarms.empty()) << alarms::to_string(b.h.sink.alarms.front().code);
    c.raise(b.bms);
    b.run_for(c.on_delay - 1000ms);
    EXPECT_FALSE(b.last(c.code)) << "raised before its on-delay";
    b.run_for(2s);
    ASSERT_EQ(b.last(c.code), AlarmState::ActiveUnacknowledged);
    const AlarmReport& r = b.h.sink.alarms.back();
    EXPECT_EQ(r.source, alarms::DeviceKind::Battery);
    EXPECT_EQ(r.device, 2);
    EXPECT_EQ(r.bus, "sim0");
    b.bms = Bms{};
    b.run_for(alarms::spec_of(c.code).off_delay + 2s);
    EXPECT_EQ(b.last(c.code), c.after_clear);
  }
}

TEST(CanOpenAlarms, ASilentBatteryIsStaleThenOffline) {
  BatteryBench b;
  b.run_for(2s);
  b.h.run_for(2500ms);  // stale after 3 x 1 s
  EXPECT_EQ(b.last(Code::DeviceStale), AlarmState::ActiveUnacknowledged);
  EXPECT_FALSE(b.last(Code::DeviceOffline));
  b.h.run_for(7s);
  EXPECT_EQ(b.last(Code::DeviceOffline), AlarmState::ActiveUnacknowledged);
  b.run_for(2s);
  EXPECT_EQ(b.last(Code::DeviceStale), AlarmState::Normal);
  EXPECT_EQ(b.last(Code::DeviceOffline), AlarmState::ClearedUnacknowledged);
}

TEST(CanOpenAlarms, AnMpptRaisesOnlyItsHealth) {
  BusConfig bus = sim_bus({device(1)});
  bus.mppts.push_back(MpptConfig{3, 1000ms, {}});
  bus.mppts.push_back(MpptConfig{4, 1000ms, {}});
  Harness h(bus, {pmu(1)});
  auto node = h.network().attach("mppt");
  // The document gives no MPPT State values: none of them is a fault.
  for (int i = 0; i < 20; ++i) {
    for (const int state : {0, 1, 2, 7, 255})
      ASSERT_TRUE(node->send(canopen_frame(mppt_id(3), 0, 0x03, {static_cast<std::uint8_t>(state)}), 0ms).ok());
    ASSERT_TRUE(node->send(canopen_frame(mppt_id(3), 0, 0x04, {0}), 0ms).ok());
    h.run_for(1s);
  }
  for (const auto& a : h.sink.alarms) {
    EXPECT_EQ(a.device, 4) << "only the MPPT never heard: " << alarms::to_string(a.code);
    EXPECT_EQ(a.source, alarms::DeviceKind::Mppt);
  }
  EXPECT_EQ(last(h.sink, Code::DeviceOffline, alarms::DeviceKind::Mppt), AlarmState::ActiveUnacknowledged);
}

TEST(CanOpenAlarms, TheBusRaisesErrorPassiveAndBusOff) {
  Harness h(sim_bus({device(1)}), {pmu(1)});
  const auto bus_alarm = [&](Code code) { return last(h.sink, code, alarms::DeviceKind::Bus); };
  h.run_for(1s);
  EXPECT_FALSE(bus_alarm(Code::BusErrorPassive));
  h.network().set_state(transport::BusState::ErrorPassive);
  h.run_for(50ms);
  ASSERT_EQ(bus_alarm(Code::BusErrorPassive), AlarmState::ActiveUnacknowledged);
  EXPECT_EQ(h.sink.alarms.back().device, 0);
  EXPECT_EQ(h.sink.alarms.back().bus, "sim0");
  EXPECT_FALSE(bus_alarm(Code::BusOff));
  h.network().set_state(transport::BusState::BusOff);
  h.run_for(50ms);
  EXPECT_EQ(bus_alarm(Code::BusOff), AlarmState::ActiveUnacknowledged);
  h.network().set_state(transport::BusState::Up);
  h.run_for(50ms);
  EXPECT_EQ(bus_alarm(Code::BusOff), AlarmState::ClearedUnacknowledged) << "critical: latched";
  EXPECT_EQ(h.worker().acknowledge_bus_alarm(Code::BusOff), alarms::AckResult::Acknowledged);
  EXPECT_EQ(bus_alarm(Code::BusOff), AlarmState::Normal);
  EXPECT_EQ(bus_alarm(Code::BusErrorPassive), AlarmState::ActiveUnacknowledged) << "5 s off-delay";
  h.run_for(5s);
  EXPECT_EQ(bus_alarm(Code::BusErrorPassive), AlarmState::Normal);
}

TEST(CanOpenAlarms, ABusThatStartsErrorPassiveIsAlarmedAtOnce) {
  transport::ManualClock clock;
  transport::SimulatedNetwork network(clock);
  auto bus = network.attach("sim0");
  network.set_state(transport::BusState::ErrorPassive);
  RecordingSink sink;
  BusWorker w(sim_bus({device(1)}), std::move(bus), clock, Timeouts{}, sink);
  EXPECT_EQ(last(sink, Code::BusErrorPassive, alarms::DeviceKind::Bus), AlarmState::ActiveUnacknowledged);
}

TEST(CanOpenAlarms, TheBusSettingsApply) {
  BusConfig bus = sim_bus({device(1)});
  bus.alarms[Code::BusErrorPassive].enabled = false;
  Harness h(bus, {pmu(1)});
  h.network().set_state(transport::BusState::BusOff);
  h.run_for(50ms);
  EXPECT_FALSE(last(h.sink, Code::BusErrorPassive, alarms::DeviceKind::Bus));
  EXPECT_EQ(last(h.sink, Code::BusOff, alarms::DeviceKind::Bus), AlarmState::ActiveUnacknowledged);
}

}  // namespace
}  // namespace pmu::service::test
