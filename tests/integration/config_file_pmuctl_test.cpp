// A PMU's configuration as a file, as an operator uses it (docs/interface.md 3.2, 4.6):
// pmuctl config snapshot, diff and apply against pmu-service on the built-in simulator, with
// one simulated PMU for each firmware the documents describe.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

// A namespace of its own: the unity builds put this file in one translation unit with the
// other integration tests, whose helpers have the same names.
namespace config_file_pmuctl_test {
namespace {

using Json = nlohmann::json;

// Addresses 12..17 play firmware 1.12..1.17; address 20 is a unit whose memory does not take
// cranking_time.
std::string config(const std::string& domain) {
  std::string c = "domain: " + domain + "\nqos_file: " PMU_QOS_FILE "\nbuses:\n  - interface: sim\n    devices:\n";
  for (int minor = 12; minor <= 17; ++minor)
    c += "      - address: " + std::to_string(minor) + "\n        period: 0.5\n        sim: {firmware: \"1." +
         std::to_string(minor) + "\"}\n";
  c += "      - address: 20\n        period: 0.5\n        sim: {ignores_set: cranking_time}\n";
  return c;
}

class Files {
 public:
  Files() {
    char tmpl[] = "/tmp/pmu-config-file-XXXXXX";
    dir_ = ::mkdtemp(tmpl);
  }
  ~Files() { pmu::test::run_capture("rm -rf '" + dir_ + "'"); }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  static std::string read(const std::string& p) {
    std::ostringstream s;
    s << std::ifstream(p).rdbuf();
    return s.str();
  }

 private:
  std::string dir_;
};

// A FIFO a child writes its stderr to, kept full until the test reads it: the child's first
// line on stderr stops it right there. pmuctl's apply writes its first line once its first
// change is made, under its hold, so a test can act while an apply holds a PMU mid-way.
class StderrGate {
 public:
  explicit StderrGate(const std::string& path) : path_(path) {
    if (::mkfifo(path.c_str(), 0600) != 0) throw std::runtime_error("mkfifo " + path);
    read_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    const int w = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (read_ < 0 || w < 0) throw std::runtime_error("open " + path);
    const std::string page(4096, '.');
    for (ssize_t n; (n = ::write(w, page.data(), page.size())) > 0;) filler_ += static_cast<std::size_t>(n);
    for (ssize_t n; (n = ::write(w, ".", 1)) > 0;) filler_ += static_cast<std::size_t>(n);
    ::close(w);
  }
  ~StderrGate() { ::close(read_); }
  StderrGate(const StderrGate&) = delete;
  StderrGate& operator=(const StderrGate&) = delete;

  const std::string& path() const { return path_; }
  // Takes what is in the FIFO without waiting; the child goes on once there is room.
  void drain() {
    char buf[4096];
    for (ssize_t n; (n = ::read(read_, buf, sizeof buf)) > 0;) {
      std::size_t skip = std::min(filler_, static_cast<std::size_t>(n));
      filler_ -= skip;
      text_.append(buf + skip, static_cast<std::size_t>(n) - skip);
    }
  }
  const std::string& text() const { return text_; }

