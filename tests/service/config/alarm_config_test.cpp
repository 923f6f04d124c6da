// `alarms:` in the config (alarm_settings.cpp, interface.md 1.6 and 4.1): read into each
// device's and bus's settings, and every refusal at its own line, in alarms::resolve's words
// where resolve is the one that refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pmu/config/config.hpp"

namespace pmu::service {
namespace {

using alarms::Code;

TEST(AlarmConfig, SettingsReachEveryKindOfEntry) {
  const Config c = parse_config(R"(buses:
  - interface: can0
    alarms:
      bus_error_passive: {off_delay: 10}
    discover:
      alarms:
        device_stale: {enabled: false}
    devices:
      - address: 1
        alarms:
          battery_a_low_voltage: {limit: 20.5, deadband: 0.2, on_delay: 5, off_delay: 15}
          battery_b_low_voltage: {enabled: false}
          payload_shed: {severity: critical}
      - address: 2
    batteries:
      - node: 2
        alarms:
          bms_low_soc: {limit: 20}
    mppts:
      - device: 0
        alarms:
          mppt_fault:
)",
                                "good.yaml");
  const BusConfig& b = c.buses.at(0);
  EXPECT_EQ(b.alarms[Code::BusErrorPassive].off_delay_s, 10.0);
  EXPECT_EQ(b.discovered_defaults.alarms[Code::DeviceStale].enabled, false);
  const auto& a = b.devices.at(0).alarms;
  EXPECT_EQ(a[Code::BatteryALowVoltage].limit, 20.5);
  EXPECT_EQ(a[Code::BatteryALowVoltage].deadband, 0.2);
  EXPECT_EQ(a[Code::BatteryALowVoltage].on_delay_s, 5.0);
  EXPECT_EQ(a[Code::BatteryALowVoltage].off_delay_s, 15.0);
  EXPECT_EQ(a[Code::BatteryBLowVoltage].enabled, false);
  EXPECT_EQ(a[Code::PayloadShed].severity, alarms::Severity::Critical);
  for (const auto& o : b.devices.at(1).alarms.overrides) EXPECT_TRUE(o.empty()) << "no alarms: the table's defaults";
  EXPECT_EQ(b.batteries.at(0).alarms[Code::BmsLowSoc].limit, 20.0);
  EXPECT_TRUE(b.mppts.at(0).alarms[Code::MpptFault].empty()) << "a code with nothing after it changes nothing";
}

struct Refusal {
  const char* name;
  const char* entry;    // the lines after `- interface: can0`, indented by four
  const char* message;  // the whole "FILE:LINE: ..." text
};

const Refusal kRefused[] = {
    {"unknown code", "devices:\n      - address: 1\n        alarms:\n          battery_c_low_voltage: {limit: 1}\n",
     "bad.yaml:6: unknown alarm code 'battery_c_low_voltage' (alarms of a pmu: thermal_shutdown, soa_shutdown, "
     "payload_shed, battery_a_low_voltage, battery_a_critical_voltage, battery_b_low_voltage, "
     "battery_b_critical_voltage, internal_over_temperature, starter_over_temperature, generator_over_temperature, "
     "battery_a_over_temperature, battery_b_over_temperature, generator_not_producing, uncommanded_engine_stop, "
     "device_stale, device_offline)"},
    {"code of another kind", "devices:\n      - address: 1\n        alarms:\n          cell_low: {limit: 3.1}\n",
     "bad.yaml:6: cell_low: not an alarm of a pmu"},
    {"PMU code on a battery", "batteries:\n      - node: 2\n        alarms:\n          thermal_shutdown: {}\n",
     "bad.yaml:6: thermal_shutdown: not an alarm of a battery"},
    {"device code on a bus", "discover: true\n    alarms:\n      device_offline: {enabled: false}\n",
     "bad.yaml:5: device_offline: not an alarm of a bus"},
    {"unknown key",
     "devices:\n      - address: 1\n        alarms:\n          battery_a_low_voltage:\n            treshold: 20\n",
     "bad.yaml:7: unknown key 'treshold' in battery_a_low_voltage (known: limit, deadband, on_delay, off_delay, "
     "severity, enabled)"},
    {"negative deadband",
     "devices:\n      - address: 1\n        alarms:\n          battery_a_low_voltage:\n            limit: 20\n"
     "            deadband: -0.5\n",
     "bad.yaml:8: battery_a_low_voltage: deadband -0.5 is negative"},
    {"limit of a flag", "devices:\n      - address: 1\n        alarms:\n          thermal_shutdown: {limit: 1}\n",
     "bad.yaml:6: thermal_shutdown: limit cannot be set: the alarm is a flag"},
    {"NaN limit", "mppts:\n      - device: 0\n        alarms:\n          device_stale: {on_delay: .nan}\n",
     "bad.yaml:6: device_stale: on_delay is not a number of seconds"},
    {"delay past a day", "batteries:\n      - node: 2\n        alarms:\n          bms_low_soc: {off_delay: 90000}\n",
     "bad.yaml:6: bms_low_soc: off_delay 90000 s is longer than a day"},
    {"negative delay",
     "devices:\n      - address: 1\n        alarms:\n          payload_shed:\n            on_delay: -1\n",
     "bad.yaml:7: payload_shed: on_delay -1 s is negative"},
    {"limit not a number",
     "devices:\n      - address: 1\n        alarms:\n          battery_a_low_voltage: {limit: low}\n",
     "bad.yaml:6: battery_a_low_voltage: limit must be a number, not 'low'"},
    {"unknown severity", "devices:\n      - address: 1\n        alarms:\n          payload_shed: {severity: major}\n",
     "bad.yaml:6: payload_shed: severity must be warning or critical, not 'major'"},
    {"enabled not a boolean", "alarms:\n      bus_off: {enabled: sometimes}\n    discover: true\n",
     "bad.yaml:4: bus_off: enabled must be true or false, not 'sometimes'"},
    {"alarms a list", "devices:\n      - address: 1\n        alarms: [thermal_shutdown]\n",
     "bad.yaml:5: alarms must be a mapping of alarm code: settings, e.g. {battery_a_low_voltage: {limit: 20.5}}"},
    {"settings a number", "devices:\n      - address: 1\n        alarms:\n          thermal_shutdown: 1\n",
     "bad.yaml:6: thermal_shutdown must be a mapping, e.g. {limit: 20.5, on_delay: 10}"},
    {"discover's alarms", "discover:\n      alarms:\n        cell_imbalance: {limit: 0.2}\n",
     "bad.yaml:5: cell_imbalance: not an alarm of a pmu"},
};

TEST(AlarmConfig, EveryRefusalNamesItsLine) {
  for (const auto& r : kRefused) {
    SCOPED_TRACE(r.name);
    const std::string yaml = std::string("buses:\n  - interface: can0\n    ") + r.entry;
    try {
      (void)parse_config(yaml, "bad.yaml");
      ADD_FAILURE() << "accepted:\n" << yaml;
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), r.message) << yaml;
    }
  }
}

}  // namespace
}  // namespace pmu::service
