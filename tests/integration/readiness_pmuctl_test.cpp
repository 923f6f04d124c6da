// Alarms and readiness as a ground station reads them (docs/interface.md 1.6, 1.7, 3.2):
// pmu-service on the configured simulator, pmuctl alarms and pmuctl preflight.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <regex>
#include <string>
#include <thread>

#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"

namespace {

using namespace std::chrono_literals;

std::string config(const std::string& domain, const std::string& device_1) {
  return "domain: " + domain +
         "\nqos_file: " PMU_QOS_FILE
         "\nbuses:\n  - interface: sim\n    devices:\n      - address: 1\n        period: 0.5\n" +
         device_1;
}

// Runs `command` until `done` holds for its result, for at most `within`.
template <class Done>
pmu::test::RunResult until(const std::string& command, Done done, std::chrono::seconds within) {
  const auto deadline = std::chrono::steady_clock::now() + within;
  pmu::test::RunResult r = pmu::test::run_capture(command);
  while (!done(r) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(500ms);
    r = pmu::test::run_capture(command);
  }
  return r;
}

TEST(ReadinessOverDds, AHealthyVehicleIsReadyWithNoAlarm) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, ""));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto ready = until(
      p + "--timeout 10 --json preflight", [](const auto& r) { return r.status == 0; }, 30s);
  ASSERT_EQ(ready.status, 0) << ready.out << service.describe();
  const auto lines = pmu::test::json_lines(ready.out);
  ASSERT_EQ(lines.size(), 1u) << ready.out;
  EXPECT_EQ(lines[0]["ready"], true);
  EXPECT_EQ(lines[0]["level"], "READY");
  EXPECT_TRUE(lines[0]["reasons"].empty()) << ready.out;
  const auto alarms = pmu::test::run_capture(p + "--timeout 5 --json alarms");
  EXPECT_EQ(alarms.status, 0);
  EXPECT_TRUE(pmu::test::json_lines(alarms.out).empty()) << alarms.out;
}

TEST(ReadinessOverDds, AHotPmuRaisesItsAlarmAndMakesTheVehicleNotReady) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, "        sim: {internal_temperature: 95}\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto alarms = until(
      p + "--timeout 10 --json alarms",
      [](const auto& r) { return r.out.find("thermal_shutdown") != std::string::npos; }, 30s);
  ASSERT_EQ(alarms.status, 0) << alarms.out << service.describe();
  bool found = false;
  for (const auto& j : pmu::test::json_lines(alarms.out)) {
    if (j.value("code", "") != "thermal_shutdown") continue;
    found = true;
    EXPECT_EQ(j["severity"], "critical");
    EXPECT_EQ(j["state"], "ACTIVE_UNACKNOWLEDGED");
    EXPECT_EQ(j["kind"], "pmu");
    EXPECT_EQ(j["device"], 1);
    EXPECT_TRUE(j["value"].is_null()) << "a flag";
  }
  EXPECT_TRUE(found) << alarms.out;

  const auto r = pmu::test::run_capture(p + "--timeout 10 preflight");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("NOT READY"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CRITICAL thermal_shutdown"), std::string::npos) << r.out;
}

// Polled for voltages and currents only, a PMU at 95 degC (in thermal shutdown over its T_U
// of 80) raises no alarm: neither the flag nor the temperature reaches the service. The
// vehicle is not ready for want of them (input_missing, docs/safety.md H6).
TEST(ReadinessOverDds, APmuWhoseAlarmsSeeNothingIsNotReady) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH,
                                       config(domain,
                                              "        mode: polling\n        packets: [voltages, currents]\n"
                                              "        sim: {internal_temperature: 95}\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto r = until(
      p + "--timeout 10 preflight",
      [](const auto& x) { return x.out.find("temperatures not monitored") != std::string::npos; }, 30s);
  EXPECT_EQ(r.status, 1) << r.out << service.describe();
  EXPECT_NE(r.out.find("NOT READY"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CRITICAL input_missing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("PMU 1 temperatures not monitored"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("PMU 1 status not monitored"), std::string::npos) << r.out;
}

// watch shows the alarm with the device's telemetry: a marker on its lines, and with --json
// the alarm's own line, as `pmuctl alarms --json` prints it.
TEST(ReadinessOverDds, WatchMarksTheHotPmusLinesWithItsAlarm) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, "        sim: {internal_temperature: 95}\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  // After the state and age, before the values: "... sim/1 temperatures ONLINE 0.3s ALARM ... internal=95.0degC ...";
  // 1 alarm, or 2 once internal_over_temperature's on-delay is over: the critical is the worst either way.
  const std::regex marked(
      " sim/1 temperatures [A-Z]+ [0-9.]+s ALARM [12] CRIT unacked \\(thermal_shutdown\\) internal=");
  const auto text = until(
      p + "--timeout 20 watch --count 15", [&marked](const auto& r) { return std::regex_search(r.out, marked); }, 30s);
  ASSERT_EQ(text.status, 0) << text.out << service.describe();
  EXPECT_TRUE(std::regex_search(text.out, marked)) << text.out;
  EXPECT_NE(text.out.find(" sim/1 alarms CRITICAL ACTIVE_UNACKNOWLEDGED thermal_shutdown"), std::string::npos)
      << text.out;

  const auto json = pmu::test::run_capture(p + "--timeout 20 --json watch --count 30");
  ASSERT_EQ(json.status, 0) << json.out;
  std::size_t alarms = 0, telemetry = 0;
  for (const auto& j : pmu::test::json_lines(json.out)) {
    if (j.value("topic", "") != "alarms") {
      ++telemetry;
      continue;
    }
    ++alarms;
    if (j.value("code", "") != "thermal_shutdown") continue;
    EXPECT_EQ(j["severity"], "critical");
    EXPECT_EQ(j["state"], "ACTIVE_UNACKNOWLEDGED");
    EXPECT_EQ(j["kind"], "pmu");
    EXPECT_EQ(j["device"], 1);
    EXPECT_EQ(j["bus"], "sim");
    EXPECT_TRUE(j.contains("contract"));
  }
  EXPECT_EQ(telemetry, 30u) << "--count counts the telemetry only: " << json.out;
  EXPECT_GE(alarms, 1u) << json.out;
  EXPECT_NE(json.out.find("\"code\":\"thermal_shutdown\""), std::string::npos) << json.out;
}

