// pmuctl's tables read from a running pmu-service on its built-in simulated PMU: mask names
// both ways, units, and health and age on every watch row (interface.md section 3.2).
#include <gtest/gtest.h>

#include <chrono>
#include <regex>
#include <string>

#include "support/domain.hpp"
#include "support/process.hpp"

namespace {

using namespace std::chrono_literals;

TEST(PmuctlViewOnSim, TablesShowNamesUnitsAndHealth) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ChildOptions o;
  o.stdout_path = o.stderr_path = "/dev/null";
  pmu::test::Child service({PMU_SERVICE_PATH, "--bus", "sim", "--domain", domain}, o);
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --timeout 20 ";
  auto run = [&p](const std::string& args) { return pmu::test::run_capture(p + args + " 2>&1"); };

  auto r = run("config set power_up_state avionics_servo,payload");
  EXPECT_EQ(r.status, 0) << r.out;
  r = run("config get power_up_state");
  EXPECT_NE(r.out.find("sim0/1 power_up_state = avionics_servo,payload (0x03)"), std::string::npos) << r.out;
  r = run("--json config get power_up_state");
  EXPECT_NE(r.out.find("\"power_up_state\":3"), std::string::npos) << "JSON keeps the number: " << r.out;
  r = run("config set power_up_state avionics_servo,pay");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("unknown name 'pay'"), std::string::npos) << r.out;

  r = run("config get");
  EXPECT_NE(r.out.find("avionics_voltage         12.0 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("packets_streamed         voltages,currents,battery_energy,temperatures,status (0x1F)"),
            std::string::npos)
      << r.out;

  r = run("watch --count 10");
  ASSERT_EQ(r.status, 0) << r.out;
  // The state is UNKNOWN on lines printed before the first pmu/health sample arrived.
  EXPECT_TRUE(std::regex_search(r.out, std::regex(" sim0/1 voltages (ONLINE|UNKNOWN) [0-9.]+s avionics="))) << r.out;
  EXPECT_NE(r.out.find(" avionics=12.0V "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" generator=no sensor "), std::string::npos) << r.out;
}

}  // namespace
