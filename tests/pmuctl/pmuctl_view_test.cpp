// What pmuctl's tables and --json show of each DDS sample (tools/pmuctl/view/sample_fields.hpp,
// table_text.hpp) and how `config set` reads a value (mask_names.hpp): units from the spec's
// tables, every sentinel, every mask, and the health and age on watch rows.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "pmuctl/view/mask_names.hpp"
#include "pmuctl/view/sample_fields.hpp"
#include "pmuctl/view/table_text.hpp"

namespace pmu::tools {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

SampleField field(const SampleFields& fields, const std::string& name) {
  const SampleField* f = find_field(fields, name);
  const SampleField missing{"<missing>", nullptr, "<missing>", ""};
  EXPECT_NE(f, nullptr) << name;
  return f ? *f : missing;
}

pmu::v5::Voltages voltages() {
  pmu::v5::Voltages s;
  s.avionics(12.3f), s.output_28v(28.0f), s.payload(12.0f), s.servo(6.0f), s.battery_a(24.1f), s.battery_b(24.0f),
      s.generator(0.4f);
  return s;
}
pmu::v5::Currents currents() {
  pmu::v5::Currents s;
  s.avionics(1.5f), s.output_28v(-0.3f), s.battery_a(-2.5f);
  return s;
}
pmu::v5::Temperatures temperatures() {
  pmu::v5::Temperatures s;
  s.internal(31), s.battery_a(kNaN), s.battery_b(22), s.generator(kNaN), s.starter(-49);
  return s;
}
pmu::v5::Status status(float rpm) {
  pmu::v5::Status s;
  s.generator_rpm(rpm), s.generation_enabled(true), s.payload_on(true);
  return s;
}
pmu::v5::Config config() {
  pmu::v5::Config s;
  s.avionics_voltage(24.0f), s.payload_voltage(12.0f), s.servo_voltage(6.0f), s.battery_voltage(25.2f);
  s.packet_period(1.5f), s.packets_streamed(0x1F), s.temperature_offset(128), s.upper_temperature_limit(80);
  s.power_up_state(0x03), s.cranking_time(2.5f), s.can_address(1), s.outputs(0x05), s.generation_enabled(true);
  return s;
}
pmu::v5::Health health(float age) {
  pmu::v5::Health s;
  s.state(pmu::v5::OFFLINE), s.last_frame_age(age), s.frames_received(42);
  return s;
}
// Every value received.
pmu::v5::Battery battery(float time_to_go) {
  pmu::v5::Battery s;
  s.voltage(48.123f), s.current(-3.2f), s.current_discharge(3.2f), s.current_charge(0.0f), s.state_of_charge(77);
  s.time_to_go(time_to_go), s.cell_temperature_high(31), s.cell_temperature_low(24), s.cell_voltage_high(3.412f);
  s.cell_voltage_low(3.301f), s.bms_state(0x12345678), s.temperature_1(20), s.temperature_2(21), s.temperature_3(22);
  s.temperature_4(23), s.power_level(55), s.received(0xFFFF);
  return s;
}
pmu::v5::Mppt mppt() {
  pmu::v5::Mppt s;
  s.voltage_output_raw(1234), s.current_output_raw(-17), s.mppt_state(3), s.safety_enabled(1);
  s.temperature(41), s.duty_cycle_panel_1(45), s.channel_1_active(1);
  // voltage_output_raw, current_output_raw, mppt_state, safety_enabled, temperature,
  // duty_cycle_panel_1, channel_1_active (interface.md 1.4's bit order)
  s.received((1u << 0) | (1u << 1) | (1u << 3) | (1u << 4) | (1u << 6) | (1u << 9) | (1u << 10));
  return s;
}

pmu::v5::BatteryCells battery_cells() {
  pmu::v5::BatteryCells s;
  for (const auto& [n, v] : std::vector<std::pair<int, float>>{{1, 3.350f}, {2, 3.301f}, {3, 3.412f}}) {
    pmu::v5::BatteryCell c;
    c.cell(static_cast<std::uint8_t>(n)), c.cell_voltage(v);
    s.cells().push_back(c);
  }
  return s;
}

struct UnitRow {
  const char* what;
  SampleFields fields;
  const char* name;
  const char* text;  // text_with_unit: value and unit as a table shows them
};

// Units: protocol v1.9 tables 2..6 and 8..18, the battery/MPPT document, interface.md 1.1 and 1.4.
TEST(PmuctlView, EveryTableValueHasItsUnit) {
  const std::vector<UnitRow> rows = {
      {"table 2", fields_of(voltages()), "avionics", "12.3 V"},
      {"table 2", fields_of(voltages()), "output_28v", "28.0 V"},
      {"table 2", fields_of(voltages()), "generator", "0.4 V"},
      {"table 3", fields_of(currents()), "avionics", "1.5 A"},
      {"table 3", fields_of(currents()), "battery_a", "-2.5 A"},
      {"table 4", fields_of([] {
         pmu::v5::BatteryEnergy e;
         e.battery_a_mah(-120);
         return e;
       }()),
       "battery_a_mah", "-120 mAh"},
      {"table 5", fields_of(temperatures()), "internal", "31.0 degC"},
      {"table 5", fields_of(temperatures()), "starter", "-49.0 degC"},
      {"table 6", fields_of(status(6000)), "generator_rpm", "6000 rpm"},
      {"table 6", fields_of(status(6000)), "payload_on", "yes"},
      {"table 8", fields_of(config()), "avionics_voltage", "24.0 V"},
      {"table 11", fields_of(config()), "battery_voltage", "25.2 V"},
      {"table 12", fields_of(config()), "packet_period", "1.5 s"},
      {"table 14", fields_of(config()), "temperature_offset", "128"},
      {"table 15", fields_of(config()), "upper_temperature_limit", "80 degC"},
      {"table 17", fields_of(config()), "cranking_time", "2.5 s"},
      {"table 18", fields_of(config()), "can_address", "1"},
      {"health", fields_of(health(0.5f)), "last_frame_age", "0.5 s"},
      {"health", fields_of(health(0.5f)), "frames_received", "42"},
      {"battery 0x302", fields_of(battery(600)), "voltage", "48.123 V"},
      {"battery 0x302", fields_of(battery(600)), "current", "-3.2 A"},
      {"battery 0x302", fields_of(battery(600)), "state_of_charge", "77.0 %"},
      {"battery 0x302: minutes x 60", fields_of(battery(600)), "time_to_go", "600.0 s"},
      {"battery 0x402", fields_of(battery(600)), "cell_temperature_high", "31.0 degC"},
      {"battery 0x402", fields_of(battery(600)), "cell_voltage_low", "3.301 V"},
      {"battery 0x402", fields_of(battery(600)), "bms_state", "305419896"},
      {"battery 0x402", fields_of(battery(600)), "temperature_4", "23.0 degC"},
      {"battery 0x202", fields_of(battery(600)), "power_level", "55.0 %"},
      {"mppt", fields_of(mppt()), "temperature", "41.0 degC"},
      {"mppt", fields_of(mppt()), "duty_cycle_panel_1", "45.0 %"},
      {"mppt", fields_of(mppt()), "mppt_state", "3"},
      {"mppt", fields_of(mppt()), "safety_enabled", "yes"},
  };
  for (const auto& r : rows) EXPECT_EQ(text_with_unit(field(r.fields, r.name)), r.text) << r.what << " " << r.name;
  EXPECT_EQ(text_with_unit(field(fields_of(voltages()), "avionics"), true), "12.3V");
}

// MPPT voltages and currents have no resolution in the document: raw counts, integers in
// both the table and the JSON.
TEST(PmuctlView, MpptRawCountsAreIntegers) {
  const auto f = fields_of(mppt());
  for (const char* name : {"voltage_output_raw", "current_output_raw"}) {
    EXPECT_TRUE(field(f, name).json.is_number_integer()) << name << " " << field(f, name).json;
    EXPECT_TRUE(field(f, name).unit.empty()) << name;
  }
  EXPECT_EQ(field(f, "voltage_output_raw").text, "1234");
  EXPECT_EQ(field(f, "current_output_raw").text, "-17");
  EXPECT_EQ(json_of(f).dump().find("1234.0"), std::string::npos) << json_of(f);
  // What no MPPT sends (int16 counts) still prints, as a number.
  auto huge = mppt();
  huge.voltage_output_raw(1e30f);
  EXPECT_EQ(field(fields_of(huge), "voltage_output_raw").text, "1e+30");
}

struct SentinelRow {
  const char* what;
  SampleFields fields;
  const char* name;
  const char* text;
};

// A value standing for "no value" is a word in tables and null in JSON.
TEST(PmuctlView, SentinelsAreWordsInTablesAndNullInJson) {
  pmu::v5::Battery none_received;
  pmu::v5::Mppt mppt_none;
  const std::vector<SentinelRow> rows = {
      {"table 5: -128 = no sensor", fields_of(temperatures()), "battery_a", "no sensor"},
      {"table 5: -128 = no sensor", fields_of(temperatures()), "generator", "no sensor"},
      {"table 6: NaN = no reading", fields_of(status(kNaN)), "generator_rpm", "no reading"},
      {"health: NaN = never", fields_of(health(kNaN)), "last_frame_age", "never"},
      {"battery: NaN received = not discharging", fields_of(battery(kNaN)), "time_to_go", "n/a (not discharging)"},
      {"battery: time_to_go not received", fields_of([] {
         auto b = battery(kNaN);
         b.received(0xFFFF & ~(1u << 5));
         return b;
       }()),
       "time_to_go", "-"},
      {"battery: float not received", fields_of(none_received), "voltage", "-"},
      {"battery: integer not received", fields_of(none_received), "bms_state", "-"},
      {"battery: NaN with its bit set", fields_of([] {
         auto b = battery(600);
         b.voltage(kNaN);
         return b;
       }()),
       "voltage", "-"},
      {"mppt: flag not received", fields_of(mppt_none), "pwm_enabled", "-"},
      {"mppt: raw count not received", fields_of(mppt()), "voltage_out_sw_raw", "-"},
      {"mppt: channel not received", fields_of(mppt()), "channel_2_active", "-"},
  };
  for (const auto& r : rows) {
    const auto f = field(r.fields, r.name);
    EXPECT_EQ(text_with_unit(f), r.text) << r.what;
    EXPECT_TRUE(f.json.is_null()) << r.what << ": " << f.json;
  }
  // Their neighbours are values.
  EXPECT_EQ(field(fields_of(status(65534)), "generator_rpm").json, 65534);
  EXPECT_EQ(field(fields_of(status(0)), "generator_rpm").json, 0);
  EXPECT_EQ(field(fields_of(battery(65534.0f * 60)), "time_to_go").json, 65534.0 * 60);
  EXPECT_EQ(field(fields_of(health(0.0f)), "last_frame_age").json, 0.0);
  EXPECT_EQ(field(fields_of(temperatures()), "battery_b").json, 22.0);
}

// Settings with a special value keep their number in JSON and say what it means in tables.
TEST(PmuctlView, SpecialSettingsSayWhatTheyMean) {
  struct Row {
    const char* what;
    pmu::v5::Config c;
    const char* name;
    const char* text;
    double json;
  };
  auto with = [](auto set) {
    auto c = config();
    set(c);
    return c;
  };
  const std::vector<Row> rows = {
      {"table 15", with([](pmu::v5::Config& c) { c.upper_temperature_limit(0); }), "upper_temperature_limit",
       "0 (forces thermal shutdown)", 0},
      {"table 15", with([](pmu::v5::Config& c) { c.upper_temperature_limit(255); }), "upper_temperature_limit",
       "255 (thermal shutdown disabled)", 255},
      {"table 17", with([](pmu::v5::Config& c) { c.cranking_time(0); }), "cranking_time", "0.0 (no timeout)", 0},
  };
  for (const auto& r : rows) {
    const auto f = field(fields_of(r.c), r.name);
    EXPECT_EQ(text_with_unit(f), r.text) << r.what;
    EXPECT_EQ(f.json, r.json) << r.what;
  }
}

// Masks by name with the number (tables 13, 16, 19; interface.md's names); JSON keeps the number.
TEST(PmuctlView, MasksShowTheirBitNames) {
  struct Row {
    const char* name;
    std::uint8_t mask;
    const char* text;
  };
  const std::vector<Row> rows = {
      {"outputs", 0x00, "none (0x00)"},
      {"outputs", 0x03, "avionics_servo,payload (0x03)"},
      {"outputs", 0x0C, "charger_a,charger_b (0x0C)"},
      {"outputs", 0x1F, "avionics_servo,payload,charger_a,charger_b,bit4 (0x1F)"},
      {"packets_streamed", 0x1F, "voltages,currents,battery_energy,temperatures,status (0x1F)"},
      {"packets_streamed", 0x81, "voltages,bit7 (0x81)"},
      {"power_up_state", 0x0F, "avionics_servo,payload,charger_a,charger_b (0x0F)"},
      {"power_up_state", 0x70, "battery_disconnect_detect,payload_shedding,soa_management (0x70)"},
      {"power_up_state", 0x80, "bit7 (0x80)"},
  };
  for (const auto& r : rows) {
    auto c = config();
    if (std::string(r.name) == "outputs") c.outputs(r.mask);
    if (std::string(r.name) == "packets_streamed") c.packets_streamed(r.mask);
    if (std::string(r.name) == "power_up_state") c.power_up_state(r.mask);
    const auto f = field(fields_of(c), r.name);
    EXPECT_EQ(text_with_unit(f), r.text) << r.name;
    EXPECT_EQ(f.json, r.mask) << r.name;
  }
}

// `config set PARAM VALUE`: names, comma lists, none, or a number; a clear refusal otherwise.
TEST(PmuctlView, ConfigSetReadsMaskNamesAndNumbers) {
  struct Row {
    const char* parameter;
    const char* text;
    double value;         // when accepted
    const char* refusal;  // a part of the error; nullptr: accepted
  };
  const std::vector<Row> rows = {
      {"power_up_state", "avionics_servo,payload", 3, nullptr},
      {"power_up_state", "soa_management", 0x40, nullptr},
      {"power_up_state", "payload,payload", 2, nullptr},
      {"power_up_state", "none", 0, nullptr},
      {"power_up_state", "5", 5, nullptr},
      {"power_up_state", "0x13", 0x13, nullptr},
      {"packets_streamed", "voltages,status", 0x11, nullptr},
      {"outputs", "charger_a,charger_b", 0x0C, nullptr},
      {"avionics_voltage", "12.5", 12.5, nullptr},
      {"cranking_time", "0", 0, nullptr},
      {"power_up_state", "avionics_servo,foo", 0,
       "power_up_state: unknown name 'foo' in 'avionics_servo,foo' (avionics_servo, payload, charger_a, charger_b, "
       "battery_disconnect_detect, payload_shedding, soa_management, none, or a number 0..0x7F)"},
      {"packets_streamed", "-1", 0,
       "packets_streamed: '-1' is not a mask (voltages, currents, battery_energy, temperatures, status, none, or a "
       "number 0..0x1F)"},
      {"packets_streamed", "voltage", 0, "unknown name 'voltage'"},
      {"packets_streamed", "voltages,,status", 0, "packets_streamed: empty name in 'voltages,,status'"},
      {"packets_streamed", "voltages,", 0, "empty name"},
      {"power_up_state", "none,payload", 0, "'none' cannot be combined with names in 'none,payload'"},
      {"power_up_state", "256", 0, "power_up_state: '256' is not a mask"},
      {"power_up_state", "-1", 0, "is not a mask"},
      {"power_up_state", "1.5", 0, "is not a mask"},
      {"power_up_state", "", 0, "empty name"},
      {"avionics_voltage", "payload", 0, "avionics_voltage: 'payload' is not a number"},
      {"avionics_voltage", "12V", 0, "'12V' is not a number"},
      {"avionics_voltage", "nan", 0, "is not a number"},
      {"avionics_voltage", "", 0, "'' is not a number"},
      // The spec's range, step and mask, before anything is sent (interface.md 3.2: exit 2).
      {"packets_streamed", "0x20", 0, "packets_streamed 32 has bits outside the defined mask 0x1F"},
      {"packets_streamed", "32", 0, "packets_streamed 32 has bits outside the defined mask 0x1F"},
      {"power_up_state", "0x80", 0, "power_up_state 128 has bits outside the defined mask 0x7F"},
      {"avionics_voltage", "99", 0, "value 99.0 V out of range 12.0..24.0 V for avionics_voltage"},
      {"can_address", "65535", 0, "out of range"},
      {"cranking_time", "2.55", 0, "is not a multiple of 0.1 s"},
      {"packets_streamed", "0x1F", 0x1F, nullptr},
      {"can_address", "65534", 65534, nullptr},
  };
  for (const auto& r : rows) {
    const auto v = parse_config_value(r.parameter, r.text);
    if (r.refusal) {
      EXPECT_FALSE(v.value) << r.parameter << " " << r.text;
      EXPECT_NE(v.error.find(r.refusal), std::string::npos) << r.text << ": " << v.error;
    } else {
      ASSERT_TRUE(v.value) << r.parameter << " '" << r.text << "': " << v.error;
      EXPECT_EQ(*v.value, r.value) << r.text;
    }
  }
}

// Every watch row says its device's health and its values' age.
TEST(PmuctlView, WatchRowsSayHealthAndAge) {
  struct Row {
    std::optional<pmu::v5::HealthState> state;
    double age;
    const char* text;
  };
  const std::vector<Row> rows = {
      {pmu::v5::ONLINE, 0.2, "ONLINE 0.2s"},    {pmu::v5::STALE, 3.04, "STALE 3.0s"},
      {pmu::v5::OFFLINE, 9.06, "OFFLINE 9.1s"}, {pmu::v5::OFFLINE, 42, "OFFLINE 42s"},
      {pmu::v5::OFFLINE, 720, "OFFLINE 12m"},   {pmu::v5::OFFLINE, 72000, "OFFLINE 20h"},
      {std::nullopt, 1, "UNKNOWN 1.0s"},        {pmu::v5::ONLINE, -0.5, "ONLINE 0.0s"},
  };
  for (const auto& r : rows) EXPECT_EQ(freshness(r.state, r.age), r.text);
  EXPECT_EQ(row_values(fields_of(temperatures())),
            "internal=31.0degC battery_a=no sensor battery_b=22.0degC generator=no sensor starter=-49.0degC");
}

// One line per device and topic, grouped by topic; the short topics fit an 80-column
// terminal (the wider ones, e.g. voltages, do not).
TEST(PmuctlView, WatchTableHasOneLinePerDeviceAndTopic) {
  pmu::v5::BatteryEnergy e;
  e.battery_a_mah(-1200), e.battery_b_mah(850);
  const auto lines =
      watch_table({{"uav1/can0/1", "battery_energy", pmu::v5::ONLINE, 0.2, fields_of(e)},
                   {"uav1/can0/battery2", "battery_cells", std::nullopt, 1.0, fields_of(battery_cells())},
                   {"uav1/can0/2", "battery_energy", pmu::v5::OFFLINE, 9.06, fields_of(e)}});
  const std::vector<std::string> want = {
      "battery_energy:",
      "uav1/can0/1  ONLINE   0.2s  battery_a_mah=-1200mAh battery_b_mah=850mAh",
      "uav1/can0/2  OFFLINE  9.1s  battery_a_mah=-1200mAh battery_b_mah=850mAh",
      "battery_cells:",
      "uav1/can0/battery2  UNKNOWN  1.0s  cells=3 cells 3.301..3.412 V",
  };
  EXPECT_EQ(lines, want);
  for (const auto& l : lines) EXPECT_LE(l.size(), 80u) << l;
}

TEST(PmuctlView, BatteryCellsAreOneShortRow) {
  const auto f = fields_of(battery_cells());
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].text, "3 cells 3.301..3.412 V");
  EXPECT_EQ(f[0].json.size(), 3u) << "JSON keeps every cell";
  EXPECT_EQ(f[0].json[1]["cell"], 2);
  EXPECT_EQ(f[0].json[1]["cell_voltage"], 3.301);
  EXPECT_EQ(fields_of(pmu::v5::BatteryCells{})[0].text, "none received");
}

