// The EnergyTracker in front of the publishers (interface.md 1.8): it passes every event on,
// takes each PMU's critical voltages from the config as its alarms run with them, and hands
// on figures at most once a second of the samples' receive time.
#include <gtest/gtest.h>

#include <cmath>

#include "pmu/energy_sink/energy_tracker.hpp"
#include "recording_sink.hpp"

namespace pmu::service::test::energy_tracker {
namespace {

using namespace std::chrono_literals;
const auto t0 = std::chrono::system_clock::time_point{} + std::chrono::hours(24 * 365 * 56);

codec::PmuMessage voltages(std::uint16_t address, double battery_a) {
  codec::Voltages v;
  v.avionics = 12;
  v.output_28v = 28;
  v.payload = 12;
  v.servo = 6;
  v.battery_a = battery_a;
  v.battery_b = 22;
  codec::PmuMessage m;
  m.packet = codec::PacketId::Voltages;
  m.address = address;
  m.payload = v;
  return m;
}

codec::PmuMessage currents(std::uint16_t address, double battery_a) {
  codec::PmuMessage m;
  m.packet = codec::PacketId::Currents;
  m.address = address;
  m.payload = codec::Currents{1, 1, 2, 0.5, battery_a, 0};
  return m;
}

// Bus can0: PMU 1 with battery A's critical voltage set to 20.5 V, PMU 2 with the table's;
// discovered PMUs take 21.0 V from `discover:`.
std::vector<BusConfig> buses() {
  BusConfig b;
  b.name = "can0";
  DeviceConfig one;
  one.address = 1;
  one.alarms[alarms::Code::BatteryACriticalVoltage].limit = 20.5;
  DeviceConfig two;
  two.address = 2;
  b.devices = {one, two};
  b.discovered_defaults.alarms[alarms::Code::BatteryACriticalVoltage].limit = 21.0;
  return {b};
}

// 2 minutes of battery A at 5 A out, falling 1 mV/s from 22.0 V, one sample of each a second.
void discharge(EnergyTracker& tracker, std::uint16_t address) {
  const DeviceKey key{"can0", address, DeviceKind::Pmu};
  for (int i = 0; i <= 120; ++i) {
    tracker.on_telemetry(key, voltages(address, 22.0 - 0.001 * i), t0 + std::chrono::seconds(i));
    tracker.on_telemetry(key, currents(address, -5), t0 + std::chrono::seconds(i));
  }
}

TEST(EnergyTracker, EnduranceRunsToTheCriticalVoltageTheAlarmUses) {
  struct Row {
    std::uint16_t address;
    double critical;  // V: the config's, else the table's battery_a_critical_voltage
  };
  const Row rows[] = {{1, 20.5},
                      {2, alarms::spec_of(alarms::Code::BatteryACriticalVoltage).limit},
                      {7, 21.0}};
  for (const auto& r : rows) {
    SCOPED_TRACE(r.address);
    RecordingSink sink;
    EnergyTracker tracker(buses(), 3, sink);
    discharge(tracker, r.address);
    ASSERT_FALSE(sink.energy.empty());
    const auto& last = sink.energy.back();
    EXPECT_EQ(last.key.address, r.address);
    // Due on the voltages at 120 s, before that second's currents: the integral and the trend
    // run to the currents at 119 s.
    EXPECT_EQ(last.at, t0 + 120s);
    EXPECT_DOUBLE_EQ(last.figures.battery_a.critical_voltage, r.critical);
    // (22.0 - 0.119 - critical) / 0.001 V/s
    EXPECT_NEAR(last.figures.battery_a.endurance_s, (21.881 - r.critical) / 0.001, 1e-6);
    // 5 A at 22 V falling to 21.881 V: the mean voltage 21.9405 V for 119 s
    EXPECT_NEAR(last.figures.battery_a.used_wh, 5 * 21.9405 * 119 / 3600, 1e-9);
  }
}

TEST(EnergyTracker, PassesEveryEventOnAndReportsOncePerSecond) {
  RecordingSink sink;
  EnergyTracker tracker(buses(), 3, sink);
  discharge(tracker, 1);
  EXPECT_EQ(sink.telemetry.size(), 2u * 121u) << "every frame goes on to the publishers";
  ASSERT_EQ(sink.energy.size(), 121u) << "one a second over 0..120 s";
  for (std::size_t i = 1; i < sink.energy.size(); ++i) EXPECT_GE(sink.energy[i].at - sink.energy[i - 1].at, 1s);
}

TEST(EnergyTracker, AGoneDeviceStartsAgain) {
  RecordingSink sink;
  EnergyTracker tracker(buses(), 3, sink);
  discharge(tracker, 1);
  ASSERT_GT(sink.energy.back().figures.battery_a.used_wh, 0);
  tracker.on_gone(DeviceKey{"can0", 1, DeviceKind::Pmu});
  ASSERT_EQ(sink.gone.size(), 1u);
  const DeviceKey key{"can0", 1, DeviceKind::Pmu};
  tracker.on_telemetry(key, voltages(1, 22), t0 + 200s);
  tracker.on_telemetry(key, currents(1, -5), t0 + 200s);
  ASSERT_EQ(sink.energy.back().at, t0 + 200s);
  EXPECT_EQ(sink.energy.back().figures.battery_a.used_wh, 0);
  EXPECT_TRUE(std::isnan(sink.energy.back().figures.battery_a.endurance_s));
}

}  // namespace
}  // namespace pmu::service::test::energy_tracker
