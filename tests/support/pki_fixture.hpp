#pragma once
// The PKI of one security test process: deploy/security/make_pki.sh run into a temporary
// folder once (removed at exit; PMU_KEEP_TEST_PKI=1 keeps it), plus the bad variants of
// tests/security/make_variants.sh on first use. Each test runs in its own process
// (gtest_discover_tests), so each test has its own PKI and DDS domain.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <ctime>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pmu/security/security_files.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"

namespace pmu::security_test {

using dds::SecurityFiles;

// stdout and stderr of a shell command, and its exit status.
inline pmu::test::RunResult sh(const std::string& cmd) { return pmu::test::run_capture(cmd, true); }

inline std::string utc(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d%H%M%SZ", &tm);
  return buf;
}

// The PKI of this test process: made once, removed at exit.
class Pki {
 public:
  static Pki& get() {
    static Pki pki;
    return pki;
  }
  const std::string& dir() const { return dir_; }    // make_pki.sh's output
  const std::string& root() const { return root_; }  // the temporary folder around it
  SecurityFiles files(const std::string& identity) const { return dds::security_files_in(dir_, identity); }

  // A variant of make_variants.sh (foreign, selfsigned, window START END), made on first use.
  std::string variant(const std::string& name, const std::string& args) {
    const std::string out = root_ + "/" + name;
    if (made_.insert(name).second) {
      const auto r = sh(std::string("bash ") + PMU_SOURCE_DIR + "/tests/security/make_variants.sh " + args + " " +
                        dir_ + " " + out + extra_.at(name));
      if (r.status != 0) ADD_FAILURE() << "make_variants.sh " << args << ": " << r.out;
    }
    return out;
  }
  std::string window(const std::string& name, std::chrono::system_clock::time_point from,
                     std::chrono::system_clock::time_point until) {
    extra_[name] = " " + utc(from) + " " + utc(until);
    return variant(name, "window");
  }
  std::string foreign() { return (extra_["foreign"] = "", variant("foreign", "foreign")); }
  std::string selfsigned() { return (extra_["selfsigned"] = "", variant("selfsigned", "selfsigned")); }
  std::string lax() { return (extra_["lax"] = "", variant("lax", "lax")); }
  std::string single_ca() { return (extra_["single-ca"] = "", variant("single-ca", "single-ca")); }

  // A second PKI of its own (own CAs) made by make_pki.sh with `args` on this test's domain,
  // e.g. made("fleet", "--ground-station ground-uav1=uav1"), made on first use.
  std::string made(const std::string& name, const std::string& args) {
    const std::string out = root_ + "/" + name;
    if (made_.insert(name).second) {
      const auto r = sh(std::string("bash ") + PMU_SOURCE_DIR + "/deploy/security/make_pki.sh " + out + " --domain " +
                        std::to_string(pmu::test::exclusive_dds_domain()) + " " + args);
      if (r.status != 0) ADD_FAILURE() << "make_pki.sh " << args << ": " << r.out;
    }
    return out;
  }

  ~Pki() {
    if (!root_.empty() && !std::getenv("PMU_KEEP_TEST_PKI")) sh("rm -rf '" + root_ + "'");
  }

