// Clients built from older contracts' IDL (old_consumer_v2, _v3, _v4) against pmu-service on
// its simulated PMUs (address 1 heard, address 2 silent), with pmuctl (contract v5) as the
// reference reader:
// - a service that serves v5 only: no old client matches anything (v5's type names), while
//   pmuctl reads it;
// - with `also_serve_contract: 4`: the v4 client reads every field as pmuctl does, and the
//   "no value" values as contract v4 sent them where v5 sends NaN (-1 s for the PMU never
//   heard), and gets one reply to its command; v3 and v2 clients match nothing;
// - pmuctl against a v4 service names the contract instead of reporting no service.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/configured_service.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace {

using namespace std::chrono_literals;
using Json = nlohmann::json;

// pmu-service on two simulated PMUs (sim0, address 1, and address 2, which never speaks), from
// a config file of its own.
class Service : public pmu::test::ConfiguredService {
 public:
  Service(int domain, bool also_v4)
      : ConfiguredService(PMU_SERVICE_PATH,
                          "domain: " + std::to_string(domain) + (also_v4 ? "\nalso_serve_contract: 4" : "") +
                              "\nlog_level: info\nbuses:\n  - interface: sim\n    name: sim0\n    devices:\n"
                              "      - address: 1\n        period: 0.5\n"
                              "      - address: 2\n        period: 0.5\n        sim: {silent: true}\n") {}
};

std::string pmuctl(int domain) { return std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain) + " "; }

// pmuctl's JSON line of a simulated PMU (unnamed vehicle, sim0/address), or null.
Json pmu_line(const std::string& out, const char* topic, int address = 1) {
  for (const auto& j : pmu::test::json_lines(out))
    if (j.is_object() && j.value("topic", "") == topic && j.value("vehicle", "?").empty() &&
        j.value("bus", "") == "sim0" && j.value("address", 0) == address)
      return j;
  return nullptr;
}

Json v5_state(int domain, const std::string& verb, const char* topic, int address = 1) {
  return pmu_line(pmu::test::run_capture(pmuctl(domain) + "--timeout 20 --json " + verb + " 2>/dev/null").out, topic,
                  address);
}

// pmuctl reads the PMU's health as ONLINE: the service is up and discoverable.
Json wait_v5_online(int domain) {
  Json h;
  (void)pmu::test::wait_until(
      [&] {
        h = v5_state(domain, "health", "health");
        return h.is_object() && h["values"].value("state", "") == "ONLINE";
      },
      120s, 200ms);
  return h;
}

struct ConsumerRun {
  std::string out;
  std::vector<Json> samples;  // every line but the final one
  Json final;
  // The newest decoded sample of `topic` (of the PMU at `address`), or null.
  Json last(const std::string& topic, int address = 1) const {
    Json j;
    for (const auto& s : samples)
      if (s.is_object() && s.value("topic", "") == topic && (!s.contains("address") || s["address"] == address)) j = s;
    return j;
  }
  std::size_t count(const std::string& topic) const {
    std::size_t n = 0;
    for (const auto& s : samples) n += s.is_object() && s.value("topic", "") == topic;
    return n;
  }
};

ConsumerRun run_consumer(const char* path, int domain, const std::string& args) {
  ConsumerRun r;
  r.out = pmu::test::run_capture(std::string(path) + " --domain " + std::to_string(domain) + " " + args).out;
  for (auto& j : pmu::test::json_lines(r.out)) {
    if (j.is_object() && j.value("final", false))
      r.final = j;
    else
      r.samples.push_back(j);
  }
  return r;
}

// The contracts a `pmuctl --json list` line says its vehicle's services serve.
Json contracts_of(const Json& line) {
  return line.is_object() && line.contains("values") && line["values"].contains("contracts")
             ? line["values"]["contracts"]
             : Json();
}

bool has(const Json& list, const std::string& v) {
  if (!list.is_array()) return false;
  for (const auto& e : list)
    if (e == v) return true;
  return false;
}

// A health counter of the v4 client's newest sample lies between pmuctl's reads before and
// after the client ran (they only grow): a misread number falls outside.
void expect_between(const Json& before, const Json& v4, const Json& after, const char* counter) {
  const auto lo = before["values"].value(counter, ~0ull), hi = after["values"].value(counter, 0ull);
  const auto got = v4.value(counter, ~0ull);
  EXPECT_TRUE(lo <= got && got <= hi) << counter << ": v4 read " << got << ", pmuctl " << lo << " before and " << hi
                                      << " after";
}

