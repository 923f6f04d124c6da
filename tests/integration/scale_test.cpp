// 100 PMUs on one pmu-service: four built-in simulated buses of 25 units each,
// the same addresses 1..25 on every bus, so only the (bus, address) key tells them apart.
// Every unit must be listed, stream every packet to `pmuctl watch` and take commands; a
// QoS resource limit that caps instances per reader or writer (Fast DDS's default is 10)
// shows up here as units that are missing.
// Cost at scale (CPU, memory) is measured by bench/run.sh, not here.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace {

using namespace std::chrono_literals;
using Key = std::pair<std::string, int>;  // (bus, address)

constexpr int kBuses = 4;
constexpr int kPerBus = 25;
constexpr std::size_t kUnits = kBuses * kPerBus;
const std::set<std::string> kTelemetryTopics{"voltages", "currents", "battery_energy", "temperatures", "status"};

std::string bus_name(int b) { return "sim" + std::to_string(b); }

// stdout only: pmuctl's JSON lines.
pmu::test::RunResult run(const std::string& cmd) { return pmu::test::run_capture(cmd); }

using pmu::test::json_lines;

// pmu-service on a generated config, stopped with SIGTERM (a killed participant would leave
// its shared-memory ports behind for later tests to wait on).
class Service {
 public:
  explicit Service(int domain) {
    char dir[] = "/tmp/pmu-scale-XXXXXX";
    if (::mkdtemp(dir)) dir_ = dir;
    config_ = dir_ + "/pmu-service.yaml";
    std::ofstream c(config_);
    c << "domain: " << domain << "\nqos_file: " << PMU_QOS_FILE << "\nlog_level: warn\nbuses:\n";
    for (int b = 0; b < kBuses; ++b) {
      c << "  - interface: sim\n    name: " << bus_name(b) << "\n    devices:\n";
      for (int a = 1; a <= kPerBus; ++a) c << "      - address: " << a << "\n        period: 1.0\n";
    }
    c.close();
    process_ = pmu::test::Child({PMU_SERVICE_PATH, "--config", config_});
  }
  ~Service() {
    (void)stop();
    if (!config_.empty()) ::unlink(config_.c_str());
    if (!dir_.empty()) ::rmdir(dir_.c_str());
  }
  bool started() const { return process_.pid() > 0 && !dir_.empty(); }
  // SIGTERM; the exit status (non-zero also when a sanitizer reported something at exit).
  int stop() {
    const auto st = process_.stop(10s);  // std::nullopt: it had to be killed
    return st && WIFEXITED(*st) ? WEXITSTATUS(*st) : -1;
  }

 private:
  std::string dir_, config_;
  pmu::test::Child process_;
};

class Scale : public ::testing::Test {
 protected:
  void start() {
    ::setenv("PMU_QOS_FILE", PMU_QOS_FILE, 1);    // pmuctl reads the same profiles as the service
    domain_ = pmu::test::exclusive_dds_domain();  // this test process's own
    service_ = std::make_unique<Service>(domain_);
    ASSERT_TRUE(service_->started());
  }
  std::string pmuctl(const std::string& args) const {
    return std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain_) + " " + args;
  }
  // `pmuctl ... list`/`config get` return once the first samples have settled; 100 units'
  // state may take more than one such call, so this repeats until `done` or a minute
  // passes (a bound for a loaded machine, not a measurement).
  template <class Done>
  std::vector<nlohmann::json> until(const std::string& args, Done&& done) const {
    std::vector<nlohmann::json> last;
    pmu::test::wait_until(
        [&] {
          const auto r = run(pmuctl(args));
          last = json_lines(r.out);
          return r.status == 0 && done(last);
        },
        60s, 500ms);
    return last;
  }

  int domain_ = 0;
  std::unique_ptr<Service> service_;
};

std::set<Key> all_units() {
  std::set<Key> s;
  for (int b = 0; b < kBuses; ++b)
    for (int a = 1; a <= kPerBus; ++a) s.insert({bus_name(b), a});
  return s;
}

// Fields read without throwing: a unit whose info has not arrived has nulls in its row.
std::string text(const nlohmann::json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
}
double number(const nlohmann::json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>() : -1.0;
}
const nlohmann::json& values(const nlohmann::json& j) {
  static const nlohmann::json none = nlohmann::json::object();
  return j.is_object() && j.contains("values") && j["values"].is_object() ? j["values"] : none;
}
Key key_of(const nlohmann::json& j) { return {text(j, "bus"), static_cast<int>(number(j, "address"))}; }