// The JSON keys are the contract's field names, in its order (interface.md sections 1.3, 1.4).
TEST(PmuctlView, JsonKeysAreTheContractsNames) {
  auto keys = [](const SampleFields& f) {
    const Json j = json_of(f);
    std::string s;
    for (auto it = j.begin(); it != j.end(); ++it) s += (s.empty() ? "" : ",") + it.key();
    return s;
  };
  EXPECT_EQ(keys(fields_of(voltages())), "avionics,output_28v,payload,servo,battery_a,battery_b,generator");
  EXPECT_EQ(keys(fields_of(currents())), "avionics,output_28v,payload,servo,battery_a,battery_b");
  EXPECT_EQ(keys(fields_of(temperatures())), "internal,battery_a,battery_b,generator,starter");
  EXPECT_EQ(keys(fields_of(status(0))),
            "generator_rpm,generation_enabled,thermal_shutdown,soa_shutdown,start_button,payload_shed,"
            "starter_ready,avionics_servo_on,payload_on,charger_a_on,charger_b_on");
  EXPECT_EQ(keys(fields_of(config())),
            "avionics_voltage,payload_voltage,servo_voltage,battery_voltage,packet_period,packets_streamed,"
            "temperature_offset,upper_temperature_limit,power_up_state,cranking_time,can_address,outputs,"
            "generation_enabled");
  EXPECT_EQ(keys(fields_of(health(1))),
            "state,bus_state,last_frame_age,frames_received,frames_sent,decode_errors,bus_errors,rx_dropped,"
            "timeouts,reconnects,publish_failures");
  EXPECT_EQ(keys(fields_of(battery(1))),
            "voltage,current,current_discharge,current_charge,state_of_charge,time_to_go,cell_temperature_high,"
            "cell_temperature_low,cell_voltage_high,cell_voltage_low,bms_state,temperature_1,temperature_2,"
            "temperature_3,temperature_4,power_level");
  EXPECT_EQ(field(fields_of(battery(1)), "voltage").json, 48.123) << "the float's shortest decimal";
}