 private:
  Pki() {
    char tmpl[] = "/tmp/pmu-security-test-XXXXXX";
    if (!::mkdtemp(tmpl)) throw std::runtime_error("mkdtemp failed");
    root_ = tmpl;
    dir_ = root_ + "/pki";
    const auto r = sh(std::string("bash ") + PMU_SOURCE_DIR + "/deploy/security/make_pki.sh " + dir_ + " --domain " +
                      std::to_string(pmu::test::exclusive_dds_domain()));
    if (r.status != 0) throw std::runtime_error("make_pki.sh failed: " + r.out);
  }
  std::string root_, dir_;
  std::set<std::string> made_;
  std::map<std::string, std::string> extra_;
};

// A pmu-service config: the built-in simulated PMU on this test's domain, with `f`; `extra`
// goes into the security section, `vehicle` is the config's `vehicle` (none when empty).
inline std::string write_config(const std::string& name, const SecurityFiles& f, const std::string& extra = "",
                                const std::string& vehicle = "") {
  const std::string path = Pki::get().root() + "/" + name + ".yaml";
  std::ofstream out(path);
  out << "domain: " << pmu::test::exclusive_dds_domain() << "\n"
      << (vehicle.empty() ? "" : "vehicle: " + vehicle + "\n")
      << "buses:\n  - interface: sim\n    name: sim0\n    devices:\n"
      << "      - address: 1\n        period: 0.5\nsecurity:\n"
      << "  identity_ca: " << f.identity_ca << "\n  identity_certificate: " << f.identity_certificate
      << "\n  private_key: " << f.private_key << "\n  permissions_ca: " << f.permissions_ca
      << "\n  governance: " << f.governance << "\n  permissions: " << f.permissions << "\n"
      << extra;
  return path;
}

// The contract's topics (interface.md sections 1.2, 1.4, 1.5, 1.6, 1.7, 1.8 and 1.9).
inline const std::set<std::string> kTelemetryAndState = {"pmu/voltages",
                                                         "pmu/currents",
                                                         "pmu/battery_energy",
                                                         "pmu/temperatures",
                                                         "pmu/status",
                                                         "pmu/low_rate/voltages",
                                                         "pmu/low_rate/currents",
                                                         "pmu/low_rate/battery_energy",
                                                         "pmu/low_rate/temperatures",
                                                         "pmu/low_rate/status",
                                                         "pmu/battery",
                                                         "pmu/battery_cells",
                                                         "pmu/mppt",
                                                         "pmu/config",
                                                         "pmu/info",
                                                         "pmu/health",
                                                         "pmu/low_rate/health",
                                                         "pmu/alarms",
                                                         "pmu/readiness",
                                                         "pmu/energy",
                                                         "pmu/baseline",
                                                         "pmu/bms_energy"};
inline const char* const kContractTopics[] = {"pmu/voltages",
                                              "pmu/currents",
                                              "pmu/battery_energy",
                                              "pmu/temperatures",
                                              "pmu/status",
                                              "pmu/low_rate/voltages",
                                              "pmu/low_rate/currents",
                                              "pmu/low_rate/battery_energy",
                                              "pmu/low_rate/temperatures",
                                              "pmu/low_rate/status",
                                              "pmu/battery",
                                              "pmu/battery_cells",
                                              "pmu/mppt",
                                              "pmu/config",
                                              "pmu/info",
                                              "pmu/health",
                                              "pmu/low_rate/health",
                                              "pmu/alarms",
                                              "pmu/readiness",
                                              "pmu/energy",
                                              "pmu/baseline",
                                              "pmu/bms_energy",
                                              "pmu/command",
                                              "pmu/command_reply",
                                              "pmu/alarm_ack",
                                              "pmu/alarm_ack_reply",
                                              "pmu/role",
                                              "pmu/role_move",
                                              "pmu/role_move_reply"};

// Only the ground station commands, acknowledges alarms and moves a hot-standby pair's role; the
// service publishes telemetry, state, replies and its role, and reads its peer's role; the
// mission computer only reads telemetry, state and the pair's roles.
inline bool allowed(const std::string& identity, const std::string& topic, bool publish) {
  const bool data = kTelemetryAndState.count(topic) > 0;
  const bool role = topic == "pmu/role";
  const bool request = topic == "pmu/command" || topic == "pmu/alarm_ack" || topic == "pmu/role_move";
  const bool reply = topic == "pmu/command_reply" || topic == "pmu/alarm_ack_reply" || topic == "pmu/role_move_reply";
  if (identity == "pmu-service") return publish ? data || reply || role : request || role;
  if (identity == "ground-station") return publish ? request : data || reply || role;
  if (identity == "mission-computer") return !publish && (data || role);
  return false;
}

}  // namespace pmu::security_test