TEST_F(Scale, EveryOneOf100UnitsOnFourBusesIsListedOnline) {
  ASSERT_NO_FATAL_FAILURE(start());
  const auto rows = until("--json --timeout 5 list", [](const std::vector<nlohmann::json>& v) {
    std::size_t online = 0;
    for (const auto& j : v) online += text(values(j), "state") == "ONLINE" ? 1u : 0u;
    return online == kUnits;
  });
  std::set<Key> listed, online;
  for (const auto& j : rows) {
    listed.insert(key_of(j));
    if (text(values(j), "state") == "ONLINE") online.insert(key_of(j));
    EXPECT_EQ(text(values(j), "firmware"), "1.17") << j.dump();
    EXPECT_EQ(number(values(j), "serial_number"), 1000 + number(j, "address")) << j.dump();
  }
  EXPECT_EQ(rows.size(), kUnits) << "one row per unit";
  EXPECT_EQ(listed, all_units());
  EXPECT_EQ(online.size(), kUnits);
  EXPECT_EQ(service_->stop(), 0) << "pmu-service stops cleanly (SIGTERM)";
}

TEST_F(Scale, WatchShowsEveryPacketOfEveryUnit) {
  ASSERT_NO_FATAL_FAILURE(start());
  // 100 units x 5 packets once a second: 10 s of watching gives each (unit, packet) about
  // ten chances; telemetry is best effort, but a unit missing from all of them is a bug.
  (void)until("--json --timeout 5 list", [](const std::vector<nlohmann::json>& v) { return v.size() == kUnits; });
  const auto r = run(pmuctl("--json --timeout 10 watch"));
  ASSERT_EQ(r.status, 0);
  std::map<Key, std::set<std::string>> topics;
  for (const auto& j : json_lines(r.out)) topics[key_of(j)].insert(text(j, "topic"));
  std::set<Key> seen;
  for (const auto& [k, t] : topics) {
    seen.insert(k);
    EXPECT_EQ(t, kTelemetryTopics) << k.first << "/" << k.second;
  }
  EXPECT_EQ(seen, all_units());
  EXPECT_EQ(service_->stop(), 0);
}

TEST_F(Scale, UnitsOnEveryBusTakeCommandsAndOnlyTheirOwn) {
  ASSERT_NO_FATAL_FAILURE(start());
  // Wait for the whole config state: sets are checked against it afterwards.
  const auto is_all = [](const std::vector<nlohmann::json>& v) { return v.size() == kUnits; };
  ASSERT_EQ(until("--json --timeout 5 config get avionics_voltage", is_all).size(), kUnits);
  // Two units per bus, the first and the last, each set to its own value (12..24 V, 0.1 V).
  std::map<Key, double> set;
  for (int b = 0; b < kBuses; ++b)
    for (int a : {1, kPerBus}) set[{bus_name(b), a}] = 13.0 + 2.0 * b + (a == 1 ? 0.0 : 1.0);
  for (const auto& [k, v] : set) {
    char value[16];
    std::snprintf(value, sizeof value, "%.1f", v);
    const auto r = run(pmuctl("--bus " + k.first + " --address " + std::to_string(k.second) +
                              " --timeout 10 config set avionics_voltage " + value + " 2>&1"));
    EXPECT_EQ(r.status, 0) << k.first << "/" << k.second << ": " << r.out;
    EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << r.out;
  }
  // Every unit's value: the ones set have theirs (read back from the unit and republished),
  // every other unit, including those at the same address on the other buses, still 12 V.
  const auto rows = until("--json --timeout 5 config get avionics_voltage", [&](const std::vector<nlohmann::json>& v) {
    std::size_t changed = 0;
    for (const auto& j : v)
      if (const auto it = set.find(key_of(j)); it != set.end())
        changed += std::abs(number(values(j), "avionics_voltage") - it->second) < 1e-3 ? 1u : 0u;
    return v.size() == kUnits && changed == set.size();
  });
  std::set<Key> seen;
  for (const auto& j : rows) {
    const Key k = key_of(j);
    seen.insert(k);
    const auto it = set.find(k);
    EXPECT_NEAR(number(values(j), "avionics_voltage"), it != set.end() ? it->second : 12.0, 1e-3)
        << k.first << "/" << k.second;
  }
  EXPECT_EQ(seen, all_units());
  EXPECT_EQ(service_->stop(), 0);
}

}  // namespace
