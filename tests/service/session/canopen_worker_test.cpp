// Batteries and MPPTs through the bus worker (bus_worker.hpp), with frames injected on the
// in-process bus by a node of the test's own, a fake clock, and a PMU on the same bus.
#include <gtest/gtest.h>

#include <cmath>

#include "support/canopen_frames.hpp"
#include "support/harness.hpp"
#include "pmu/session/receive_filters.hpp"

namespace pmu::service::test {
namespace {

BusConfig bus_with(std::vector<BatteryConfig> batteries, std::vector<MpptConfig> mppts, bool listen = false) {
  BusConfig b = sim_bus({device(1)});
  b.batteries = std::move(batteries);
  b.mppts = std::move(mppts);
  b.listen_canopen = listen;
  return b;
}

TEST(CanOpenWorker, ConfiguredDevicesArePublishedBesideThePmu) {
  Harness h(bus_with({BatteryConfig{2, 1000ms, {}, {}}}, {MpptConfig{5, 1000ms, {}}}), {pmu(1)});
  auto node = h.network().attach("bms-and-mppt");
  ASSERT_TRUE(h.worker().canopen_session(DeviceKind::Battery, 2));
  ASSERT_TRUE(h.worker().canopen_session(DeviceKind::Mppt, 5));
  const auto sent_at = h.clock().system_now();
  ASSERT_TRUE(node->send(canopen_frame(0x302, 0x2005, 0x01, {0x39, 0x30}), 0ms).ok());
  ASSERT_TRUE(node->send(canopen_frame(mppt_id(5), 0, 0x06, {25}), 0ms).ok());
  h.run_for(500ms);
  ASSERT_FALSE(h.sink.batteries.empty());
  EXPECT_EQ(h.sink.batteries.back().key, (DeviceKey{"sim0", 2, DeviceKind::Battery}));
  EXPECT_NEAR(h.sink.batteries.back().state.values[*battery_slot("voltage")], 12.345, 1e-9);
  EXPECT_EQ(h.sink.batteries.back().newest, sent_at) << "the sample's time is its frame's receive time";
  ASSERT_FALSE(h.sink.mppts.empty());
  EXPECT_EQ(h.sink.mppts.back().key, (DeviceKey{"sim0", 5, DeviceKind::Mppt}));
  EXPECT_EQ(h.sink.mppts.back().state.values[*mppt_slot("temperature")], 25);
  // The PMU's conversation is untouched: its identity was read, it is ONLINE.
  ASSERT_FALSE(h.sink.infos.empty());
  EXPECT_EQ(h.sink.infos.back().first, (DeviceKey{"sim0", 1}));
  EXPECT_EQ(h.sink.last_health(1)->state, HealthState::Online);
  const auto* battery = h.sink.last_health(2, DeviceKind::Battery);
  ASSERT_NE(battery, nullptr);
  EXPECT_EQ(battery->state, HealthState::Online);
}

TEST(CanOpenWorker, ASilentBatteryIsNoticedWithinPeriodTimesStalePeriods) {
  Timeouts t;
  t.stale_periods = 3;
  t.offline_periods = 10;
  Harness h(bus_with({BatteryConfig{2, 500ms, {}, {}}}, {}), {pmu(1)}, t);
  auto node = h.network().attach("bms");
  ASSERT_TRUE(node->send(canopen_frame(0x202, 0, 0, {90}), 0ms).ok());
  h.run_for(100ms);
  ASSERT_EQ(h.sink.last_health(2, DeviceKind::Battery)->state, HealthState::Online);
  h.run_for(1400ms);  // 1.5 s after the frame = 3 x 0.5 s: not yet
  EXPECT_EQ(h.sink.last_health(2, DeviceKind::Battery)->state, HealthState::Online);
  h.run_for(100ms);
  EXPECT_EQ(h.sink.last_health(2, DeviceKind::Battery)->state, HealthState::Stale);
  h.run_for(3500ms);
  EXPECT_EQ(h.sink.last_health(2, DeviceKind::Battery)->state, HealthState::Offline);
  // The PMU keeps streaming and stays ONLINE: the two are separate instances.
  EXPECT_EQ(h.sink.last_health(1)->state, HealthState::Online);
}

TEST(CanOpenWorker, AConfiguredBatteryNeverHeardGoesOffline) {
  Harness h(bus_with({BatteryConfig{2, 1000ms, {}, {}}}, {}), {pmu(1)});
  h.run_for(10500ms);
  const auto* report = h.sink.last_health(2, DeviceKind::Battery);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->state, HealthState::Offline);
  EXPECT_EQ(report->last_frame_age, -1);
}

TEST(CanOpenWorker, UnlistedDevicesAreServedOnlyWithListenCanopen) {
  for (const bool listen : {false, true}) {
    SCOPED_TRACE(listen ? "listen_canopen: true" : "listen_canopen: false");
    Harness h(bus_with({}, {}, listen), {pmu(1)});
    auto node = h.network().attach("mppt");
    ASSERT_TRUE(node->send(canopen_frame(mppt_id(2, 1), 0, 0x01, {40}), 0ms).ok());
    ASSERT_TRUE(node->send(canopen_frame(0x482, 0x2000, 3, {0xE4, 0x0C}), 0ms).ok());
    h.run_for(300ms);
    EXPECT_EQ(h.worker().canopen_session(DeviceKind::Mppt, 2) != nullptr, listen);
    EXPECT_EQ(h.worker().canopen_session(DeviceKind::Battery, 2) != nullptr, listen);
    EXPECT_EQ(h.sink.mppts.size(), listen ? 1u : 0u);
    EXPECT_EQ(h.sink.cells.size(), listen ? 1u : 0u);
    if (listen) {
      EXPECT_EQ(h.sink.mppts[0].state.values[*mppt_slot("duty_cycle_panel_1")], 40);
      EXPECT_NEAR(h.sink.cells[0].state.volts[3], 3.300, 1e-9);
    }
  }
}

TEST(CanOpenWorker, BusStateReachesBatteriesToo) {
  Harness h(bus_with({BatteryConfig{2, 1000ms, {}, {}}}, {}), {pmu(1)});
  h.network().set_state(transport::BusState::BusOff);
  h.run_for(50ms);
  const auto* report = h.sink.last_health(2, DeviceKind::Battery);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->bus_state, transport::BusState::BusOff);
}

}  // namespace
}  // namespace pmu::service::test