// An old client that finds the service's endpoints under names other than its own and
// matches none of them. `commands`: it also tried to send a command. Every endpoint it
// discovered has a name that starts with `service_type_prefix`.
void expect_matched_nothing(const ConsumerRun& run, const std::string& service_type_prefix, bool commands) {
  ASSERT_TRUE(run.final.is_object()) << run.out;
  // Discovery reported the service's endpoints under other names, so "matched nothing" is
  // the verdict on them, not a run that ended too early.
  std::vector<std::pair<std::string, std::string>> endpoints{
      {"pmu/health", "Health"}, {"pmu/config", "Config"}, {"pmu/voltages", "Voltages"}, {"pmu/status", "Status"}};
  if (commands)
    endpoints.insert(endpoints.end(), {{"pmu/command_reply", "CommandReply"}, {"reader:pmu/command", "Command"}});
  for (const auto& [topic, type] : endpoints) {
    const Json found = run.final["discovered"].value(topic, Json());
    EXPECT_TRUE(found.is_array() && !found.empty()) << topic << ": " << run.out;
    for (const auto& name : found)
      EXPECT_EQ(name.get<std::string>().rfind(service_type_prefix, 0), 0u) << topic << ": " << name << " " << run.out;
  }
  EXPECT_EQ(run.final["matched"].size(), commands ? 6u : 4u) << run.out;
  for (const auto& [topic, n] : run.final["matched"].items()) EXPECT_EQ(n, 0) << topic << ": " << run.out;
  EXPECT_TRUE(run.samples.empty()) << run.out;
  EXPECT_EQ(run.final.value("command_sent", true), false) << run.out;
}

TEST(OldContractConsumers, MatchNothingOfAServiceOfV5AloneWhichV5Reads) {
  const int domain = pmu::test::exclusive_dds_domain();
  Service service(domain, false);
  ASSERT_TRUE(wait_v5_online(domain).is_object()) << service.describe();

  for (const char* path : {OLD_CONSUMER_V4_PATH, OLD_CONSUMER_V3_PATH, OLD_CONSUMER_V2_PATH}) {
    SCOPED_TRACE(path);
    const bool commands = std::string(path) != OLD_CONSUMER_V2_PATH;
    const auto run = run_consumer(path, domain,
                                  std::string("--seconds 90 --until discovered --linger 2") +
                                      (commands ? " --command GET_SERIAL" : ""));
    expect_matched_nothing(run, "pmu::v5::", commands);
    EXPECT_TRUE(has(run.final["discovered"].value("pmu/health", Json()), "pmu::v5::Health")) << run.out;
    // What a tool of any contract can read without matching: the participant's property.
    EXPECT_EQ(run.final["service_contracts"], Json::array({"5"})) << run.out;
  }
  EXPECT_TRUE(wait_v5_online(domain).is_object()) << "pmuctl no longer reads the service: " << service.describe();
}