 private:
  std::string path_;
  int read_ = -1;
  std::size_t filler_ = 0;
  std::string text_;
};

// Each pmuctl call is a process of its own that discovers the service before it reads or
// sends anything. These tests check what the config verbs say and do, not how soon a new
// participant discovers the service, which under a sanitizer on a loaded host can take longer
// than pmuctl's interactive default of 5 s: so every call here states its deadline.
constexpr const char* kCallDeadline = "--timeout 30 ";

// Lets `child` (stopped on `gate`) go on to its end; its exit status, -1 when it did not exit.
int run_to_end(pmu::test::Child& child, StderrGate& gate) {
  const bool ended = pmu::test::wait_until(
      [&] {
        gate.drain();
        return !child.running();
      },
      std::chrono::seconds(120));
  gate.drain();
  if (!ended || !child.status() || !WIFEXITED(*child.status())) return -1;
  return WEXITSTATUS(*child.status());
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A file that changes every one of the thirteen settings from the simulator's factory
// values, to values the firmware has (S0's newer bits only where it has them).
std::string every_setting_changed(int minor, int new_address) {
  std::string s0 = "[avionics_servo, payload";
  if (minor >= 15) s0 += ", battery_disconnect_detect";
  if (minor >= 16) s0 += ", soa_management";
  s0 += "]";
  return "parameters:\n"
         "  avionics_voltage: 22.0\n"
         "  payload_voltage: 13.5\n"
         "  servo_voltage: 7.5\n"
         "  battery_voltage: 24.0\n"
         "  packet_period: 0.4\n"
         "  packets_streamed: [voltages, currents, temperatures, status]\n"
         "  temperature_offset: 100\n"
         "  upper_temperature_limit: 90\n"
         "  power_up_state: " +
         s0 +
         "\n"
         "  cranking_time: 3.5\n"
         "  can_address: " +
         std::to_string(new_address) +
         "\n"
         "outputs: [avionics_servo, charger_a]\n"
         "generation_enabled: false\n";
}

TEST(ConfigFilesOverDds, SnapshotApplyAndBackOnEveryFirmware) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim ";
  Files files;
  for (int minor = 17; minor >= 12; --minor) {
    SCOPED_TRACE("firmware 1." + std::to_string(minor));
    const bool first = minor == 17;  // what does not depend on the firmware, once
    const std::string at = "--address " + std::to_string(minor) + " ";
    const std::string factory = files.path("factory-" + std::to_string(minor) + ".yaml");
    const auto snap = pmu::test::run_capture(p + "--timeout 30 " + at + "config snapshot " + factory + " 2>&1");
    ASSERT_EQ(snap.status, 0) << snap.out << service.describe();
    const std::string text = Files::read(factory);
    EXPECT_NE(text.find("firmware: \"1." + std::to_string(minor) + "\""), std::string::npos) << text;
    EXPECT_NE(text.find("serial: " + std::to_string(1000 + minor)), std::string::npos) << text;

    const int moved = minor + 100;
    const std::string changed =
        files.write("changed-" + std::to_string(minor) + ".yaml", every_setting_changed(minor, moved));
    if (first) {
      // A second snapshot to the same file is refused and leaves it as it was.
      const auto again = pmu::test::run_capture(p + at + "config snapshot " + factory + " 2>&1");
      EXPECT_EQ(again.status, 2) << again.out;
      EXPECT_EQ(Files::read(factory), text);
      const auto before = pmu::test::run_capture(p + at + "--json config diff " + changed);
      EXPECT_EQ(before.status, 1) << before.out;
      const auto d = Json::parse(before.out);
      EXPECT_EQ(d["differences"].size(), 13u) << before.out;
      EXPECT_EQ(d["equal"], false);
      // can_address needs --confirm: without it the file is refused whole and nothing is sent.
      const auto audits = count_of(service.describe(), "audit: command");
      const auto unconfirmed = pmu::test::run_capture(p + at + "config apply " + changed + " 2>&1");
      EXPECT_EQ(unconfirmed.status, 2) << unconfirmed.out;
      EXPECT_NE(unconfirmed.out.find(changed + ":12: can_address"), std::string::npos) << unconfirmed.out;
      EXPECT_NE(unconfirmed.out.find("rule set_can_address"), std::string::npos) << unconfirmed.out;
      EXPECT_EQ(count_of(service.describe(), "audit: command"), audits) << "a command was sent";
    }

    const auto apply = pmu::test::run_capture(p + at + "--confirm config apply " + changed + " 2>&1");
    ASSERT_EQ(apply.status, 0) << apply.out << service.describe();
    EXPECT_EQ(count_of(apply.out, ": COMPLETED"), 13u) << apply.out;
    // The address last (section 4.6).
    const auto moved_at = apply.out.find("can_address " + std::to_string(minor) + " -> ");
    const auto streamed_at = apply.out.find("packets_streamed ");
    ASSERT_NE(moved_at, std::string::npos) << apply.out;
    ASSERT_NE(streamed_at, std::string::npos) << apply.out;
    EXPECT_GT(moved_at, streamed_at) << apply.out;
    const std::string now = "--address " + std::to_string(moved) + " ";
    const auto there = pmu::test::run_capture(p + now + "config diff " + changed + " 2>&1");
    EXPECT_EQ(there.status, 0) << there.out;

    // Back to the snapshot, at the new address: the file's can_address moves it home.
    const auto back = pmu::test::run_capture(p + now + "--confirm config apply " + factory + " 2>&1");
    ASSERT_EQ(back.status, 0) << back.out << service.describe();
    const auto home = pmu::test::run_capture(p + at + "config diff " + factory + " 2>&1");
    EXPECT_EQ(home.status, 0) << home.out;
  }
}

// A set the unit does not take, in the middle of a file: the change fails on its read-back,
// the changes before it are restored (each verified), the exit status is 1 and the device is
// as it was.
TEST(ConfigFilesOverDds, AFailedChangeRestoresWhatWasApplied) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim --address 20 ";
  Files files;
  const std::string factory = files.path("factory.yaml");
  ASSERT_EQ(pmu::test::run_capture(p + "--timeout 30 config snapshot " + factory).status, 0) << service.describe();
  // Applied in the order temperature_offset, cranking_time (fails), avionics_voltage.
  const std::string file = files.write("bad-memory.yaml",
                                       "parameters:\n  avionics_voltage: 22.0\n  cranking_time: 3.5\n"
                                       "  temperature_offset: 100\n");
  const auto r = pmu::test::run_capture(p + kCallDeadline + "--json config apply " + file + " 2>&1");
  EXPECT_EQ(r.status, 1) << r.out << service.describe();
  EXPECT_NE(r.out.find("temperature_offset 128 -> 100: COMPLETED"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cranking_time 5.0 s -> 3.5 s: FAILED"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("restored temperature_offset to 128: COMPLETED"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("avionics_voltage 12.0 V -> 22.0 V"), std::string::npos) << "sent after the failure";
  EXPECT_NE(r.out.find("1 of 1 applied change(s) restored"), std::string::npos) << r.out;
  std::smatch json;
  const std::string out = r.out;
  ASSERT_TRUE(std::regex_search(out, json, std::regex(R"(\{"address".*\})"))) << r.out;
  const auto j = Json::parse(json.str());
  EXPECT_EQ(j["applied"], false);
  EXPECT_EQ(j["restored"].size(), 1u);
  EXPECT_EQ(j["exit_status"], 1);
  EXPECT_EQ(pmu::test::run_capture(p + kCallDeadline + "config diff " + factory).status, 0)
      << "the device is as it was";
}

// Two applies at once (docs/safety.md H11): the first holds the PMU from its first command to
// its last. The second, run while the first is stopped mid-way with a change made, is refused
// with the holder named and changes nothing; the first goes on to its end, and the PMU holds
// exactly the first file's values.
TEST(ConfigFilesOverDds, TwoAppliesAtOnceTheSecondIsRefusedNamingTheHolder) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim --address 17 ";
  Files files;
  ASSERT_EQ(pmu::test::run_capture(p + "--timeout 30 config get can_address").status, 0) << service.describe();
  const std::string first = files.write(
      "first.yaml", "parameters:\n  avionics_voltage: 22.0\n  payload_voltage: 13.5\n  cranking_time: 3.5\n");
  const std::string second = files.write(
      "second.yaml", "parameters:\n  avionics_voltage: 20.0\n  payload_voltage: 15.0\n  cranking_time: 4.0\n");

  StderrGate gate(files.path("first.stderr"));
  pmu::test::ChildOptions stopped;
  stopped.stderr_path = gate.path();
  stopped.stdout_path = files.path("first.stdout");
  pmu::test::Child a(
      {PMUCTL_PATH, "--domain", domain, "--bus", "sim", "--address", "17", "--timeout", "60", "config", "apply", first},
      stopped);
  // Its first change (cranking_time, section 4.6's order) is made; it stops at its line.
  const std::regex changed(R"(set_parameter cranking_time=3.5 to sim/17[^\n]* -> COMPLETED)");
  ASSERT_TRUE(
      pmu::test::wait_until([&] { return std::regex_search(service.describe(), changed); }, std::chrono::seconds(60)))
      << service.describe();

  const auto b = pmu::test::run_capture(p + "--timeout 20 config apply " + second + " 2>&1");
  EXPECT_EQ(b.status, 1) << b.out;
  EXPECT_NE(b.out.find(second + " not applied: reading "), std::string::npos) << b.out;
  EXPECT_NE(b.out.find("DENIED: configuration of sim/17 held by an apply from "), std::string::npos) << b.out;
  // The holder's request id, pmuctl-HOST-PID-NANOSECONDS#N: the first apply's process.
  EXPECT_TRUE(std::regex_search(b.out, std::regex("\\(request id pmuctl-[^ ]*-" + std::to_string(a.pid()) +
                                                  "-[0-9]+#1\\) for another [0-9.]+ s")))
      << b.out;
  EXPECT_NE(b.out.find("; nothing was changed"), std::string::npos) << b.out;
  EXPECT_EQ(b.out.find("-> 20.0 V"), std::string::npos) << "the second apply changed something";

  EXPECT_EQ(run_to_end(a, gate), 0) << gate.text() << service.describe();
  EXPECT_NE(gate.text().find("3 change(s) applied; it matches " + first), std::string::npos) << gate.text();
  EXPECT_EQ(pmu::test::run_capture(p + kCallDeadline + "config diff " + first).status, 0)
      << "exactly the first file's values";
  EXPECT_EQ(pmu::test::run_capture(p + kCallDeadline + "config diff " + second).status, 1);
}

// A restore puts back only what the apply changed (docs/safety.md H11): a setting another
// writer changed after the apply did (here once the hold of an apply stopped mid-way ran out
// by itself) keeps that writer's value, reported and not counted as restored.
TEST(ConfigFilesOverDds, ARestoreLeavesWhatAnotherWriterChangedMeanwhile) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim --address 20 ";
  Files files;
  ASSERT_EQ(pmu::test::run_capture(p + "--timeout 30 config get can_address").status, 0) << service.describe();
  // Applied in the order temperature_offset, cranking_time (this unit does not take it).
  const std::string file =
      files.write("bad-memory.yaml", "parameters:\n  cranking_time: 3.5\n  temperature_offset: 100\n");
  StderrGate gate(files.path("apply.stderr"));
  pmu::test::ChildOptions stopped;
  stopped.stderr_path = gate.path();
  stopped.stdout_path = files.path("apply.stdout");
  pmu::test::Child a(
      {PMUCTL_PATH, "--domain", domain, "--bus", "sim", "--address", "20", "--timeout", "10", "config", "apply", file},
      stopped);
  const std::regex changed(R"(set_parameter temperature_offset=100 to sim/20[^\n]* -> COMPLETED)");
  ASSERT_TRUE(
      pmu::test::wait_until([&] { return std::regex_search(service.describe(), changed); }, std::chrono::seconds(60)))
      << service.describe();
  // The hold ends 10 s after the apply's latest command; until then the set is DENIED.
  ASSERT_TRUE(pmu::test::wait_until(
      [&] { return pmu::test::run_capture(p + kCallDeadline + "config set temperature_offset 90").status == 0; },
      std::chrono::seconds(60), std::chrono::milliseconds(200)))
      << service.describe();

