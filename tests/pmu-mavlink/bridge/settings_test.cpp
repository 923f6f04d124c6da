#include "program/settings.hpp"

#include <gtest/gtest.h>

namespace pmu::mavlink_bridge {
namespace {

using namespace std::chrono_literals;
namespace id = pmu::mavlink::msgid;

TEST(Settings, Defaults) {
  const Settings s;
  EXPECT_EQ(s.component_id, 180) << "MAV_COMP_ID_BATTERY";
  EXPECT_FALSE(s.system_id) << "learned from the autopilot";
  EXPECT_EQ(s.pmu_battery_id, 10);
  EXPECT_EQ(s.bms_battery_id, 20);
  EXPECT_EQ(s.intervals.at(id::kHeartbeat), 1s);
  EXPECT_EQ(s.intervals.at(id::kBatteryStatus), 2s);
  EXPECT_EQ(s.intervals.at(id::kGeneratorStatus), 1s);
  EXPECT_EQ(s.intervals.at(id::kRelayStatus), 1s);
}

TEST(Settings, EveryKey) {
  Settings s;
  read_settings(
      "udp: 127.0.0.1:14550\n"
      "serial: /dev/ttyAMA0:57600\n"
      "system_id: 3\n"
      "component_id: 191\n"
      "domain: 7\n"
      "vehicle: uav1\n"
      "qos_file: /etc/pmu-dds/qos.xml\n"
      "signing_key: /etc/pmu-dds/mavlink-signing.key\n"
      "battery_ids: {pmu: 30, bms: 40}\n"
      "rates: {battery_status: 1, generator_status: 0, heartbeat: 2, relay_status: 0.2}\n"
      "confirm: [engine_start, reset]\n",
      "m.yaml", s);
  ASSERT_TRUE(s.udp);
  EXPECT_EQ(s.udp->port, 14550);
  ASSERT_TRUE(s.serial);
  EXPECT_EQ(s.serial->baud, 57600U);
  EXPECT_EQ(s.system_id, 3);
  EXPECT_EQ(s.component_id, 191);
  EXPECT_EQ(s.domain, 7);
  EXPECT_EQ(s.vehicle, "uav1");
  EXPECT_EQ(s.signing_key, "/etc/pmu-dds/mavlink-signing.key");
  EXPECT_EQ(s.pmu_battery_id, 30);
  EXPECT_EQ(s.bms_battery_id, 40);
  EXPECT_EQ(s.intervals.at(id::kBatteryStatus), 1s);
  EXPECT_EQ(s.intervals.at(id::kGeneratorStatus), 0s) << "0 Hz: off";
  EXPECT_EQ(s.intervals.at(id::kHeartbeat), 500ms);
  EXPECT_EQ(s.intervals.at(id::kRelayStatus), 5s);
  using service::ConfirmRule;
  for (std::size_t i = 0; i < s.confirm.size(); ++i) {
    const auto rule = static_cast<ConfirmRule>(i);
    EXPECT_EQ(s.confirm[i], rule == ConfirmRule::EngineStart || rule == ConfirmRule::Reset) << i;
  }
}

TEST(Settings, ErrorsNameFileAndLine) {
  const struct {
    const char* text;
    const char* expected;
  } cases[] = {
      {"udp: 127.0.0.1:14550\ncomponent_id: 0\n", "m.yaml:2: component_id: '0' is not a whole number 1..255"},
      {"udp: 127.0.0.1\n", "m.yaml:1: udp: '127.0.0.1' is not HOST:PORT"},
      {"\nserial: /dev/ttyS0:1234\n", "m.yaml:2: serial: '/dev/ttyS0:1234': the baud rate must be one of"},
      {"rates:\n  battery_status: 100\n", "m.yaml:2: rates.battery_status: 0 (off) or 0.01..50 Hz"},
      {"rates:\n  gps_raw: 1\n", "m.yaml:2: rates: unknown message 'gps_raw'"},
      {"sysid: 1\n", "m.yaml:1: unknown key 'sysid'"},
      {"battery_ids: {pmu: 254}\n", "m.yaml:1: battery_ids.pmu: '254' is not a whole number 0..253"},
      {"udp: [\n", "m.yaml:"},
      {"udp: 127.0.0.1:14550\nsigning_key: [a, b]\n", "m.yaml:2: signing_key: expected a value"},
      {"signing_key: ''\n", "m.yaml:1: signing_key: expected the key file's path"},
      {"udp: 127.0.0.1:14550\nconfirm:\n  - reset\n  - start_engine\n",
       "m.yaml:4: confirm: unknown confirm rule 'start_engine' (rules: "},
      {"confirm: engine_start\n", "m.yaml:1: confirm: expected a list of rule names"},
  };
  for (const auto& c : cases) {
    Settings s;
    try {
      read_settings(c.text, "m.yaml", s);
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const SettingsError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(c.expected, 0), 0U) << e.what();
    }
  }
}

TEST(Settings, ConfirmOptionAddsToTheFilesRules) {
  Settings s;
  EXPECT_FALSE(s.confirm[static_cast<std::size_t>(service::ConfirmRule::EngineStart)]) << "none by default";
  read_settings("confirm: [reset]\n", "m.yaml", s);
  EXPECT_FALSE(apply_confirm_option("engine_start", s));
  EXPECT_TRUE(s.confirm[static_cast<std::size_t>(service::ConfirmRule::EngineStart)]);
  EXPECT_TRUE(s.confirm[static_cast<std::size_t>(service::ConfirmRule::Reset)]);
  const auto e = apply_confirm_option("everything", s);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->rfind("--confirm: unknown confirm rule 'everything'", 0), 0U) << *e;
}

TEST(Settings, RateOption) {
  Settings s;
  EXPECT_FALSE(apply_rate_option("battery_status=0.2", s));
  EXPECT_EQ(s.intervals.at(id::kBatteryStatus), 5s);
  EXPECT_FALSE(apply_rate_option("relay_status=0", s));
  EXPECT_EQ(s.intervals.at(id::kRelayStatus), 0s) << "off";
  for (const char* bad : {"battery_status", "battery_status=fast", "battery_status=-1", "efi_status=1", "heartbeat=1x"})
    EXPECT_TRUE(apply_rate_option(bad, s)) << bad;
}

}  // namespace
}  // namespace pmu::mavlink_bridge