TEST(PmuctlView, ListColumnsAreAsWideAsTheirCells) {
  const auto lines = aligned_columns({{"VEHICLE", "BUS", "DEVICE", "LAST FRAME"},
                                      {"-", "can0", "1", "0.2s ago"},
                                      {"uav1", "can0", "battery2", "never"}});
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "VEHICLE  BUS   DEVICE    LAST FRAME");
  EXPECT_EQ(lines[1], "-        can0  1         0.2s ago");
  EXPECT_EQ(lines[2], "uav1     can0  battery2  never");
}

TEST(PmuctlView, StateVerbsShowOneValuePerLine) {
  EXPECT_EQ(value_block("can0/1", fields_of(temperatures())),
            "can0/1\n"
            "  internal                 31.0 degC\n"
            "  battery_a                no sensor\n"
            "  battery_b                22.0 degC\n"
            "  generator                no sensor\n"
            "  starter                  -49.0 degC\n");
}

}  // namespace
}  // namespace pmu::tools

namespace pmu::tools {
namespace {

// --json through sample_json.hpp: sentinels are null, raw counts integers; the rest as before.
TEST(PmuctlViewJson, SentinelsAreNullAndRawCountsIntegers) {
  pmu::v5::Health h;
  h.last_frame_age(std::numeric_limits<float>::quiet_NaN());
  EXPECT_TRUE(values_of(h)["last_frame_age"].is_null()) << values_of(h);
  pmu::v5::Status st;
  st.generator_rpm(std::numeric_limits<float>::quiet_NaN());
  EXPECT_TRUE(values_of(st)["generator_rpm"].is_null()) << values_of(st);
  pmu::v5::Battery b;
  b.time_to_go(std::numeric_limits<float>::quiet_NaN()), b.received(1u << 5);
  EXPECT_TRUE(values_of(b)["time_to_go"].is_null()) << values_of(b);
  pmu::v5::Mppt m;
  m.voltage_output_raw(1234), m.received(1u << 0);
  EXPECT_EQ(values_of(m)["voltage_output_raw"].dump(), "1234");
  pmu::v5::Temperatures t;
  t.internal(30), t.battery_a(std::numeric_limits<float>::quiet_NaN());
  EXPECT_TRUE(values_of(t)["battery_a"].is_null());
  EXPECT_EQ(values_of(t)["internal"].dump(), "30.0");
}

}  // namespace
}  // namespace pmu::tools
