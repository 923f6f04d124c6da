// pmu-sim's battery and MPPT options: bad values are refused before any bus is opened, and
// --help documents them. (Playing them on a bus: tests/sim/runner_solar_test.cpp, the same
// BusRunner pmu-sim uses.)
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
};

TEST(PmuSimOptions, BadBatteryAndMpptValuesAreRefusedBeforeTheBusIsOpened) {
  for (const auto& c : kBad) {
    SCOPED_TRACE(c.args);
    const auto r = pmu::test::run_capture(std::string(PMU_SIM_PATH) + " vcan0 " + c.args + " 2>&1");
    EXPECT_EQ(r.status, 2) << "(1 would mean it got as far as opening the bus) " << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << r.out;
  }
}

TEST(PmuSimOptions, HelpDocumentsTheBatteryAndMpptOptions) {
  const auto r = pmu::test::run_capture(std::string(PMU_SIM_PATH) + " --help");
  EXPECT_EQ(r.status, 0);
  for (const char* option : {"--battery", "--mppt", "--no-pmu", "--cells", "--battery-period", "--mppt-period",
                             "--load", "--sun"}) {
    EXPECT_NE(r.out.find(option), std::string::npos) << option;
  }
}

}  // namespace