  EXPECT_EQ(run_to_end(a, gate), 1) << gate.text() << service.describe();
  const std::string& out = gate.text();
  EXPECT_NE(out.find("cranking_time 5.0 s -> 3.5 s: FAILED"), std::string::npos) << out;
  EXPECT_NE(out.find("temperature_offset NOT RESTORED: the device holds 90, not the 100 this apply set: another "
                     "writer changed it since; left as it is"),
            std::string::npos)
      << out;
  EXPECT_EQ(out.find("restored temperature_offset"), std::string::npos) << out;
  EXPECT_NE(out.find("0 of 1 applied change(s) restored; 1 changed by another writer since, left as they are"),
            std::string::npos)
      << out;
  const std::string theirs = files.write("theirs.yaml", "parameters:\n  temperature_offset: 90\n");
  EXPECT_EQ(pmu::test::run_capture(p + kCallDeadline + "config diff " + theirs).status, 0)
      << "the other writer's value stays";
}

// A bad file is exit 2 with FILE:LINE and no frame; a file for a newer firmware is refused for
// this device at the line of the bit it lacks.
TEST(ConfigFilesOverDds, BadFilesSendNothing) {
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, config(domain));
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim --address 14 ";
  Files files;
  ASSERT_EQ(pmu::test::run_capture(p + "--timeout 30 config get can_address").status, 0) << service.describe();
  struct Bad {
    std::string text;
    std::string says;
    int diff_status;  // diff reads the file alone: only the file's own faults are its
  };
  const Bad kBad[] = {
      {"parameters:\n  avionics_voltage: 30.0\n", ":2: value 30.0 V out of range 12.0..24.0 V", 2},
      {"parameters:\n  avionics_voltage: 22.0\n  cranking: 3\n", ":3: unknown parameter 'cranking'", 2},
      // For this unit's firmware: bit 6 comes with 1.16.
      {"parameters:\n  power_up_state: [avionics_servo, soa_management]\n", ":2: power_up_state", 1},
      // Avionics off: needs --confirm.
      {"outputs: [payload]\n", ":1: outputs", 1},
      {"device:\n  min_firmware: \"1.16\"\noutputs: [avionics_servo, payload, charger_a, charger_b]\n",
       ":2: sim/14 has firmware 1.14", 0},
  };
  const auto audits = count_of(service.describe(), "audit: command");
  for (const auto& b : kBad) {
    const std::string file = files.write("bad.yaml", b.text);
    const auto r = pmu::test::run_capture(p + kCallDeadline + "config apply " + file + " 2>&1");
    EXPECT_EQ(r.status, 2) << b.text << r.out;
    EXPECT_NE(r.out.find(file + b.says), std::string::npos) << b.text << r.out;
    const auto d = pmu::test::run_capture(p + kCallDeadline + "config diff " + file + " 2>&1");
    EXPECT_EQ(d.status, b.diff_status) << b.text << d.out;
  }
  EXPECT_EQ(count_of(service.describe(), "audit: command"), audits) << "a bad file sent a command";
  const auto missing = pmu::test::run_capture(p + kCallDeadline + "config diff " + files.path("none.yaml") + " 2>&1");
  EXPECT_EQ(missing.status, 2) << missing.out;
}