TEST(OldContractConsumers, V4ConsumerReadsEveryFieldOfAServiceThatAlsoServesV4) {
  const int domain = pmu::test::exclusive_dds_domain();
  Service service(domain, true);
  const Json before = wait_v5_online(domain);
  ASSERT_TRUE(before.is_object()) << service.describe();
  // pmuctl sees the v4 participant once discovery has reported it.
  Json listed;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] {
        listed = v5_state(domain, "list", "list");
        return listed.is_object() && contracts_of(listed) == Json::array({5, 4});
      },
      60s, 200ms))
      << listed.dump();
  const Json config = v5_state(domain, "config get", "config");
  const Json info = v5_state(domain, "info", "info");
  ASSERT_TRUE(config.is_object() && info.is_object()) << config.dump() << "\n" << info.dump();
  Json voltages, status;
  for (const auto& j : pmu::test::json_lines(
           pmu::test::run_capture(pmuctl(domain) + "--timeout 20 --json --address 1 watch --count 20").out)) {
    if (j.is_object() && j.value("topic", "") == "voltages") voltages = j;
    if (j.is_object() && j.value("topic", "") == "status") status = j;
  }
  ASSERT_TRUE(voltages.is_object() && status.is_object()) << "pmuctl watch printed no voltages or status";
  // The silent PMU: pmuctl reads NaN, which it shows as null ("never").
  const Json silent = v5_state(domain, "health", "health", 2);
  ASSERT_TRUE(silent.is_object()) << service.describe();
  EXPECT_TRUE(silent["values"]["last_frame_age"].is_null()) << silent.dump();

  const auto run =
      run_consumer(OLD_CONSUMER_V4_PATH, domain, "--seconds 90 --until decoded --linger 2 --command GET_SERIAL");
  const Json after = v5_state(domain, "health", "health");
  ASSERT_TRUE(run.final.is_object() && after.is_object()) << run.out << "\n" << service.describe();
  for (const char* topic :
       {"pmu/health", "pmu/config", "pmu/voltages", "pmu/status", "pmu/command", "pmu/command_reply"})
    EXPECT_EQ(run.final["matched"].value(topic, -1), 1) << topic << ": the v4 participant's alone; " << run.out;
  // Two participants named pmu-service, each announcing the contract it serves.
  EXPECT_EQ(run.final["service_contracts"], Json::array({"4", "5"})) << run.out;

  // Contract v4's "never heard", where v5 sends NaN.
  const Json never = run.last("pmu/health", 2);
  ASSERT_TRUE(never.is_object()) << run.out;
  EXPECT_EQ(never.value("last_frame_age", 0.0), -1.0) << never.dump();
  // The generator's speed as pmuctl reads it, as v4's unsigned short.
  const Json st = run.last("pmu/status");
  ASSERT_TRUE(st.is_object()) << run.out;
  ASSERT_TRUE(status["values"]["generator_rpm"].is_number()) << status.dump();
  EXPECT_EQ(st["generator_rpm"], status["values"]["generator_rpm"]) << st.dump() << status.dump();

  const Json h = run.last("pmu/health");
  ASSERT_TRUE(h.is_object()) << run.out;
  EXPECT_EQ(h["vehicle"], "");
  EXPECT_EQ(h["bus"], "sim0");
  EXPECT_EQ(h["address"], 1);
  EXPECT_EQ(h["kind"], "KIND_PMU");
  EXPECT_EQ(h["state"], "ONLINE");
  EXPECT_EQ(h["bus_state"], "UP");
  EXPECT_GE(h.value("last_frame_age", -1.0), 0.0) << h.dump();
  EXPECT_LT(h.value("last_frame_age", 99.0), 5.0) << h.dump();
  for (const char* c : {"frames_received", "frames_sent", "decode_errors", "bus_errors", "rx_dropped", "timeouts",
                        "reconnects", "publish_failures"})
    expect_between(before, h, after, c);

  // Stored parameters do not change by themselves: every field as pmuctl read it.
  const Json c = run.last("pmu/config");
  ASSERT_TRUE(c.is_object()) << run.out;
  EXPECT_EQ(c["bus"], "sim0");
  EXPECT_EQ(c["address"], 1);
  for (const auto& [field, value] : config["values"].items()) {
    ASSERT_TRUE(c.contains(field)) << field << " missing from " << c.dump();
    if (value.is_number_float()) {
      EXPECT_NEAR(c[field].get<double>(), value.get<double>(), 1e-3) << field;
    } else {
      EXPECT_EQ(c[field], value) << field;
    }
  }
  EXPECT_EQ(config["values"].size(), c.size() - 4) << "fields besides topic and keys: " << c.dump();

  // Set points read exactly; battery voltages drift with the simulated plant.
  const Json v = run.last("pmu/voltages");
  ASSERT_TRUE(v.is_object()) << run.out;
  for (const auto& [field, value] : voltages["values"].items()) {
    ASSERT_TRUE(v.contains(field)) << field << " missing from " << v.dump();
    if (value.is_number()) {
      EXPECT_NEAR(v[field].get<double>(), value.get<double>(), 0.5) << field << ": " << v.dump();
    }
  }

  ASSERT_EQ(run.count("pmu/command_reply"), 1u) << run.out;
  const Json reply = run.last("pmu/command_reply");
  EXPECT_EQ(reply["request_id"], run.final["request_id"]);
  EXPECT_EQ(reply["kind"], "GET_SERIAL");
  EXPECT_EQ(reply["result"], "COMPLETED") << reply.dump();
  EXPECT_EQ(reply["has_value"], true);
  EXPECT_EQ(reply.value("value", -1.0), info["values"].value("serial_number", -2.0)) << reply.dump() << info.dump();
  EXPECT_EQ(run.final["replies"], 1);
}

TEST(OldContractConsumers, V3AndV2ConsumersMatchNothingOfAServiceThatAlsoServesV4) {
  const int domain = pmu::test::exclusive_dds_domain();
  Service service(domain, true);
  ASSERT_TRUE(wait_v5_online(domain).is_object()) << service.describe();
  // Serving v4 as well serves v4's names only: a v3 client (pmu::Health) matches neither.
  for (const char* path : {OLD_CONSUMER_V3_PATH, OLD_CONSUMER_V2_PATH}) {
    SCOPED_TRACE(path);
    const bool commands = std::string(path) == OLD_CONSUMER_V3_PATH;
    const auto run = run_consumer(path, domain,
                                  std::string("--seconds 90 --until discovered --linger 2") +
                                      (commands ? " --command GET_SERIAL" : ""));
    // Whichever of the service's two participants discovery reported first: their names are
    // versioned, the client's are not.
    expect_matched_nothing(run, "pmu::v", commands);
  }
}

