// pmu-sim's options: bad values are refused before any bus is opened, and --help documents
// them. (Playing them on a bus: tests/sim/runner_solar_test.cpp, the same BusRunner pmu-sim
// uses; the world options are the keys of pmu-service's sim: mappings, whose effect on the
// models tests/service/app/simulated_bus_test.cpp shows.)
#include <gtest/gtest.h>

#include <string>

#include "support/process.hpp"

namespace {

struct BadCase {
  const char* args;
  const char* message;  // part of stderr naming what is wrong
};

const BadCase kBad[] = {
    {"--no-pmu", "pmu-sim: --no-pmu needs --battery or --mppt"},
    {"--no-pmu --address 3 --battery 2", "excludes --no-pmu"},
    {"--battery 0", "--battery: Value 0 not in range 1 to 127"},
    {"--battery 128", "--battery: Value 128 not in range 1 to 127"},
    {"--mppt 8", "--mppt: Value 8 not in range 0 to 7"},
    {"--battery 2 --cells 16", "--cells: Value 16 not in range 1 to 15"},
    {"--battery 2 --cells 0", "--cells: Value 0 not in range 1 to 15"},
    {"--battery 2 --battery-period 0", "--battery-period: Value 0 not in range"},
    {"--mppt 1 --mppt-period -5", "--mppt-period"},
    {"--mppt 1 --sun -1", "--sun: Value -1 not in range"},
    {"--battery 2 --load x", "--load"},
    // The PMUs' world: pmu-service's sim: keys (interface.md 4.4) under the same names.
    {"--engine off", "--engine: off not in {running,stopped}"},
    {"--engine stopped --engine-stopped", "--engine excludes --engine-stopped"},
    {"--engine-starts-after soon", "pmu-sim: --engine-starts-after 'soon' is not seconds (0..3600) or never"},
    {"--engine-starts-after -1", "pmu-sim: --engine-starts-after '-1' is not seconds (0..3600) or never"},
    {"--engine-starts-after 3601", "pmu-sim: --engine-starts-after '3601' is not seconds (0..3600) or never"},
    {"--engine-starts-after 2s", "pmu-sim: --engine-starts-after '2s' is not seconds (0..3600) or never"},
    {"--internal-temperature 128", "--internal-temperature: Value 128 not in range -127 to 127"},
    {"--internal-temperature hot", "--internal-temperature: Value hot is not a number"},
    {"--battery-a-voltage 25.1", "--battery-a-voltage: Value 25.1 not in range 0 to 25"},
    {"--battery-b-voltage -1", "--battery-b-voltage: Value -1 not in range 0 to 25"},
    {"--starter-ready maybe", "--starter-ready: maybe not in {true,false}"},
    {"--no-pmu --battery 2 --silent", "--silent excludes --no-pmu"},
    {"--no-pmu --battery 2 --engine stopped", "--engine excludes --no-pmu"},
    {"--no-pmu --mppt 0 --internal-temperature 95", "--internal-temperature excludes --no-pmu"},
    // The batteries' and MPPTs': only with a battery or an MPPT to play.
    {"--state-of-charge 50", "--state-of-charge requires --battery"},
    {"--battery 2 --state-of-charge 101", "--state-of-charge: Value 101 not in range 0 to 100"},
    {"--battery 2 --cell-voltages 3.9,x", "--cell-voltages: Value x is not a number"},
    {"--battery 2 --cell-voltages 3.9,5.1", "--cell-voltages: Value 5.1 not in range 0 to 5"},
    {"--battery 2 --cells 3 --cell-voltages 3.9,3.9",
     "pmu-sim: --cell-voltages gives 2 voltages but --cells is 3 (one per cell)"},
    {"--battery 2 --cell-voltages 4,4,4,4,4,4,4,4,4,4,4,4,4,4,4,4",
     "pmu-sim: --cell-voltages gives 16 voltages; a battery has 1..15 cells"},
    {"--cell-voltages 3.9", "--cell-voltages requires --battery"},
    {"--battery 2 --battery-garble always", "--battery-garble: always not in {none,wrong_length,unknown_subindex}"},
    {"--battery-silent", "--battery-silent requires --battery"},
    {"--panels 2", "--panels requires --mppt"},
    {"--mppt 0 --panels 5", "--panels: Value 5 not in range 0 to 4"},
    {"--mppt 0 --mppt-garble [none]", "--mppt-garble: [none] not in {none,wrong_length,unknown_subindex}"},
    {"--mppt-silent", "--mppt-silent requires --mppt"},
    // Only a firmware the documents describe (interface.md 3.3, 4.4).
    {"--firmware 1.11", "pmu-sim: --firmware 1.11: the simulator is firmware 1.12..1.17"},
    {"--firmware 9.9", "pmu-sim: --firmware 9.9: the simulator is firmware 1.12..1.17"},
    {"--firmware 1.x", "pmu-sim: --firmware '1.x' is not a version like 1.16"},
};

TEST(PmuSimOptions, BadValuesAreRefusedBeforeTheBusIsOpened) {
  for (const auto& c : kBad) {
    SCOPED_TRACE(c.args);
    const auto r = pmu::test::run_capture(std::string(PMU_SIM_PATH) + " vcan0 " + c.args + " 2>&1");
    EXPECT_EQ(r.status, 2) << "(1 would mean it got as far as opening the bus) " << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << r.out;
  }
}

// Options that parse get as far as opening the bus: status 1 here (no CAN in this kernel), or
// still running when `timeout` ends it (124) where the interface exists; never 2.
TEST(PmuSimOptions, GoodWorldOptionsAreAccepted) {
  const char* const good[] = {
      "--engine stopped --engine-starts-after never --internal-temperature 95 --silent",
      "--engine running --engine-starts-after 7.5 --battery-a-voltage 19.5 --battery-b-voltage 0 "
      "--starter-ready false --soa-shutdown --payload-shed",
      "--engine-stopped --engine-starts-after 0",
      "--no-pmu --battery 2 --state-of-charge 35 --cell-voltages 3.9,3.9,3.9,3.55 --battery-garble wrong_length "
      "--battery-silent --mppt 0 --panels 2 --mppt-garble unknown_subindex --mppt-silent",
      "--battery 2 --cells 3 --cell-voltages 3.9,4.25,3.1",
      "--firmware 1.12 --serial 7",
      "--firmware 1.17",
  };
  for (const char* args : good) {
    SCOPED_TRACE(args);
    const auto r = pmu::test::run_capture("timeout 2 " + std::string(PMU_SIM_PATH) + " pmusimnone0 " + args + " 2>&1");
    EXPECT_TRUE(r.status == 1 || r.status == 124) << r.status << ": " << r.out;
    EXPECT_NE(r.out.find("pmusimnone0"), std::string::npos) << "(it should have tried the bus) " << r.out;
  }
}

TEST(PmuSimOptions, HelpDocumentsEveryOption) {
  const auto r = pmu::test::run_capture(std::string(PMU_SIM_PATH) + " --help");
  EXPECT_EQ(r.status, 0);
  for (const char* option : {"--battery",
                             "--mppt",
                             "--no-pmu",
                             "--cells",
                             "--battery-period",
                             "--mppt-period",
                             "--load",
                             "--sun",
                             "--engine",
                             "--engine-stopped",
                             "--engine-starts-after",
                             "--internal-temperature",
                             "--battery-a-voltage",
                             "--battery-b-voltage",
                             "--starter-ready",
                             "--soa-shutdown",
                             "--payload-shed",
                             "--silent",
                             "--state-of-charge",
                             "--cell-voltages",
                             "--battery-garble",
                             "--battery-silent",
                             "--panels",
                             "--mppt-garble",
                             "--mppt-silent"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
}

}  // namespace