// Without a file, diff compares the PMU with the baseline its service watches it with
// (pmu/baseline), and says so when there is none.
TEST(ConfigFilesOverDds, DiffWithoutAFileUsesTheServicesBaseline) {
  Files files;
  const std::string settings = files.write("settings.yaml", "parameters:\n  avionics_voltage: 22.0\n");
  const std::string pinned =
      files.write("pinned.yaml", "device:\n  serial: 4242\noutputs: [avionics_servo, payload, charger_a, charger_b]\n");
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH,
                                       "domain: " + domain +
                                           "\nqos_file: " PMU_QOS_FILE
                                           "\nbuses:\n  - interface: sim\n    devices:\n"
                                           "      - address: 1\n        period: 0.5\n        baseline: " +
                                           settings +
                                           "\n"
                                           "      - address: 2\n        period: 0.5\n        baseline: " +
                                           pinned +
                                           "\n"
                                           "      - address: 3\n        period: 0.5\n");
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim ";
  // Each PMU's configuration and identity, which every diff below compares, are there once
  // the service has read it: the service reads its PMUs each on its own, so having read one
  // says nothing of the others.
  for (const char* address : {"1", "2", "3"}) {
    const auto read = pmu::test::run_capture(p + "--timeout 30 --address " + address + " config snapshot - 2>&1");
    ASSERT_EQ(read.status, 0) << "sim/" << address << ": " << read.out << service.describe();
  }
  const auto differs = pmu::test::run_capture(p + kCallDeadline + "--address 1 config diff 2>&1");
  EXPECT_EQ(differs.status, 1) << differs.out << service.describe();
  EXPECT_NE(differs.out.find(settings + ": avionics_voltage: device 12.0 V, file 22.0 V"), std::string::npos)
      << differs.out;
  EXPECT_NE(differs.out.find("differs from " + settings + " in 1 of 1 settings"), std::string::npos) << differs.out;
  const auto set = pmu::test::run_capture(p + kCallDeadline + "--address 1 config set avionics_voltage 22.0 2>&1");
  ASSERT_EQ(set.status, 0) << set.out;
  const auto equal = pmu::test::run_capture(p + kCallDeadline + "--address 1 config diff 2>&1");
  EXPECT_EQ(equal.status, 0) << equal.out;

  // Another unit than the baseline's differs, whatever its settings: never "matches".
  const auto other_unit = pmu::test::run_capture(p + kCallDeadline + "--address 2 config diff 2>&1");
  EXPECT_EQ(other_unit.status, 1) << other_unit.out;
  EXPECT_NE(other_unit.out.find(pinned + ": serial: device 1002, baseline 4242: another unit than the baseline's"),
            std::string::npos)
      << other_unit.out;
  EXPECT_NE(other_unit.out.find("sim/2 differs from " + pinned +
                                ": it is another unit (serial 1002, the baseline's "
                                "4242); its 1 settings match"),
            std::string::npos)
      << other_unit.out;
  EXPECT_EQ(other_unit.out.find("matches"), std::string::npos) << other_unit.out;
  const auto other_json = pmu::test::run_capture(p + kCallDeadline + "--address 2 --json config diff");
  ASSERT_EQ(other_json.status, 1) << other_json.out;
  // Read with at() and value(): a const json's operator[] with a key it lacks is undefined.
  const auto j = Json::parse(other_json.out, nullptr, false);
  ASSERT_TRUE(j.is_object() && j.contains("equal") && j.contains("differences")) << other_json.out;
  EXPECT_EQ(j.at("equal"), false) << other_json.out;
  ASSERT_TRUE(j.at("differences").is_array()) << other_json.out;
  ASSERT_EQ(j.at("differences").size(), 1u) << other_json.out;
  const auto& serial = j.at("differences").at(0);
  EXPECT_EQ(serial.value("name", ""), "serial") << other_json.out;
  EXPECT_EQ(serial.value("device", ""), "1002") << other_json.out;
  EXPECT_EQ(serial.value("file", ""), "4242") << other_json.out;

  const auto none = pmu::test::run_capture(p + kCallDeadline + "--address 3 config diff 2>&1");
  EXPECT_EQ(none.status, 2) << none.out;
  EXPECT_NE(none.out.find("no baseline configured for PMU sim/3"), std::string::npos) << none.out;
}