// A stand-in for a v4 pmu-service: participant "pmu-service", pmu/health as pmu::v4::Health.
pmu::test::Child fake_v4_service(int domain, const std::string& vehicle) {
  pmu::test::ChildOptions o;
  o.stdout_path = o.stderr_path = "/dev/null";
  return pmu::test::Child({OLD_CONSUMER_V4_PATH, "--domain", std::to_string(domain), "--serve-health", "--vehicle",
                           vehicle, "--seconds", "600"},
                          o);
}

TEST(OldContractConsumers, PmuctlNamesTheContractOfTheOnlyServiceThere) {
  const int domain = pmu::test::exclusive_dds_domain();
  auto fake = fake_v4_service(domain, "");
  // With nothing of v5 to read, pmuctl waits out its timeout: 15 s covers discovery.
  const auto r = pmu::test::run_capture(pmuctl(domain) + "--timeout 15 list", true);
  EXPECT_EQ(r.status, 3) << r.out;
  EXPECT_NE(r.out.find("no pmu-service of contract v5 on domain " + std::to_string(domain) +
                       "; found pmu-service of contract v4 (vehicles: (unnamed)); this pmuctl reads "
                       "contract v5 only (docs/interface.md section 10"),
            std::string::npos)
      << r.out;
  const auto j = pmu::test::run_capture(pmuctl(domain) + "--timeout 15 --json list 2>/dev/null");
  EXPECT_EQ(j.status, 3) << j.out;
  const auto lines = pmu::test::json_lines(j.out);
  ASSERT_EQ(lines.size(), 1u) << j.out;
  ASSERT_TRUE(lines[0].is_object()) << j.out;
  EXPECT_EQ(lines[0].value("exit_status", -1), 3) << j.out;
  const auto error = lines[0].value("error", "");
  EXPECT_NE(error.find("contract v4"), std::string::npos) << j.out;
  EXPECT_NE(error.find("this pmuctl reads contract v5"), std::string::npos) << j.out;
  EXPECT_TRUE(fake.running()) << "the fake v4 service exited early";
}

TEST(OldContractConsumers, PmuctlListsAnotherVehiclesV4ServiceAsUnreadable) {
  const int domain = pmu::test::exclusive_dds_domain();
  Service service(domain, false);
  auto fake = fake_v4_service(domain, "uav2");
  ASSERT_TRUE(wait_v5_online(domain).is_object()) << service.describe();

  // list settles on the v5 state it reads; uav2 is there once discovery has reported it.
  Json uav2, own;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] {
        const auto r = pmu::test::run_capture(pmuctl(domain) + "--timeout 20 --json list 2>/dev/null");
        own = pmu_line(r.out, "list");
        for (const auto& l : pmu::test::json_lines(r.out))
          if (l.is_object() && l.value("vehicle", "") == "uav2") uav2 = l;
        return r.status == 0 && uav2.is_object();
      },
      60s, 200ms))
      << uav2.dump();
  EXPECT_EQ(contracts_of(uav2), Json::array({4})) << uav2.dump();
  EXPECT_EQ(uav2["contract"], 5) << uav2.dump();
  EXPECT_EQ(uav2.value("error", ""), "serves contract v4, which this pmuctl cannot read") << uav2.dump();
  EXPECT_EQ(contracts_of(own), Json::array({5})) << own.dump();

  pmu::test::RunResult text;
  EXPECT_TRUE(pmu::test::wait_until(
      [&] {
        text = pmu::test::run_capture(pmuctl(domain) + "--timeout 20 list", true);
        return text.out.find("UNREADABLE") != std::string::npos;
      },
      60s, 200ms))
      << text.out;
  EXPECT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("\nuav2 "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("pmuctl: UNREADABLE: pmu-service of contract v4 (vehicles: uav2); this pmuctl "
                          "reads contract v5 only"),
            std::string::npos)
      << text.out;

  // Asked for uav2 alone, while a v5 service serves another vehicle: the message names uav2's
  // contract, not the v5 vehicles, and nothing answered (3).
  const auto one = pmu::test::run_capture(pmuctl(domain) + "--vehicle uav2 --timeout 5 health", true);
  EXPECT_EQ(one.status, 3) << one.out;
  EXPECT_NE(one.out.find("no pmu-service of contract v5 for vehicle uav2 on domain " + std::to_string(domain) +
                         "; found pmu-service of contract v4 (vehicles: uav2)"),
            std::string::npos)
      << one.out;
}

}  // namespace
