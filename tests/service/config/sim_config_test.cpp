// The `sim:` mapping of a device on an `interface: sim` bus (docs/interface.md section 4.4):
// every key read into plain settings, every bad one refused with FILE:LINE and what is wrong.
// What the simulated units then do with them: tests/service/app/simulated_bus_test.cpp.
#include <gtest/gtest.h>

#include <string>

#include "pmu/config/config.hpp"

namespace pmu::service {
namespace sim_config_test {  // named: the unity build joins this file with others of its target
namespace {

using std::chrono::milliseconds;

const char* const kEveryKey = R"(buses:
  - interface: sim
    devices:
      - address: 1
        sim:
          engine: stopped
          engine_starts_after: 7.5
          internal_temperature: 95
          battery_a_voltage: 21.5
          battery_b_voltage: 0
          starter_ready: false
          silent: true
          soa_shutdown: true
          payload_shed: true
          firmware: "1.14"
          serial: 4242
          ignores_set: cranking_time
      - address: 2
        sim:
          engine_starts_after: never
      - address: 3
    batteries:
      - node: 2
        sim:
          state_of_charge: 42.5
          cell_voltages: [3.9, 4.25, 3.1]
          silent: true
          garble: wrong_length
    mppts:
      - device: 0
        sim:
          panels: 2
          silent: true
          garble: unknown_subindex
      - device: 1
        sim: {}
)";

TEST(SimConfig, EveryKeyIsRead) {
  const Config c = parse_config(kEveryKey, "sim.yaml");
  const BusConfig& b = c.buses.at(0);
  ASSERT_EQ(b.devices.size(), 3u);
  ASSERT_EQ(b.sim.pmus.count(1), 1u);
  const PmuSimSettings& p = b.sim.pmus.at(1);
  EXPECT_FALSE(p.engine_running);
  EXPECT_EQ(p.engine_starts_after, milliseconds(7500));
  EXPECT_FALSE(p.engine_never_starts);
  EXPECT_EQ(p.internal_temperature, 95.0);
  EXPECT_EQ(p.battery_a_voltage, 21.5);
  EXPECT_EQ(p.battery_b_voltage, 0.0);
  EXPECT_EQ(p.starter_ready, false);
  EXPECT_TRUE(p.silent);
  EXPECT_EQ(p.soa_shutdown, true);
  EXPECT_EQ(p.payload_shed, true);
  EXPECT_EQ(p.firmware, (codec::FirmwareVersion{1, 14}));
  EXPECT_EQ(p.serial, std::optional<std::uint16_t>(4242));
  EXPECT_EQ(p.ignores_set, codec::Parameter::CrankingTime);

  ASSERT_EQ(b.sim.pmus.count(2), 1u);
  const PmuSimSettings& flooded = b.sim.pmus.at(2);
  EXPECT_TRUE(flooded.engine_running) << "running unless said";
  EXPECT_TRUE(flooded.engine_never_starts);
  EXPECT_FALSE(flooded.engine_starts_after);
  EXPECT_FALSE(flooded.internal_temperature) << "unset: the model's own value";
  EXPECT_FALSE(flooded.starter_ready);
  EXPECT_FALSE(flooded.silent);
  EXPECT_EQ(b.sim.pmus.count(3), 0u) << "no sim: mapping";

  ASSERT_EQ(b.sim.batteries.count(2), 1u);
  const BatterySimSettings& bat = b.sim.batteries.at(2);
  EXPECT_EQ(bat.state_of_charge, 42.5);
  EXPECT_FALSE(bat.cells) << "the list gives the count";
  EXPECT_EQ(bat.cell_voltages, (std::vector<double>{3.9, 4.25, 3.1}));
  EXPECT_TRUE(bat.silent);
  EXPECT_EQ(bat.garble, SimGarble::WrongLength);

  ASSERT_EQ(b.mppts.size(), 2u);
  ASSERT_EQ(b.sim.mppts.size(), 2u);
  EXPECT_EQ(b.sim.mppts.at(0).panels, 2);
  EXPECT_TRUE(b.sim.mppts.at(0).silent);
  EXPECT_EQ(b.sim.mppts.at(0).garble, SimGarble::UnknownSubindex);
  EXPECT_FALSE(b.sim.mppts.at(1).panels) << "an empty mapping is the defaults";
  EXPECT_FALSE(b.sim.mppts.at(1).silent);
  EXPECT_EQ(b.sim.mppts.at(1).garble, SimGarble::None);
}

TEST(SimConfig, CellsAloneAndCellsWithAsManyVoltages) {
  const Config c = parse_config(R"(buses:
  - interface: sim
    batteries:
      - node: 2
        sim: {cells: 4, cell_voltages: [3.7, 3.7, 3.7, 3.6], state_of_charge: 0, garble: none}
  - interface: sim
    name: sim1
    batteries:
      - node: 2
        sim: {cells: 15, state_of_charge: 100}
)",
                                "sim.yaml");
  const BatterySimSettings& four = c.buses[0].sim.batteries.at(2);
  EXPECT_EQ(four.cells, 4);
  EXPECT_EQ(four.cell_voltages.size(), 4u);
  EXPECT_EQ(four.state_of_charge, 0.0);
  const BatterySimSettings& fifteen = c.buses[1].sim.batteries.at(2);
  EXPECT_EQ(fifteen.cells, 15);
  EXPECT_TRUE(fifteen.cell_voltages.empty());
}

struct BadCase {
  const char* yaml;  // appended to a sim bus whose device list starts on line 3
  const char* message;
};

// A PMU's sim: mapping starts on line 5, a battery's on line 4, an MPPT's on line 4.
const char* const kPmu = "buses:\n  - interface: sim\n    devices:\n      - address: 1\n        sim:\n";
const char* const kBattery = "buses:\n  - interface: sim\n    batteries:\n      - node: 2\n        sim:\n";
const char* const kMppt = "buses:\n  - interface: sim\n    mppts:\n      - device: 0\n        sim:\n";

const BadCase kBadPmu[] = {
    {"          engin: stopped\n",
     "bad.yaml:6: unknown key 'engin' in the PMU's sim (known: engine, engine_starts_after, internal_temperature, "
     "battery_a_voltage, battery_b_voltage, starter_ready, silent, soa_shutdown, payload_shed, firmware, serial, "
     "ignores_set)"},
    {"          engine: off\n", "bad.yaml:6: engine must be running or stopped, not 'off'"},
    {"          engine: [running]\n", "bad.yaml:6: engine must be running or stopped"},
    {"          engine_starts_after: soon\n",
     "bad.yaml:6: engine_starts_after must be seconds (0..3600) or never, not 'soon'"},
    {"          engine_starts_after: [1]\n",
     "bad.yaml:6: engine_starts_after must be seconds (0..3600) or never, not 'a list or mapping'"},
    {"          engine_starts_after: -1\n", "bad.yaml:6: engine_starts_after -1 out of range 0..3600"},
    {"          engine_starts_after: 3601\n", "bad.yaml:6: engine_starts_after 3601 out of range 0..3600"},
    {"          internal_temperature: 128\n", "bad.yaml:6: internal_temperature 128 out of range -127..127"},
    {"          internal_temperature: hot\n", "bad.yaml:6: internal_temperature must be a number, not 'hot'"},
    {"          battery_a_voltage: 25.1\n", "bad.yaml:6: battery_a_voltage 25.1 out of range 0..25"},
    {"          battery_b_voltage: -1\n", "bad.yaml:6: battery_b_voltage -1 out of range 0..25"},
    {"          starter_ready: maybe\n", "bad.yaml:6: starter_ready must be true or false, not 'maybe'"},
    {"          silent: 2\n", "bad.yaml:6: silent must be true or false, not '2'"},
    {"          soa_shutdown: yes please\n", "bad.yaml:6: soa_shutdown must be true or false, not 'yes please'"},
    {"          payload_shed: []\n", "bad.yaml:6: payload_shed must be true or false"},
    {"          firmware: 1.x\n", "bad.yaml:6: firmware '1.x' is not MAJOR.MINOR (each 0..255, e.g. \"1.14\")"},
    {"          firmware: \"9.9\"\n",
     "bad.yaml:6: firmware '9.9': the simulator is firmware 1.12..1.17 (the versions the protocol documents "
     "describe)"},
    {"          firmware: \"1.11\"\n",
     "bad.yaml:6: firmware '1.11': the simulator is firmware 1.12..1.17 (the versions the protocol documents "
     "describe)"},
    {"          firmware: \"1.18\"\n",
     "bad.yaml:6: firmware '1.18': the simulator is firmware 1.12..1.17 (the versions the protocol documents "
     "describe)"},
    {"          serial: 65536\n", "bad.yaml:6: serial 65536 out of range 0..65535"},
    {"          serial: 0x10\n",
     "bad.yaml:6: serial must be a decimal integer (digits, optionally after '-'; no leading 0, '+', 0x, 0o, "
     "exponent or fraction), not '0x10'"},
    {"          ignores_set: cranking\n", "bad.yaml:6: ignores_set: 'cranking' is not a stored parameter"},
    {"          silent: true\n          silent: false\n",
     "bad.yaml:7: key 'silent' appears twice in one mapping (first on line 6); give each key once"},
    {"          - engine\n", "bad.yaml:6: the PMU's sim must be a mapping of key: value"},
};

const BadCase kBadBattery[] = {
    {"          soc: 50\n",
     "bad.yaml:6: unknown key 'soc' in the battery's sim (known: state_of_charge, cells, cell_voltages, silent, garble)"},
    {"          state_of_charge: 101\n", "bad.yaml:6: state_of_charge 101 out of range 0..100"},
    {"          state_of_charge: full\n", "bad.yaml:6: state_of_charge must be a number, not 'full'"},
    {"          cells: 16\n", "bad.yaml:6: cells 16 out of range 1..15"},
    {"          cells: 0\n", "bad.yaml:6: cells 0 out of range 1..15"},
    {"          cells: 4.5\n",
     "bad.yaml:6: cells must be a decimal integer (digits, optionally after '-'; no leading 0, '+', 0x, 0o, exponent "
     "or fraction), not '4.5'"},
    {"          cell_voltages: 3.9\n",
     "bad.yaml:6: cell_voltages must be a list of 1..15 voltages, cell 1 first, e.g. [3.9, 3.9, 3.7]"},
    {"          cell_voltages: []\n",
     "bad.yaml:6: cell_voltages must be a list of 1..15 voltages, cell 1 first, e.g. [3.9, 3.9, 3.7]"},
    {"          cell_voltages: [3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9, 3.9]\n",
     "bad.yaml:6: cell_voltages must be a list of 1..15 voltages, cell 1 first, e.g. [3.9, 3.9, 3.7]"},
    {"          cell_voltages:\n            - 3.9\n            - 5.1\n",
     "bad.yaml:8: cell voltage 5.1 out of range 0..5"},
    {"          cell_voltages: [3.9, x]\n", "bad.yaml:6: cell voltage must be a number, not 'x'"},
    {"          cells: 3\n          cell_voltages: [3.9, 3.9]\n",
     "bad.yaml:7: cell_voltages has 2 voltages but cells is 3 (give one per cell, or leave cells out)"},
    {"          garble: always\n", "bad.yaml:6: garble must be none, wrong_length or unknown_subindex, not 'always'"},
    {"          silent: no way\n", "bad.yaml:6: silent must be true or false, not 'no way'"},
};

const BadCase kBadMppt[] = {
    {"          panel: 2\n", "bad.yaml:6: unknown key 'panel' in the MPPT's sim (known: panels, silent, garble)"},
    {"          panels: 5\n", "bad.yaml:6: panels 5 out of range 0..4"},
    {"          panels: -1\n", "bad.yaml:6: panels -1 out of range 0..4"},
    {"          garble: [none]\n", "bad.yaml:6: garble must be none, wrong_length or unknown_subindex"},
    {"          silent: sometimes\n", "bad.yaml:6: silent must be true or false, not 'sometimes'"},
};

void expect_refused(const std::string& yaml, const std::string& message) {
  SCOPED_TRACE(yaml);
  try {
    (void)parse_config(yaml, "bad.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

TEST(SimConfig, EveryBadPmuSettingIsRefusedWithItsLine) {
  for (const auto& c : kBadPmu) expect_refused(std::string(kPmu) + c.yaml, c.message);
}

TEST(SimConfig, EveryBadBatterySettingIsRefusedWithItsLine) {
  for (const auto& c : kBadBattery) expect_refused(std::string(kBattery) + c.yaml, c.message);
}

TEST(SimConfig, EveryBadMpptSettingIsRefusedWithItsLine) {
  for (const auto& c : kBadMppt) expect_refused(std::string(kMppt) + c.yaml, c.message);
}

TEST(SimConfig, ASimMappingOnARealBusIsRefusedAtTheSimKey) {
  const BadCase cases[] = {
      {"buses:\n  - interface: can0\n    devices:\n      - address: 1\n        sim:\n          engine: stopped\n",
       "bad.yaml:5: sim: sets up the built-in simulator, but this bus has interface 'can0', not sim (remove sim:, or "
       "set interface: sim)"},
      {"buses:\n  - interface: vcan0\n    name: bench\n    batteries:\n      - node: 2\n        sim: {silent: true}\n",
       "bad.yaml:6: sim: sets up the built-in simulator, but this bus has interface 'vcan0', not sim (remove sim:, "
       "or set interface: sim)"},
      // Refused for the bus it is on even when the settings themselves are bad.
      {"buses:\n  - interface: can1\n    mppts:\n      - device: 3\n        sim: {panels: 9}\n",
       "bad.yaml:5: sim: sets up the built-in simulator, but this bus has interface 'can1', not sim (remove sim:, or "
       "set interface: sim)"},
  };
  for (const auto& c : cases) expect_refused(c.yaml, c.message);
}

TEST(SimConfig, BusOverrideToARealBusDropsTheSimulatorSettings) {
  Config c = parse_config(kEveryKey, "sim.yaml");
  override_bus(c, "sim");
  EXPECT_EQ(c.buses[0].sim.pmus.size(), 2u) << "kept on a simulated bus";
  EXPECT_EQ(c.buses[0].sim.batteries.size(), 1u);
  override_bus(c, "socketcan:vcan0");
  EXPECT_TRUE(c.buses[0].sim.pmus.empty());
  EXPECT_TRUE(c.buses[0].sim.batteries.empty());
  EXPECT_TRUE(c.buses[0].sim.mppts.empty());
}

}  // namespace
}  // namespace sim_config_test
}  // namespace pmu::service
