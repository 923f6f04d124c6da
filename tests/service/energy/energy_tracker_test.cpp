// The EnergyTracker in front of the publishers (interface.md 1.8): it passes every event on,
// takes each PMU's critical voltages from the config as its alarms run with them, and hands
// on figures at most once a second of the samples' receive time.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "pmu/energy_sink/energy_tracker.hpp"
#include "support/recording_sink.hpp"

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
  const Row rows[] = {{1, 20.5}, {2, alarms::spec_of(alarms::Code::BatteryACriticalVoltage).limit}, {7, 21.0}};
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

TEST(EnergyTracker, HandsOnOnceEachEventItDerivesNothingFrom) {
  RecordingSink sink;
  EnergyTracker tracker(buses(), 3, sink);
  const DeviceKey pmu{"can0", 1, DeviceKind::Pmu};
  tracker.on_config(pmu, ConfigState{});
  tracker.on_info(pmu, InfoState{});
  tracker.on_health(pmu, HealthReport{});
  tracker.on_battery_cells(DeviceKey{"can0", 2, DeviceKind::Battery}, BatteryCellsState{}, t0);
  tracker.on_mppt(DeviceKey{"can0", 0, DeviceKind::Mppt}, MpptState{}, t0);
  tracker.on_alarm(AlarmReport{});
  tracker.on_readiness(ReadinessReport{});
  tracker.on_energy(pmu, energy::Figures{}, t0);
  tracker.on_bms_energy(DeviceKey{"can0", 2, DeviceKind::Battery}, energy::BmsFigures{}, t0);
  const std::pair<const char*, std::size_t> handed_on[] = {
      {"config", sink.configs.size()},      {"info", sink.infos.size()},    {"health", sink.healths.size()},
      {"cells", sink.cells.size()},         {"mppt", sink.mppts.size()},    {"alarm", sink.alarms.size()},
      {"readiness", sink.readiness.size()}, {"energy", sink.energy.size()}, {"bms_energy", sink.bms_energy.size()},
  };
  for (const auto& [event, count] : handed_on) EXPECT_EQ(count, 1u) << event;
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

// A pmu/battery sample: voltage, current (+ charging) and state of charge; the rest not received.
BatteryState battery(double volts, double amps, double soc) {
  BatteryState b;
  b.values[*battery_slot("voltage")] = volts;
  b.values[*battery_slot("current")] = amps;
  b.values[*battery_slot("state_of_charge")] = soc;
  return b;
}

// Bus can0 lists battery 2 with 20 Ah and bms_critical_soc at 10 %; can1 hears batteries
// through listen_canopen.
std::vector<BusConfig> battery_buses() {
  BusConfig b;
  b.name = "can0";
  BatteryConfig two;
  two.node = 2;
  two.capacity_ah = 20.0;
  two.alarms[alarms::Code::BmsCriticalSoc].limit = 10;
  b.batteries = {two};
  BusConfig heard;
  heard.name = "can1";
  heard.listen_canopen = true;
  return {b, heard};
}

TEST(EnergyTracker, BatteryFiguresUseItsCapacityAndCriticalStateOfCharge) {
  struct Row {
    const char* bus;
    double capacity_ah, critical;  // the config's, or none and the table's bms_critical_soc
  };
  const Row rows[] = {
      {"can0", 20, 10},
      {"can1", std::numeric_limits<double>::quiet_NaN(), alarms::spec_of(alarms::Code::BmsCriticalSoc).limit}};
  for (const auto& r : rows) {
    SCOPED_TRACE(r.bus);
    RecordingSink sink;
    EnergyTracker tracker(battery_buses(), 3, sink);
    const DeviceKey key{r.bus, 2, DeviceKind::Battery};
    // 0.2 s apart for 10 s: 48 V, 5 A out, 60 %.
    for (int i = 0; i <= 50; ++i) tracker.on_battery(key, battery(48, -5, 60), t0 + i * 200ms);
    EXPECT_EQ(sink.batteries.size(), 51u) << "every sample goes on to the publishers";
    ASSERT_EQ(sink.bms_energy.size(), 11u) << "one a second over 0..10 s";
    for (std::size_t i = 1; i < sink.bms_energy.size(); ++i)
      EXPECT_EQ(sink.bms_energy[i].at - sink.bms_energy[i - 1].at, 1s);
    const auto& last = sink.bms_energy.back();
    EXPECT_EQ(last.key, key);
    EXPECT_EQ(last.at, t0 + 10s);
    EXPECT_DOUBLE_EQ(last.figures.power, -240);
    EXPECT_NEAR(last.figures.used_wh, 240.0 * 10 / 3600, 1e-12);
    EXPECT_NEAR(last.figures.integrated_s, 10, 1e-9);
    EXPECT_DOUBLE_EQ(last.figures.critical_state_of_charge, r.critical);
    if (std::isnan(r.capacity_ah)) {
      EXPECT_TRUE(std::isnan(last.figures.capacity_ah));
      EXPECT_TRUE(std::isnan(last.figures.endurance_s)) << "no capacity, no endurance";
    } else {
      EXPECT_DOUBLE_EQ(last.figures.capacity_ah, r.capacity_ah);
      EXPECT_NEAR(last.figures.endurance_s, (60 - r.critical) / 100 * r.capacity_ah / 5 * 3600, 1e-6);
    }
  }
}

TEST(EnergyTracker, MpptsAndPmusGiveNoBatteryFigures) {
  RecordingSink sink;
  EnergyTracker tracker(battery_buses(), 3, sink);
  discharge(tracker, 1);
  tracker.on_mppt(DeviceKey{"can0", 0, DeviceKind::Mppt}, MpptState{}, t0);
  EXPECT_TRUE(sink.bms_energy.empty());
  EXPECT_EQ(sink.mppts.size(), 1u);
}

}  // namespace
}  // namespace pmu::service::test::energy_tracker