TEST(ReadinessOverDds, AnAlarmAcknowledgedFromTheGroundIsActiveAcknowledged) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain, "        sim: {internal_temperature: 95}\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto raised = until(
      p + "--timeout 10 --json alarms",
      [](const auto& r) { return r.out.find("thermal_shutdown") != std::string::npos; }, 30s);
  ASSERT_NE(raised.out.find("ACTIVE_UNACKNOWLEDGED"), std::string::npos) << raised.out << service.describe();

  const auto ack = pmu::test::run_capture(p + "--timeout 10 --json alarms ack thermal_shutdown");
  ASSERT_EQ(ack.status, 0) << ack.out << service.describe();
  const auto reply = pmu::test::json_lines(ack.out);
  ASSERT_EQ(reply.size(), 1u) << ack.out;
  EXPECT_EQ(reply[0]["result"], "COMPLETED");
  EXPECT_EQ(reply[0]["reason"], "acknowledged");
  EXPECT_EQ(reply[0]["state"], "ACTIVE_ACKNOWLEDGED");
  EXPECT_EQ(reply[0]["bus"], "sim");
  EXPECT_EQ(reply[0]["device"], 1);

  const auto alarms = until(
      p + "--timeout 10 --json alarms",
      [](const auto& r) { return r.out.find("ACTIVE_ACKNOWLEDGED") != std::string::npos; }, 20s);
  EXPECT_NE(alarms.out.find("ACTIVE_ACKNOWLEDGED"), std::string::npos) << alarms.out;

  // Again: idempotent, and said so.
  const auto again = pmu::test::run_capture(p + "--timeout 10 --json alarms ack thermal_shutdown");
  EXPECT_EQ(again.status, 0) << again.out;
  EXPECT_NE(again.out.find("nothing to acknowledge: ACTIVE_ACKNOWLEDGED"), std::string::npos) << again.out;
  const auto bus = pmu::test::run_capture(p + "--timeout 10 --json alarms ack bus_off --kind bus --bus sim");
  EXPECT_EQ(bus.status, 0) << bus.out;
  EXPECT_NE(bus.out.find("nothing to acknowledge: NORMAL"), std::string::npos) << bus.out;
  // A device the bus does not have has no such alarm: REJECTED, exit 1.
  const auto wrong =
      pmu::test::run_capture(p + "--timeout 10 --json alarms ack bms_low_soc --kind battery --bus sim --address 9");
  EXPECT_EQ(wrong.status, 1) << wrong.out;
  EXPECT_NE(wrong.out.find("\"REJECTED\""), std::string::npos) << wrong.out;
  const auto bad = pmu::test::run_capture(p + "--timeout 2 alarms ack thermal_shutdown --kind engine", true);
  EXPECT_EQ(bad.status, 2) << bad.out;
}

// A baseline that the simulator's factory values do not meet (V_A 12.0 V, not 22.0 V):
// preflight names the setting and the fix, and pmu/baseline carries the file.
TEST(ReadinessOverDds, ASettingThatDiffersFromTheBaselineMakesTheVehicleNotReady) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  char path[] = "/tmp/pmu-baseline-XXXXXX";
  const int fd = ::mkstemp(path);
  ASSERT_GE(fd, 0);
  const std::string text = "device:\n  serial: 1001\nparameters:\n  avionics_voltage: 22.0\n";
  ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fd);
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH,
                                       config(domain, std::string("        baseline: ") + path + "\n"));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " ";
  const auto r = until(
      p + "--timeout 10 --json preflight",
      [](const auto& x) { return x.out.find("config_differs") != std::string::npos; }, 30s);
  ::unlink(path);
  ASSERT_EQ(r.status, 1) << r.out << service.describe();
  const auto lines = pmu::test::json_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << r.out;
  bool found = false;
  for (const auto& reason : lines[0]["reasons"]) {
    if (reason.value("code", "") != "config_differs") continue;
    found = true;
    EXPECT_EQ(reason["severity"], "critical");
    EXPECT_EQ(reason["device"], 1);
    EXPECT_EQ(reason["message"], "config differs: avionics_voltage");
    EXPECT_NE(reason.value("description", "").find("avionics_voltage 12.0 V->22.0 V"), std::string::npos) << r.out;
  }
  EXPECT_TRUE(found) << r.out;
  EXPECT_EQ(r.out.find("serial_differs"), std::string::npos)
      << "the simulated unit at address 1 has serial 1001: " << r.out;
  EXPECT_NE(service.describe().find("configuration differs from baseline"), std::string::npos) << service.describe();
}

TEST(ReadinessOverDds, NothingOnTheDomainIsExitThree) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  const auto r =
      pmu::test::run_capture(std::string(PMUCTL_PATH) + " --domain " + domain + " --timeout 1 preflight", true);
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("no pmu-service on domain"), std::string::npos) << r.out;
}

}  // namespace