// apply judges the unit and the new address before the first frame, and its dry run refuses
// what it would: a file read from another serial needs --other-unit, and a can_address that
// another PMU of the service has is refused as the service would refuse it (interface.md 2.6).
TEST(ConfigFilesOverDds, ApplyJudgesTheUnitAndTheNewAddressBeforeSending) {
  Files files;
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  pmu::test::ConfiguredService service(PMU_SERVICE_PATH, "domain: " + domain +
                                                             "\nqos_file: " PMU_QOS_FILE
                                                             "\nbuses:\n  - interface: sim\n    devices:\n"
                                                             "      - address: 1\n        period: 0.5\n"
                                                             "      - address: 2\n        period: 0.5\n");
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + domain + " --bus sim ";
  ASSERT_EQ(pmu::test::run_capture(p + "--timeout 30 --address 2 config get can_address").status, 0)
      << service.describe();
  const std::string from_1 =
      files.write("from-1.yaml", "device:\n  serial: 1001\nparameters:\n  avionics_voltage: 22.0\n");
  const std::string to_1 = files.write("to-1.yaml", "parameters:\n  can_address: 1\n");
  const std::string to_5 = files.write("to-5.yaml", "parameters:\n  can_address: 5\n");
  struct Case {
    std::string args;
    int status;
    std::string says;
  };
  const Case refused[] = {
      {"config apply " + from_1, 2,
       from_1 + ":2: the file was read from serial 1001, and sim/2 is serial 1002: another unit; nothing was sent "
                "(--other-unit applies it to this unit)"},
      {"config apply --dry-run " + from_1, 2, from_1 + ":2: the file was read from serial 1001"},
      {"--confirm config apply " + to_1, 2,
       to_1 + ":2: can_address 1: address 1 is already in use on sim (a PMU the service serves); nothing was sent"},
      {"config apply --dry-run " + to_1, 2, to_1 + ":2: can_address 1: address 1 is already in use on sim"},
      {"config apply --dry-run " + to_5, 0, "1. " + to_5 + ":2: can_address: 2 -> 5 (needs --confirm"},
      {"config apply --dry-run --other-unit " + from_1, 0, "1. " + from_1 + ":4: avionics_voltage: 12.0 V -> 22.0 V"},
  };
  const auto audits = count_of(service.describe(), "audit: command");
  for (const auto& c : refused) {
    SCOPED_TRACE(c.args);
    const auto r = pmu::test::run_capture(p + "--timeout 10 --address 2 " + c.args + " 2>&1");
    EXPECT_EQ(r.status, c.status) << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << r.out;
  }
  EXPECT_EQ(count_of(service.describe(), "audit: command"), audits) << "a refused or dry-run apply sent a command";
  // Said so, it is applied to this unit.
  const auto applied =
      pmu::test::run_capture(p + "--timeout 10 --address 2 config apply --other-unit " + from_1 + " 2>&1");
  EXPECT_EQ(applied.status, 0) << applied.out << service.describe();
  EXPECT_NE(applied.out.find("sim/2: avionics_voltage 12.0 V -> 22.0 V: COMPLETED"), std::string::npos) << applied.out;
}

}  // namespace
}  // namespace config_file_pmuctl_test
