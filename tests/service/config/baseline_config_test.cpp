// A device's `baseline:` in the service's config (interface.md 4.1): the file is read with the
// config, relative to the config's folder; a missing, unreadable or refused one stops the
// start at the config's line, quoting the baseline's own FILE:LINE.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "pmu/config/config.hpp"

#include "support/temp_dir.hpp"

namespace pmu::service::baseline_config_test {
namespace {

const char* const kBaseline = R"(device:
  serial: 1001
  min_firmware: "1.14"
parameters:
  avionics_voltage: 22.0
  upper_temperature_limit: 80
outputs: [avionics_servo, payload]
generation_enabled: true
)";

std::string config_with(const std::string& device_keys) {
  return "buses:\n  - interface: can0\n    devices:\n      - address: 1\n" + device_keys;
}

std::string refusal(const std::string& text, const std::string& source) {
  try {
    (void)parse_config(text, source);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(BaselineConfig, ARelativePathIsReadFromTheConfigsFolder) {
  pmu::test::TempDir dir{"pmu-baseline"};
  dir.write("pmu1.yaml", kBaseline);
  const std::string source = dir.path() + "/pmu-service.yaml";
  const Config c = parse_config(config_with("        baseline: pmu1.yaml\n"), source);
  const DeviceConfig& d = c.buses.at(0).devices.at(0);
  ASSERT_TRUE(d.baseline.has_value());
  EXPECT_EQ(d.baseline_file, "pmu1.yaml") << "as configured: pmu/baseline carries it";
  EXPECT_EQ(d.baseline_path, dir.path() + "/pmu1.yaml");
  EXPECT_EQ(d.baseline->header.serial, std::optional<std::uint16_t>(1001));
  EXPECT_EQ(d.baseline->header.min_firmware, std::optional<codec::FirmwareVersion>(codec::FirmwareVersion{1, 14}));
  EXPECT_EQ(d.baseline->settings[baseline::Setting::AvionicsVoltage], std::optional<std::uint32_t>(220));
  EXPECT_EQ(d.baseline->settings[baseline::Setting::Outputs], std::optional<std::uint32_t>(0x03));
  EXPECT_FALSE(d.baseline->settings[baseline::Setting::PayloadVoltage].has_value()) << "not in the file";
}

TEST(BaselineConfig, AnAbsolutePathIsTakenAsItIs) {
  pmu::test::TempDir dir{"pmu-baseline"};
  const std::string file = dir.write("pmu1.yaml", kBaseline);
  const Config c = parse_config(config_with("        baseline: " + file + "\n"), "/elsewhere/pmu-service.yaml");
  EXPECT_EQ(c.buses.at(0).devices.at(0).baseline_path, file);
  EXPECT_TRUE(c.buses.at(0).devices.at(0).baseline.has_value());
}

TEST(BaselineConfig, NoBaselineUnlessConfigured) {
  const Config c = parse_config(config_with("") + "    discover: true\n", "a.yaml");
  EXPECT_FALSE(c.buses.at(0).devices.at(0).baseline.has_value());
  EXPECT_FALSE(c.buses.at(0).discovered_defaults.baseline.has_value());
  // A found unit is not a configured one: it has no file to be compared with.
  EXPECT_NE(refusal("buses:\n  - interface: can0\n    discover:\n      baseline: x.yaml\n", "a.yaml")
                .find("a.yaml:4: unknown key 'baseline' in discover"),
            std::string::npos);
}

// Each refusal names the config's line and, for a file that reads but is wrong, quotes the
// baseline's own FILE:LINE, so the operator knows which of the two files to open.
TEST(BaselineConfig, AFileThatCannotServeIsRefusedAtTheConfigsLine) {
  pmu::test::TempDir dir{"pmu-baseline"};
  const std::string source = dir.path() + "/pmu-service.yaml";
  dir.write("bad.yaml", "parameters:\n  avionics_voltage: 22.0\n  payload_voltage: 99\n");
  dir.write("s0.yaml", "parameters:\n  power_up_state: [avionics_servo, soa_management]\n");
  dir.write("pinned.yaml", "device:\n  min_firmware: \"1.12\"\nparameters:\n  power_up_state: [soa_management]\n");
  dir.write("empty.yaml", "");
  const std::string p = dir.path() + "/";
  struct Case {
    const char* what;
    std::string device_keys;
    std::string message;  // the start of the refusal
  };
  const Case cases[] = {
      {"missing", "        baseline: none.yaml\n",
       source + ":5: baseline " + p + "none.yaml cannot be read: No such file or directory"},
      {"a folder", "        baseline: .\n", source + ":5: baseline " + p + ". cannot be read: it is a directory"},
      {"a value out of range", "        baseline: bad.yaml\n",
       source + ":5: baseline refused: " + p +
           "bad.yaml:3: value 99.0 V out of range 12.0..24.0 V for payload_voltage"},
      {"an empty file", "        baseline: empty.yaml\n",
       source + ":5: baseline refused: " + p + "empty.yaml:1: the file is empty"},
      {"a bit the configured minimum firmware lacks", "        min_firmware: \"1.12\"\n        baseline: s0.yaml\n",
       source + ":6: baseline refused: " + p + "s0.yaml:2: "},
      {"a bit its own min_firmware pin lacks", "        baseline: pinned.yaml\n",
       source + ":5: baseline refused: " + p + "pinned.yaml:4: "},
      {"not a path", "        baseline: [a, b]\n",
       source + ":5: baseline must be the path of a PMU configuration file"},
      {"too long", "        baseline: " + std::string(256, 'x') + "\n",
       source + ":5: baseline: the path is 256 bytes long; at most 255"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string got = refusal(config_with(c.device_keys), source);
    EXPECT_EQ(got.substr(0, c.message.size()), c.message) << got;
  }
}

// What is not a regular file within 64 KiB is refused at the config's line without being
// read (docs/safety.md H12): /dev/zero would exhaust memory, a FIFO block the start.
TEST(BaselineConfig, ADeviceAFifoOrAHugeFileIsRefusedNotRead) {
  pmu::test::TempDir dir{"pmu-baseline"};
  const std::string source = dir.path() + "/pmu-service.yaml";
  const std::string fifo = dir.path() + "/pmu1.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string huge = dir.write("huge.yaml", "# " + std::string(64 * 1024, 'x') + "\noutputs: []\n");
  const std::pair<std::string, std::string> cases[] = {
      {"/dev/zero", source + ":5: baseline /dev/zero cannot be read: it is a character device, not a regular file"},
      {fifo, source + ":5: baseline " + fifo + " cannot be read: it is a FIFO, not a regular file"},
      {huge, source + ":5: baseline " + huge + " cannot be read: it is 65551 bytes, larger than the 64 KiB bound"},
  };
  for (const auto& [path, message] : cases) {
    SCOPED_TRACE(path);
    EXPECT_EQ(refusal(config_with("        baseline: " + path + "\n"), source), message);
  }
  ::unlink(fifo.c_str());
}

TEST(BaselineConfig, AnUnreadableFileSaysWhy) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads a file of mode 000: no EACCES to see";
  pmu::test::TempDir dir{"pmu-baseline"};
  const std::string file = dir.write("locked.yaml", kBaseline);
  ASSERT_EQ(::chmod(file.c_str(), 0), 0);
  EXPECT_EQ(refusal(config_with("        baseline: locked.yaml\n"), dir.path() + "/c.yaml"),
            dir.path() + "/c.yaml:5: baseline " + file + " cannot be read: Permission denied");
}

}  // namespace
}  // namespace pmu::service::baseline_config_test
