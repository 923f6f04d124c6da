// The alarms pmuctl shows (tools/pmuctl/view/alarm_marker.hpp, interface.md 1.6 and 3.2): the
// marker watch puts beside a device or bus, where it goes in watch's table, and the --json
// object `pmuctl alarms` and `pmuctl watch` share.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pmuctl/view/alarm_marker.hpp"
#include "pmuctl/view/table_text.hpp"

namespace pmu::tools {
namespace {

AlarmEntry alarm(const std::string& kind, std::uint16_t device, const std::string& code, bool critical,
                 AlarmStatus state) {
  AlarmEntry a;
  a.bus = "can0";
  a.kind = kind;
  a.device = device;
  a.code = code;
  a.critical = critical;
  a.state = state;
  return a;
}

constexpr auto kNormal = AlarmStatus::Normal;
constexpr auto kUnacked = AlarmStatus::ActiveUnacknowledged;
constexpr auto kAcked = AlarmStatus::ActiveAcknowledged;
constexpr auto kCleared = AlarmStatus::ClearedUnacknowledged;

TEST(PmuctlAlarmView, TheMarkerCountsWhatIsNotNormalAndNamesTheWorst) {
  struct Case {
    const char* name;
    std::vector<AlarmEntry> alarms;
    const char* marker;
  };
  const std::vector<Case> cases = {
      {"no alarm", {}, ""},
      {"every alarm NORMAL",
       {alarm("pmu", 1, "thermal_shutdown", true, kNormal), alarm("pmu", 1, "payload_shed", false, kNormal)},
       ""},
      {"one warning", {alarm("pmu", 1, "payload_shed", false, kUnacked)}, "ALARM 1 WARN unacked (payload_shed)"},
      {"an acknowledged warning", {alarm("pmu", 1, "payload_shed", false, kAcked)}, "ALARM 1 WARN acked (payload_shed)"},
      {"an unacknowledged critical",
       {alarm("pmu", 1, "thermal_shutdown", true, kUnacked)},
       "ALARM 1 CRIT unacked (thermal_shutdown)"},
      {"an acknowledged critical",
       {alarm("pmu", 1, "thermal_shutdown", true, kAcked)},
       "ALARM 1 CRIT acked (thermal_shutdown)"},
      {"a critical cleared before anyone acknowledged it",
       {alarm("pmu", 1, "thermal_shutdown", true, kCleared)},
       "ALARM 1 CRIT cleared unacked (thermal_shutdown)"},
      {"the critical is worse than the warning, whatever the order",
       {alarm("pmu", 1, "payload_shed", false, kUnacked), alarm("pmu", 1, "thermal_shutdown", true, kAcked),
        alarm("pmu", 1, "internal_over_temperature", false, kNormal)},
       "ALARM 2 CRIT acked (thermal_shutdown)"},
      {"an active critical is worse than a cleared one",
       {alarm("pmu", 1, "soa_shutdown", true, kCleared), alarm("pmu", 1, "thermal_shutdown", true, kAcked)},
       "ALARM 2 CRIT acked (thermal_shutdown)"},
      {"an unacknowledged critical is worse than an acknowledged one",
       {alarm("pmu", 1, "soa_shutdown", true, kAcked), alarm("pmu", 1, "thermal_shutdown", true, kUnacked),
        alarm("pmu", 1, "battery_a_critical_voltage", true, kCleared)},
       "ALARM 3 CRIT unacked (thermal_shutdown)"},
      {"equal alarms: the first code",
       {alarm("pmu", 1, "thermal_shutdown", true, kUnacked), alarm("pmu", 1, "soa_shutdown", true, kUnacked)},
       "ALARM 2 CRIT unacked (soa_shutdown)"},
      {"a battery's",
       {alarm("battery", 2, "bms_low_soc", false, kUnacked),
        alarm("battery", 2, "bms_over_temperature", true, kUnacked)},
       "ALARM 2 CRIT unacked (bms_over_temperature)"},
      {"an MPPT's", {alarm("mppt", 4, "mppt_fault", false, kUnacked)}, "ALARM 1 WARN unacked (mppt_fault)"},
      {"a bus's", {alarm("bus", 0, "bus_off", true, kUnacked)}, "ALARM 1 CRIT unacked (bus_off)"},
  };
  for (const auto& c : cases) EXPECT_EQ(alarm_marker(c.alarms), c.marker) << c.name;
}

// The label of an alarm's source is watch's label of the device's rows, so the marker finds them.
TEST(PmuctlAlarmView, AnAlarmsSourceIsLabelledAsWatchLabelsItsDevice) {
  struct Case {
    std::string vehicle, kind;
    std::uint16_t device;
    const char* source;
  };
  const std::vector<Case> cases = {
      {"", "pmu", 1, "can0/1"},
      {"uav1", "pmu", 1, "uav1/can0/1"},
      {"", "battery", 2, "can0/battery2"},
      {"uav1", "mppt", 4, "uav1/can0/mppt4"},
      {"", "bus", 0, "can0"},
      {"uav1", "bus", 0, "uav1/can0"},
  };
  for (const auto& c : cases) {
    AlarmEntry a = alarm(c.kind, c.device, "x", false, kUnacked);
    a.vehicle = c.vehicle;
    EXPECT_EQ(alarm_source(a), c.source);
  }
  const std::vector<AlarmEntry> all = {alarm("pmu", 1, "a", false, kUnacked), alarm("bus", 0, "b", true, kUnacked),
                                       alarm("pmu", 1, "c", true, kAcked), alarm("pmu", 2, "d", true, kAcked)};
  const auto of1 = alarms_of(all, "can0/1");
  ASSERT_EQ(of1.size(), 2u);
  EXPECT_EQ(of1[0].code, "a");
  EXPECT_EQ(of1[1].code, "c");
  ASSERT_EQ(alarms_of(all, "can0").size(), 1u);
  EXPECT_EQ(alarms_of(all, "can0")[0].code, "b");
}

WatchRow row(const std::string& label, const std::string& topic) {
  return {label, topic, pmu::v5::ONLINE, 0.2, {{"internal", 31.0, "31.0", "degC"}}};
}

// A device with an alarm carries its marker on its rows; a bus, which has no row, and a
// device with no row yet are in the "alarms:" section, which lists every one.
TEST(PmuctlAlarmView, WatchTableShowsTheMarkersWithTheirDevicesAndBuses) {
  struct Case {
    const char* name;
    std::vector<AlarmEntry> alarms;
    std::vector<std::string> want;
  };
  const std::vector<WatchRow> rows = {row("can0/1", "temperatures"), row("can0/2", "temperatures"),
                                      row("can0/battery2", "battery")};
  const std::vector<Case> cases = {
      {"no alarm: the table as it was",
       {},
       {"temperatures:", "can0/1  ONLINE  0.2s  internal=31.0degC", "can0/2  ONLINE  0.2s  internal=31.0degC",
        "battery:", "can0/battery2  ONLINE  0.2s  internal=31.0degC"}},
      {"every alarm NORMAL: nothing either",
       {alarm("pmu", 1, "thermal_shutdown", true, kNormal), alarm("bus", 0, "bus_off", true, kNormal)},
       {"temperatures:", "can0/1  ONLINE  0.2s  internal=31.0degC", "can0/2  ONLINE  0.2s  internal=31.0degC",
        "battery:", "can0/battery2  ONLINE  0.2s  internal=31.0degC"}},
      {"a PMU's critical: its rows, and the others of its topic keep their place",
       {alarm("pmu", 1, "thermal_shutdown", true, kUnacked)},
       {"alarms:", "can0/1  ALARM 1 CRIT unacked (thermal_shutdown)",
        "temperatures:", "can0/1  ONLINE  0.2s  ALARM 1 CRIT unacked (thermal_shutdown)  internal=31.0degC",
        "can0/2  ONLINE  0.2s  " + std::string(41, ' ') + "internal=31.0degC",
        "battery:", "can0/battery2  ONLINE  0.2s  internal=31.0degC"}},
      {"a battery's warning and the bus's: the bus first, with no row",
       {alarm("battery", 2, "bms_low_soc", false, kAcked), alarm("bus", 0, "bus_error_passive", false, kUnacked)},
       {"alarms:", "can0           ALARM 1 WARN unacked (bus_error_passive)",
        "can0/battery2  ALARM 1 WARN acked (bms_low_soc)", "temperatures:", "can0/1  ONLINE  0.2s  internal=31.0degC",
        "can0/2  ONLINE  0.2s  internal=31.0degC",
        "battery:", "can0/battery2  ONLINE  0.2s  ALARM 1 WARN acked (bms_low_soc)  internal=31.0degC"}},
      {"an MPPT with no row yet",
       {alarm("mppt", 4, "mppt_fault", false, kUnacked)},
       {"alarms:", "can0/mppt4  ALARM 1 WARN unacked (mppt_fault)",
        "temperatures:", "can0/1  ONLINE  0.2s  internal=31.0degC", "can0/2  ONLINE  0.2s  internal=31.0degC",
        "battery:", "can0/battery2  ONLINE  0.2s  internal=31.0degC"}},
  };
  for (const auto& c : cases) EXPECT_EQ(watch_table(rows, c.alarms), c.want) << c.name;
}

// `pmuctl alarms --json` and `pmuctl watch --json`: the keys of interface.md 3.2, in its order.
TEST(PmuctlAlarmView, JsonHasTheDocumentedKeys) {
  AlarmEntry a = alarm("battery", 2, "bms_low_soc", false, kAcked);
  a.vehicle = "uav1";
  a.value = 12.5f;
  a.limit = 15.0f;
  a.since = 1700000000500000000ull;
  a.message = "state of charge 12.5 % < 15 %";
  const auto j = alarm_json(a, 4);
  std::string keys;
  for (auto it = j.begin(); it != j.end(); ++it) keys += (keys.empty() ? "" : ",") + it.key();
  EXPECT_EQ(keys, "topic,vehicle,bus,kind,device,code,severity,state,value,limit,since,message,contract");
  EXPECT_EQ(j["topic"], "alarms");
  EXPECT_EQ(j["kind"], "battery");
  EXPECT_EQ(j["device"], 2);
  EXPECT_EQ(j["severity"], "warning");
  EXPECT_EQ(j["state"], "ACTIVE_ACKNOWLEDGED");
  EXPECT_EQ(j["value"], 12.5);
  EXPECT_DOUBLE_EQ(j["since"].get<double>(), 1700000000.5);
  EXPECT_EQ(j["contract"], 4);
  const auto flag = alarm_json(alarm("pmu", 1, "thermal_shutdown", true, kCleared), 4);
  EXPECT_TRUE(flag["value"].is_null()) << "a flag has no value";
  EXPECT_TRUE(flag["limit"].is_null());
  EXPECT_EQ(flag["severity"], "critical");
  EXPECT_EQ(flag["state"], "CLEARED_UNACKNOWLEDGED");
}

}  // namespace
}  // namespace pmu::tools