namespace pmu::service::test {
namespace {

// A SocketCAN bus installs these filters (main.cpp): before, every bus got the PMUs' filter
// alone, so on a real bus no battery or MPPT frame reached the service.
TEST(CanOpenWorker, ABusThatServesBatteriesOrMpptsReceivesTheirIds) {
  const codec::CanFrame battery = canopen_frame(0x302, 0x2005, 0x01, {0x39, 0x30});
  const codec::CanFrame mppt = canopen_frame(mppt_id(7, 1), 0, 0x01, {10});
  codec::CanFrame pmu_voltages;
  pmu_voltages.id = 0x1E000001;
  pmu_voltages.extended = true;
  pmu_voltages.length = 7;

  const BusConfig pmus_only = sim_bus({device(1)});
  EXPECT_TRUE(transport::accepts(receive_filters(pmus_only), pmu_voltages));
  EXPECT_FALSE(transport::accepts(receive_filters(pmus_only), battery));

  for (const auto& bus : {bus_with({BatteryConfig{}}, {}), bus_with({}, {MpptConfig{}}), bus_with({}, {}, true)}) {
    const auto filters = receive_filters(bus);
    EXPECT_TRUE(transport::accepts(filters, pmu_voltages));
    EXPECT_TRUE(transport::accepts(filters, battery));
    EXPECT_TRUE(transport::accepts(filters, mppt));
  }
}

}  // namespace
}  // namespace pmu::service::test
