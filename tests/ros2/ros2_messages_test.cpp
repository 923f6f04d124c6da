// The service's view of a device as ROS 2 messages (ros2_messages.hpp), field by field as
// sensor_msgs/BatteryState.msg and diagnostic_msgs/DiagnosticStatus.msg define them: the sign
// of current, 0..1 percentage, NaN for what is not measured, status and health from the
// current and the alarms, the diagnostic level from health and alarms.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "pmu/alarms/alarm_table.hpp"
#include "pmu/endpoints/ros2_messages.hpp"

namespace pmu::service {
namespace {

namespace Bs = sensor_msgs::msg::BatteryState_Constants;
namespace Ds = diagnostic_msgs::msg::DiagnosticStatus_Constants;
using alarms::AlarmState;
using alarms::Code;
using service::HealthState;

service::AlarmReport alarm(Code code, AlarmState state = AlarmState::ActiveUnacknowledged) {
  service::AlarmReport a;
  a.bus = "can0";
  a.code = code;
  a.severity = alarms::spec_of(code).severity;
  a.state = state;
  a.message = std::string(alarms::to_string(code)) + " message";
  return a;
}

std::string key_value(const diagnostic_msgs::msg::DiagnosticStatus& s, const std::string& key) {
  for (const auto& kv : s.values())
    if (kv.key() == key) return kv.value();
  return "<absent>";
}

TEST(Ros2Messages, PmuBatteryStatusHealthAndPresence) {
  struct Case {
    char input;
    double voltage, current;
    HealthState health;
    std::vector<service::AlarmReport> active;
    std::uint8_t status, supply_health;
    bool present;
  };
  const Case cases[] = {
      {'A', 24.6, -3.2, HealthState::Online, {}, Bs::POWER_SUPPLY_STATUS_DISCHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD, true},
      {'A', 24.6, 2.0, HealthState::Online, {}, Bs::POWER_SUPPLY_STATUS_CHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD, true},
      {'B', 24.6, 0.0, HealthState::Online, {}, Bs::POWER_SUPPLY_STATUS_NOT_CHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD, true},
      {'B',
       24.6,
       0.05,
       HealthState::Online,
       {},
       Bs::POWER_SUPPLY_STATUS_NOT_CHARGING,
       Bs::POWER_SUPPLY_HEALTH_GOOD,
       true},
      {'A', 24.6, kUnknown, HealthState::Online, {}, Bs::POWER_SUPPLY_STATUS_UNKNOWN, Bs::POWER_SUPPLY_HEALTH_GOOD, true},
      // No battery on the input: nothing is known of its health.
      {'B',
       0.0,
       0.0,
       HealthState::Online,
       {},
       Bs::POWER_SUPPLY_STATUS_NOT_CHARGING,
       Bs::POWER_SUPPLY_HEALTH_UNKNOWN,
       false},
      {'A',
       0.4,
       0.0,
       HealthState::Online,
       {alarm(Code::BatteryACriticalVoltage)},
       Bs::POWER_SUPPLY_STATUS_NOT_CHARGING,
       Bs::POWER_SUPPLY_HEALTH_UNKNOWN,
       false},
      {'A',
       kUnknown,
       kUnknown,
       HealthState::Online,
       {},
       Bs::POWER_SUPPLY_STATUS_UNKNOWN,
       Bs::POWER_SUPPLY_HEALTH_UNKNOWN,
       false},
      {'A',
       kUnknown,
       kUnknown,
       HealthState::Unknown,
       {},
       Bs::POWER_SUPPLY_STATUS_UNKNOWN,
       Bs::POWER_SUPPLY_HEALTH_UNKNOWN,
       false},
      {'A', 24.6, -1, HealthState::Stale, {}, Bs::POWER_SUPPLY_STATUS_DISCHARGING, Bs::POWER_SUPPLY_HEALTH_UNKNOWN, true},
      {'A',
       19.0,
       -1,
       HealthState::Online,
       {alarm(Code::BatteryACriticalVoltage)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_DEAD,
       true},
      // Battery B's alarm says nothing of battery A.
      {'A',
       19.0,
       -1,
       HealthState::Online,
       {alarm(Code::BatteryBCriticalVoltage)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_GOOD,
       true},
      {'B',
       19.0,
       -1,
       HealthState::Online,
       {alarm(Code::BatteryBCriticalVoltage)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_DEAD,
       true},
      // Over-temperature comes before a critical voltage.
      {'B',
       19.0,
       -1,
       HealthState::Online,
       {alarm(Code::BatteryBCriticalVoltage), alarm(Code::BatteryBOverTemperature, AlarmState::ActiveAcknowledged)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_OVERHEAT,
       true},
      // A cleared alarm (awaiting acknowledgement) is not the battery's health any more.
      {'A',
       24.0,
       -1,
       HealthState::Online,
       {alarm(Code::BatteryAOverTemperature, AlarmState::ClearedUnacknowledged)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_GOOD,
       true},
      // A low (warning) voltage is no fault of the battery's health.
      {'A',
       21.0,
       -1,
       HealthState::Online,
       {alarm(Code::BatteryALowVoltage)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_GOOD,
       true},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::string(1, c.input) + " " + std::to_string(c.voltage) + " V " + std::to_string(c.current) + " A");
    PmuBatteryView v;
    v.input = c.input;
    v.voltage = c.voltage;
    v.current = c.current;
    v.health = c.health;
    v.active = c.active;
    const auto m = pmu_battery_message(v);
    EXPECT_EQ(m.power_supply_status(), c.status);
    EXPECT_EQ(m.power_supply_health(), c.supply_health);
    EXPECT_EQ(m.present(), c.present);
  }
}

TEST(Ros2Messages, PmuBatteryFieldsAsTheMsgDefinesThem) {
  PmuBatteryView v;
  v.input = 'B';
  v.voltage = 24.6;
  v.current = -3.2;
  v.temperature = 31;
  v.pmu_serial = 4001;
  v.health = HealthState::Online;
  v.stamp = std::chrono::system_clock::time_point(std::chrono::nanoseconds(1'700'000'123'456'789'000));
  v.frame_id = "uav1/can0/pmu_1";
  const auto m = pmu_battery_message(v);
  EXPECT_EQ(m.header().stamp().sec(), 1'700'000'123);
  EXPECT_EQ(m.header().stamp().nanosec(), 456'789'000u);
  EXPECT_EQ(m.header().frame_id(), "uav1/can0/pmu_1");
  EXPECT_FLOAT_EQ(m.voltage(), 24.6f);
  EXPECT_FLOAT_EQ(m.current(), -3.2f) << "negative while discharging, as the .msg says";
  EXPECT_FLOAT_EQ(m.temperature(), 31.0f);
  // Not measured by a PMU: NaN, never 0.
  EXPECT_TRUE(std::isnan(m.percentage()));
  EXPECT_TRUE(std::isnan(m.charge()));
  EXPECT_TRUE(std::isnan(m.capacity()));
  EXPECT_TRUE(std::isnan(m.design_capacity()));
  EXPECT_TRUE(m.cell_voltage().empty());
  EXPECT_EQ(m.power_supply_technology(), Bs::POWER_SUPPLY_TECHNOLOGY_UNKNOWN);
  EXPECT_EQ(m.location(), "battery_b");
  EXPECT_EQ(m.serial_number(), "pmu 4001");
  v.pmu_serial.reset();
  v.temperature = kUnknown;
  const auto unknown = pmu_battery_message(v);
  EXPECT_EQ(unknown.serial_number(), "");
  EXPECT_TRUE(std::isnan(unknown.temperature()));
}

service::BatteryState bms_values(double voltage, double current, double soc) {
  service::BatteryState b;
  b.values[*service::battery_slot("voltage")] = voltage;
  b.values[*service::battery_slot("current")] = current;
  b.values[*service::battery_slot("state_of_charge")] = soc;
  b.values[*service::battery_slot("cell_temperature_high")] = 28;
  return b;
}

TEST(Ros2Messages, BmsBatteryFieldsAsTheMsgDefinesThem) {
  BmsView v;
  v.values = bms_values(48.1, -12.5, 64);
  v.cells.volts[0] = 3.30;
  v.cells.volts[2] = 3.32;  // cell 1 not heard
  v.capacity_ah = 20;
  v.health = HealthState::Online;
  v.frame_id = "uav1/can0/bms_2";
  v.location = "bms node 2";
  const auto m = bms_battery_message(v);
  EXPECT_FLOAT_EQ(m.voltage(), 48.1f);
  EXPECT_FLOAT_EQ(m.current(), -12.5f);
  EXPECT_FLOAT_EQ(m.percentage(), 0.64f) << "0..1, not 0..100";
  EXPECT_FLOAT_EQ(m.charge(), 12.8f) << "state of charge x the nameplate capacity";
  EXPECT_FLOAT_EQ(m.design_capacity(), 20.0f);
  EXPECT_TRUE(std::isnan(m.capacity()));
  EXPECT_FLOAT_EQ(m.temperature(), 28.0f);
  ASSERT_EQ(m.cell_voltage().size(), 3u);
  EXPECT_FLOAT_EQ(m.cell_voltage()[0], 3.30f);
  EXPECT_TRUE(std::isnan(m.cell_voltage()[1])) << "a cell not heard is NaN";
  EXPECT_FLOAT_EQ(m.cell_voltage()[2], 3.32f);
  EXPECT_TRUE(m.present());
  EXPECT_EQ(m.power_supply_status(), Bs::POWER_SUPPLY_STATUS_DISCHARGING);
  EXPECT_EQ(m.power_supply_health(), Bs::POWER_SUPPLY_HEALTH_GOOD);
  EXPECT_EQ(m.location(), "bms node 2");

  // Cells numbered from 1: the first is cell 1.
  v.cells = {};
  v.cells.volts[1] = 3.4;
  v.cells.volts[2] = 3.5;
  const auto from_one = bms_battery_message(v);
  ASSERT_EQ(from_one.cell_voltage().size(), 2u);
  EXPECT_FLOAT_EQ(from_one.cell_voltage()[0], 3.4f);

  v.capacity_ah.reset();
  EXPECT_TRUE(std::isnan(bms_battery_message(v).charge()));
  EXPECT_TRUE(std::isnan(bms_battery_message(v).design_capacity()));
  v.values = bms_values(kUnknown, kUnknown, kUnknown);
  const auto empty = bms_battery_message(v);
  EXPECT_FALSE(empty.present());
  EXPECT_TRUE(std::isnan(empty.percentage()));
  EXPECT_EQ(empty.power_supply_status(), Bs::POWER_SUPPLY_STATUS_UNKNOWN);
}

TEST(Ros2Messages, BmsStatusAndHealth) {
  struct Case {
    double current, soc;
    std::vector<service::AlarmReport> active;
    std::uint8_t status, supply_health;
  };
  const Case cases[] = {
      {3.0, 50, {}, Bs::POWER_SUPPLY_STATUS_CHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD},
      {0.0, 100, {}, Bs::POWER_SUPPLY_STATUS_FULL, Bs::POWER_SUPPLY_HEALTH_GOOD},
      {0.0, 80, {}, Bs::POWER_SUPPLY_STATUS_NOT_CHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD},
      {-5.0, 100, {}, Bs::POWER_SUPPLY_STATUS_DISCHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD},
      {-5.0, 5, {alarm(Code::BmsCriticalSoc)}, Bs::POWER_SUPPLY_STATUS_DISCHARGING, Bs::POWER_SUPPLY_HEALTH_DEAD},
      {-5.0, 12, {alarm(Code::BmsLowSoc)}, Bs::POWER_SUPPLY_STATUS_DISCHARGING, Bs::POWER_SUPPLY_HEALTH_GOOD},
      {-5.0,
       50,
       {alarm(Code::BmsOverTemperature)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_OVERHEAT},
      {-5.0,
       50,
       {alarm(Code::CellImbalance)},
       Bs::POWER_SUPPLY_STATUS_DISCHARGING,
       Bs::POWER_SUPPLY_HEALTH_UNSPEC_FAILURE},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(std::to_string(c.current) + " A " + std::to_string(c.soc) + " %");
    BmsView v;
    v.values = bms_values(48, c.current, c.soc);
    v.health = HealthState::Online;
    v.active = c.active;
    const auto m = bms_battery_message(v);
    EXPECT_EQ(m.power_supply_status(), c.status);
    EXPECT_EQ(m.power_supply_health(), c.supply_health);
  }
  // Online, but its voltage not received: not present, health unknown.
  BmsView v;
  v.values = bms_values(kUnknown, kUnknown, kUnknown);
  v.health = HealthState::Online;
  const auto m = bms_battery_message(v);
  EXPECT_FALSE(m.present());
  EXPECT_EQ(m.power_supply_health(), Bs::POWER_SUPPLY_HEALTH_UNKNOWN);
}

TEST(Ros2Messages, DiagnosticLevelFromHealthAndAlarms) {
  struct Case {
    HealthState health;
    std::vector<service::AlarmReport> active;
    std::uint8_t level;
    std::string message;
  };
  const Case cases[] = {
      {HealthState::Online, {}, Ds::OK, "online"},
      {HealthState::Online, {alarm(Code::BatteryALowVoltage)}, Ds::WARN, "battery_a_low_voltage message"},
      {HealthState::Online,
       {alarm(Code::BatteryALowVoltage), alarm(Code::ThermalShutdown)},
       Ds::ERROR,
       "thermal_shutdown message (+1 more)"},
      {HealthState::Online, {alarm(Code::ThermalShutdown, AlarmState::ClearedUnacknowledged)}, Ds::OK, "online"},
      {HealthState::Unknown, {}, Ds::STALE, "no frame yet"},
      {HealthState::Stale, {alarm(Code::DeviceStale)}, Ds::STALE, "stale: last frame 3.5 s ago"},
      {HealthState::Offline, {alarm(Code::DeviceOffline)}, Ds::ERROR, "offline: last frame 3.5 s ago"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.message);
    DeviceDiagnosticsView v;
    v.name = "uav1/can0/pmu_1";
    v.hardware_id = "pmu serial 4001";
    v.health.state = c.health;
    v.health.last_frame_age = 3.5;
    v.health.frames_received = 120;
    v.active = c.active;
    v.extra = {{"firmware", "1.17"}};
    const auto s = device_status(v);
    EXPECT_EQ(s.level(), c.level);
    EXPECT_EQ(s.message(), c.message);
    EXPECT_EQ(s.name(), "uav1/can0/pmu_1");
    EXPECT_EQ(s.hardware_id(), "pmu serial 4001");
    EXPECT_EQ(key_value(s, "frames_received"), "120");
    EXPECT_EQ(key_value(s, "firmware"), "1.17");
    EXPECT_EQ(key_value(s, "state"), service::to_string(c.health));
  }
  DeviceDiagnosticsView v;
  v.health.state = HealthState::Online;
  v.active = {alarm(Code::BatteryALowVoltage), alarm(Code::ThermalShutdown)};
  const auto s = device_status(v);
  EXPECT_EQ(key_value(s, "active_alarms"), "thermal_shutdown,battery_a_low_voltage") << "critical first";
  EXPECT_EQ(key_value(s, "alarm thermal_shutdown"), "critical, ACTIVE_UNACKNOWLEDGED: thermal_shutdown message");
}

// A device never heard (last_frame_age -1) has no age to print: its status says so as
// pmuctl does (`never`), in the message and in `last_frame_age_s`.
TEST(Ros2Messages, DiagnosticOfADeviceNeverHeard) {
  struct Case {
    HealthState health;
    double age;
    std::string message, age_value;
  };
  const Case cases[] = {
      {HealthState::Unknown, -1, "no frame yet", "never"},
      {HealthState::Offline, -1, "offline: no frame yet", "never"},
      {HealthState::Stale, -1, "stale: no frame yet", "never"},
      {HealthState::Offline, 12.3, "offline: last frame 12.3 s ago", "12.3"},
      {HealthState::Online, 0.0, "online", "0.0"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.message);
    DeviceDiagnosticsView v;
    v.health.state = c.health;
    v.health.last_frame_age = c.age;
    const auto s = device_status(v);
    EXPECT_EQ(s.message(), c.message);
    EXPECT_EQ(key_value(s, "last_frame_age_s"), c.age_value);
  }
}

}  // namespace
}  // namespace pmu::service
