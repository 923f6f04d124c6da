// The start-up check (startup_check.hpp) that every start and --check-config run: the QoS
// profile file, found, well-formed, loaded and holding the service's profiles, each problem
// with FILE:LINE. Fast DDS keeps loaded profiles for the process (the first file's profile of
// each name); a file is judged by its own profiles whatever the process loaded before.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <string>

#include "pmu/config/config.hpp"
#include "pmu/dds/dds_context.hpp"
#include "pmu/endpoints/startup_check.hpp"
#include "support/process.hpp"

namespace pmu::service {
namespace {

const std::string kShippedQos = PMU_SOURCE_DIR "/deploy/qos.xml";
const char* const kBus = "buses:\n  - interface: sim\n    discover: true\n";

// A folder of its own for each test's files.
std::string scratch(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "startup-check-" + name + "-" + std::to_string(::getpid());
  (void)std::system(("rm -rf '" + dir + "' && mkdir -p '" + dir + "'").c_str());
  return dir;
}

std::string write(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

// The shipped file with one edit, so every other profile stays right.
std::string edited_qos(const std::string& dir, const std::string& from, const std::string& to) {
  std::ifstream in(kShippedQos);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return write(dir + "/qos.xml", text);
}

StartupCheck check(const std::string& yaml, const std::string& source) {
  return check_startup(parse_config(yaml, source));
}

TEST(StartupCheck, TheShippedQosFileHasEveryProfileTheServiceUses) {
  const auto c = check("qos_file: " + kShippedQos + "\n" + kBus, "a.yaml");
  EXPECT_TRUE(c.ok()) << (c.errors.empty() ? "" : c.errors.front());
  EXPECT_EQ(c.qos_file, kShippedQos);
}

// A hot-standby pair is fenced by its CAN heartbeat on the one bus both hosts are on: a second
// bus, or the process's own simulator, would leave a bus with two owners or one nobody else
// hears (docs/safety.md H8).
TEST(StartupCheck, ARedundancySectionNeedsOneSharedBus) {
  const std::string section = "redundancy:\n  priority: 2\n  peer: mc-b\n  name: mc-a\n";
  const std::string can0 = "buses:\n  - name: can0\n    interface: can0\n    discover: true\n";
  const std::string two = can0 + "  - name: can1\n    interface: can1\n    discover: true\n";
  struct Case {
    std::string config;
    std::string error;  // empty: accepted
  };
  const Case cases[] = {
      {"qos_file: " + kShippedQos + "\n" + section + can0, ""},
      {"qos_file: " + kShippedQos + "\n" + section + kBus,
       "/etc/pmu-dds/pmu-service.yaml:2: redundancy: bus sim is the built-in simulator (interface sim), which only "
       "this process hears: a pair needs a CAN bus both hosts are on (socketcan:IFACE)"},
      {"qos_file: " + kShippedQos + "\n" + section + two,
       "/etc/pmu-dds/pmu-service.yaml:2: redundancy: a hot-standby pair shares one CAN bus; this config has 2 buses"},
      {"qos_file: " + kShippedQos + "\nredundancy:\n  priority: 2\n  peer: mc-b\n  name: mc-b\n" + can0,
       "/etc/pmu-dds/pmu-service.yaml:2: redundancy: name mc-b is the peer's name too: each instance of a pair needs "
       "its own"},
  };
  for (const auto& c : cases) {
    const auto r = check(c.config, "/etc/pmu-dds/pmu-service.yaml");
    if (c.error.empty()) {
      EXPECT_TRUE(r.errors.empty()) << c.config << (r.errors.empty() ? "" : r.errors[0]);
    } else {
      ASSERT_EQ(r.errors.size(), 1u) << c.config;
      EXPECT_EQ(r.errors[0], c.error);
    }
  }
}

TEST(StartupCheck, MissingQosFileIsNamedAtTheConfigLine) {
  const auto c = check(std::string(kBus) + "qos_file: /nonexistent/qos.xml\n", "/etc/pmu-dds/pmu-service.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(
      c.errors[0],
      "/etc/pmu-dds/pmu-service.yaml:4: qos_file: /nonexistent/qos.xml: cannot be read: No such file or directory");
}

TEST(StartupCheck, QosFileThatIsADirectory) {
  const std::string dir = scratch("dir");
  const auto c = check("qos_file: " + dir + "\n" + kBus, "a.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(c.errors[0], "a.yaml:1: qos_file: " + dir + ": cannot be read: it is a directory, not a regular file");
}

// A device or FIFO named as the QoS file is refused, never handed to Fast DDS or tinyxml2 to
// read without end or wait on (docs/safety.md H12).
TEST(StartupCheck, QosFileThatIsADeviceOrAFifo) {
  const std::string fifo = scratch("fifo") + "/qos.xml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::pair<std::string, std::string> cases[] = {
      {"/dev/zero", "a.yaml:1: qos_file: /dev/zero: cannot be read: it is a character device, not a regular file"},
      {fifo, "a.yaml:1: qos_file: " + fifo + ": cannot be read: it is a FIFO, not a regular file"},
  };
  for (const auto& [path, error] : cases) {
    SCOPED_TRACE(path);
    const auto c = check("qos_file: " + path + "\n" + kBus, "a.yaml");
    ASSERT_EQ(c.errors.size(), 1u);
    EXPECT_EQ(c.errors[0], error);
  }
  ::unlink(fifo.c_str());
}

TEST(StartupCheck, MalformedQosFileIsNamedAtItsOwnLine) {
  const std::string dir = scratch("malformed");
  const std::string qos = write(dir + "/qos.xml",
                                "<dds>\n  <profiles>\n    <data_writer profile_name=\"telemetry\">\n"
                                "  </profiles>\n</dds>\n");
  const auto c = check("qos_file: qos.xml\n" + std::string(kBus), dir + "/pmu-service.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  // tinyxml2 names the element left open, at its line.
  EXPECT_EQ(c.errors[0].rfind(dir + "/pmu-service.yaml:1: qos_file: " + qos + ":3: not well-formed XML: ", 0), 0u)
      << c.errors[0];
  EXPECT_NE(c.errors[0].find("data_writer"), std::string::npos) << c.errors[0];
}

TEST(StartupCheck, AMissingProfileIsNamed) {
  const std::string dir = scratch("profile");
  const std::string qos =
      edited_qos(dir, "<data_reader profile_name=\"command\">", "<data_reader profile_name=\"commands\">");
  const auto c = check("qos_file: " + qos + "\n" + kBus, "a.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(c.errors[0], "a.yaml:1: qos_file: " + qos +
                             ": no <data_reader profile_name=\"command\">, needed for the pmu/command reader");
}

// Only one of a hot-standby pair writes and reads pmu/role: a service alone starts with a QoS
// file made before the profile existed, an instance of a pair is told what it lacks.
TEST(StartupCheck, TheRoleProfileIsNeededByAnInstanceOfAPairOnly) {
  const std::string dir = scratch("role");
  const std::string qos =
      edited_qos(dir, "<data_reader profile_name=\"role\">", "<data_reader profile_name=\"roles\">");
  EXPECT_TRUE(check("qos_file: " + qos + "\n" + kBus, "a.yaml").ok());
  const auto c = check("qos_file: " + qos + "\nredundancy:\n  priority: 2\n  peer: mc-b\n" + kBus, "a.yaml");
  const std::string lacks =
      "a.yaml:1: qos_file: " + qos + ": no <data_reader profile_name=\"role\">, needed for the pmu/role reader";
  EXPECT_NE(std::find(c.errors.begin(), c.errors.end(), lacks), c.errors.end())
      << (c.errors.empty() ? "" : c.errors.front());
}

TEST(StartupCheck, AProfileShortOfTheCapacityIsNamedAtItsLine) {
  const std::string dir = scratch("capacity");
  const std::string qos = edited_qos(dir, "<max_instances>256</max_instances>", "<max_instances>10</max_instances>");
  const auto c = check("qos_file: " + qos + "\n" + kBus, "a.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(c.errors[0], "a.yaml:1: qos_file: " + qos +
                             ":29: <data_writer profile_name=\"telemetry\"> (the telemetry topics' writers): "
                             "max_instances 10 < 256 (PMUs per service, pmu::dds::kMaxDevicesPerService): raise "
                             "its <resourceLimitsQos> (deploy/qos.xml says how each number is derived)");
}

// After the shipped file is loaded, a file that lacks a profile or holds one short of the
// capacity is still named for it: the registry's profiles of the same names are not its own.
TEST(StartupCheck, AFileIsJudgedByItsOwnProfilesAfterAnotherWasLoaded) {
  ASSERT_TRUE(check("qos_file: " + kShippedQos + "\n" + kBus, "a.yaml").ok());
  const std::string dir = scratch("after-another");
  const std::string missing =
      edited_qos(dir, "<data_reader profile_name=\"command\">", "<data_reader profile_name=\"commands\">");
  auto c = check("qos_file: " + missing + "\n" + kBus, "a.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_NE(c.errors[0].find(": no <data_reader profile_name=\"command\">"), std::string::npos) << c.errors[0];
  const std::string short_one =
      edited_qos(dir, "<max_instances>256</max_instances>", "<max_instances>10</max_instances>");
  c = check("qos_file: " + short_one + "\n" + kBus, "a.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_NE(c.errors[0].find("max_instances 10 < 256"), std::string::npos) << c.errors[0];
}

TEST(StartupCheck, PmuQosFileIsNamedWhenItIsTheOneUsed) {
  ::setenv("PMU_QOS_FILE", "/nonexistent/env-qos.xml", 1);
  const auto c = check(kBus, "a.yaml");
  ::unsetenv("PMU_QOS_FILE");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(c.errors[0], "$PMU_QOS_FILE: /nonexistent/env-qos.xml: cannot be read: No such file or directory");
}

TEST(StartupCheck, NoQosFileAnywhere) {
  ::unsetenv("PMU_QOS_FILE");
  if (!dds::default_qos_file().empty()) GTEST_SKIP() << "this machine has an installed qos.xml";
  const auto c = check(kBus, "a.yaml");
  ASSERT_EQ(c.errors.size(), 1u);
  EXPECT_EQ(c.errors[0].rfind("a.yaml:1: no QoS profile file: no qos_file here, $PMU_QOS_FILE unset, and neither ", 0),
            0u)
      << c.errors[0];
}

// The program: --check-config and the start say the same about the same file, because the
// start runs the check first. (The start stops before any bus or participant is opened.)
TEST(StartupCheck, CheckConfigAndTheStartRefuseTheSameQosFileTheSameWay) {
  const std::string dir = scratch("program");
  const std::string cfg =
      write(dir + "/pmu-service.yaml", "domain: 170\nqos_file: /nonexistent/qos.xml\n" + std::string(kBus));
  const std::string expected = cfg + ":2: qos_file: /nonexistent/qos.xml: cannot be read: No such file or directory";
  for (const std::string extra : {" --check-config", ""}) {
    SCOPED_TRACE(extra);
    const auto r = pmu::test::run_capture("timeout 30 " PMU_SERVICE_PATH " --config " + cfg + extra + " 2>&1");
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("ready"), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace pmu::service
