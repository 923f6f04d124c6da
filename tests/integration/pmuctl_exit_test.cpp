// pmuctl's exit statuses, verb by verb, as pmuctl(1) and interface.md section 3.2 give them:
// 0 done, 1 answered but not done, 2 bad usage or no such target, 3 nothing answered; and
// with --json exactly one JSON line per result, failures included. On the demo power system
// (deploy/examples/sim-power-system.yaml: a PMU, a battery and two MPPTs on one bus), PMU
// commands find the one PMU, and an engine stop goes out in every situation.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmu/idl/alarmsPubSubTypes.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "support/domain.hpp"
#include "support/json_lines.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace {

using namespace std::chrono_literals;

struct Case {
  const char* args;     // after `pmuctl --domain N`
  int status;           // expected exit status
  const char* message;  // part of stderr+stdout ("" for none)
};

std::string pmuctl(int domain) { return std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain) + " "; }

// Runs each case (each has exactly one result), and again with --json: then stdout is exactly
// one JSON line, and a failure's line carries the same exit status.
void run_cases(int domain, const Case* begin, const Case* end) {
  for (const Case* c = begin; c != end; ++c) {
    SCOPED_TRACE(c->args);
    const auto r = pmu::test::run_capture(pmuctl(domain) + c->args, true);
    EXPECT_EQ(r.status, c->status) << r.out;
    EXPECT_NE(r.out.find(c->message), std::string::npos) << r.out;
    const auto j = pmu::test::run_capture(pmuctl(domain) + "--json " + c->args + " 2>/dev/null");
    EXPECT_EQ(j.status, c->status) << j.out;
    const auto lines = pmu::test::json_lines(j.out);
    ASSERT_EQ(lines.size(), 1u) << j.out;
    ASSERT_FALSE(lines[0].is_discarded()) << j.out;
    if (c->status >= 2) {
      EXPECT_EQ(lines[0].value("exit_status", -1), c->status) << j.out;
      EXPECT_TRUE(lines[0].contains("error") || lines[0].contains("reason")) << j.out;
    } else {
      EXPECT_TRUE(lines[0].contains("result")) << j.out;
    }
  }
}

class DemoPowerSystem : public ::testing::Test {
 protected:
  void SetUp() override {
    pmu::test::ChildOptions o;
    o.stdout_path = o.stderr_path = "/dev/null";
    service_ = pmu::test::Child({PMU_SERVICE_PATH, "--config", PMU_SOURCE_DIR "/deploy/examples/sim-power-system.yaml",
                                 "--domain", std::to_string(domain_)},
                                o);
    // Ready once every device's health is there (the MPPTs report at 1 s).
    for (int i = 0; i < 30; ++i) {
      const auto r = pmu::test::run_capture(pmuctl(domain_) + "--timeout 5 --json list");
      if (pmu::test::json_lines(r.out).size() == 4) return;
      std::this_thread::sleep_for(200ms);
    }
    FAIL() << "the demo power system did not list its four devices";
  }
  void TearDown() override { (void)service_.stop(10s); }

  const int domain_ = pmu::test::exclusive_dds_domain();
  pmu::test::Child service_;
};

const Case kDemo[] = {
    // PMU commands consider the PMU alone: the battery and MPPTs share its bus and addresses.
    {"--timeout 10 engine stop", 0, "COMPLETED"},
    {"--timeout 10 outputs get", 0, "COMPLETED"},
    // The demo's engine runs: a start is refused from the generator speed, not "sent".
    {"--timeout 10 --confirm engine start", 1, "DENIED: engine already running: 6000 rpm"},
    {"--timeout 10 --address 65535 engine stop", 0, "stop sent to every PMU (broadcast) on sim0"},
    {"--timeout 10 --bus sim0 --address 65535 engine stop", 0, "stop sent to every PMU (broadcast)"},
    // A value the spec refuses is bad usage, refused before anything is sent (interface.md 3.2).
    {"--timeout 10 config set avionics_voltage 99", 2, "value 99.0 V out of range 12.0..24.0 V for avionics_voltage"},
    // Broadcast is for the stop alone.
    {"--address 65535 outputs get", 2, "--address 65535 (broadcast) is only for `engine stop`"},
    {"--address 65535 engine start", 2, "--address 65535 (broadcast) is only for `engine stop`"},
    {"--address 65535 list", 2, "--address 65535 (broadcast) is only for `engine stop`"},
    // No such target: 2, state verbs and commands alike.
    // A device missing from a service's state is known as soon as that state has come: the
    // timeout only bounds discovery, which a loaded machine can make slow.
    {"--timeout 30 --address 9 info", 2, "PMU 9 not seen"},
    {"--timeout 30 --address 9 config get", 2, "PMU 9 not seen"},
    {"--timeout 30 --address 9 outputs get", 2, "PMU 9 not seen"},
    {"--timeout 30 --bus nope list", 2, "no device seen on bus nope"},
    // Named whole, a target is not looked up first (an engine stop waits for nothing): the
    // service's refusal says it is not there, which is no such target too.
    {"--timeout 10 --bus nope --address 1 engine stop", 2, "REJECTED: bus 'nope' is not served here (buses: sim0)"},
    {"--timeout 10 --bus nope --address 65535 engine stop", 2, "REJECTED: bus 'nope' is not served here"},
    {"--timeout 10 --bus sim0 --address 9 engine stop", 2, "REJECTED: device 9 not seen on sim0"},
    {"config get no_such_parameter", 2, "unknown parameter 'no_such_parameter' (parameters: avionics_voltage"},
    {"config set outputs 15", 2, "switch them with `pmuctl outputs set|enable|disable NAME...`"},
    {"config set generation_enabled 1", 2, "`pmuctl generation on|off`"},
    {"config set no_such_parameter 1", 2, "unknown parameter 'no_such_parameter'"},
    {"config set avionics_voltage -inf", 2, "'-inf' is not a finite number"},
    {"config set avionics_voltage nan", 2, "avionics_voltage: 'nan' is not a number"},
    {"config set packets_streamed -1", 2, "packets_streamed: '-1' is not a mask"},
    {"--timeout 10 config set packets_streamed 32", 2, "packets_streamed 32 has bits outside the defined mask 0x1F"},
    {"--timeout 10 config set packets_streamed 0x20", 2, "packets_streamed 32 has bits outside the defined mask 0x1F"},
    // Option values.
    {"--timeout 1e10 list", 2, "--timeout '1e10' is not a number of seconds"},
    {"--timeout nan list", 2, "--timeout 'nan' is not a number of seconds"},
    {"watch --count 0", 2, "--count '0' is not a whole number 1..1000000000"},
};

TEST_F(DemoPowerSystem, EveryVerbExitsAsTheTableSays) { run_cases(domain_, std::begin(kDemo), std::end(kDemo)); }

// Another vehicle's service never matches a client of uav9 (partitions), so "not there"
// is only known at the timeout, from discovery: the timeout must cover discovery of the
// service that is there, which a loaded machine makes take seconds.
const Case kOtherVehicle[] = {
    {"--timeout 10 --vehicle uav9 outputs get", 2, "no pmu-service of vehicle uav9 on domain"},
    {"--timeout 10 --vehicle uav9 list", 2, "vehicles seen: (unnamed)"},
};

TEST_F(DemoPowerSystem, AnotherVehicleIsNoSuchTargetNamingTheVehiclesThere) {
  run_cases(domain_, std::begin(kOtherVehicle), std::end(kOtherVehicle));
}

TEST_F(DemoPowerSystem, ReadingVerbsExitZeroWithOneJsonLinePerDevice) {
  for (const char* verb : {"list", "health"}) {
    SCOPED_TRACE(verb);
    const auto r = pmu::test::run_capture(pmuctl(domain_) + "--timeout 5 --json " + verb);
    EXPECT_EQ(r.status, 0) << r.out;
    EXPECT_EQ(pmu::test::json_lines(r.out).size(), 4u) << r.out;
  }
  const auto r = pmu::test::run_capture(pmuctl(domain_) + "--timeout 10 --json watch --count 3");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(pmu::test::json_lines(r.out).size(), 3u) << r.out;
}

// Nothing on the domain: every verb says so and exits 3.
const Case kNobody[] = {
    {"--timeout 1 list", 3, "no pmu-service on domain"},
    {"--timeout 1 info", 3, "no pmu-service on domain"},
    {"--timeout 1 alarms", 3, "no pmu-service on domain"},
    {"--timeout 1 energy", 3, "no pmu-service on domain"},
    {"--timeout 1 health", 3, "no pmu-service on domain"},
    {"--timeout 1 config get", 3, "no pmu-service on domain"},
    {"--timeout 1 watch --count 1", 3, "no pmu-service on domain"},
    {"--timeout 1 outputs get", 3, "no pmu-service on domain"},
    {"--timeout 1 engine stop", 3, "no pmu-service on domain"},
    {"--timeout 1 --address 65535 engine stop", 3, "no pmu-service on domain"},
    {"--timeout 1 --vehicle uav1 list", 3, "no pmu-service of vehicle uav1 on domain"},
    // Named whole, the PMU is not looked up first: the wait for its configuration is the
    // first to hear from the service, and what did not answer is the service, not the PMU.
    {"--timeout 1 --bus sim --address 1 config diff", 3, "no pmu-service on domain"},
    {"--timeout 1 --bus sim --address 1 config snapshot -", 3, "no pmu-service on domain"},
};

TEST(PmuctlExit, NothingOnTheDomainIsExitThreeForEveryVerb) {
  run_cases(pmu::test::exclusive_dds_domain(), std::begin(kNobody), std::end(kNobody));
}

// A service that takes commands and never answers: the command verb exits 3, and its JSON
// line is the reply's with a null result.
TEST(PmuctlExit, NoReplyIsExitThreeWithOneJsonLine) {
  using namespace eprosima::fastdds::dds;
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext silent(domain, PMU_QOS_FILE, "silent-service");
  (void)silent.reader(silent.topic(pmu::topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                      pmu::qos_profiles::kCommand);
  (void)silent.writer(silent.topic(pmu::topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                      pmu::qos_profiles::kCommand);
  // The timeout bounds the match with the silent service too: long enough for a loaded machine.
  const auto r = pmu::test::run_capture(pmuctl(domain) + "--timeout 8 --json --bus can0 --address 1 outputs get");
  EXPECT_EQ(r.status, 3) << r.out;
  const auto lines = pmu::test::json_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << r.out;
  EXPECT_TRUE(lines[0]["result"].is_null()) << r.out;
  EXPECT_EQ(lines[0]["bus"], "can0") << r.out;
  EXPECT_EQ(lines[0]["exit_status"], 3) << r.out;
  EXPECT_NE(lines[0]["reason"].get<std::string>().find("no reply from pmu-service within 8.0 s"), std::string::npos)
      << r.out;
}


std::uint64_t epoch_ns(std::chrono::system_clock::time_point t) {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

// A service whose request reader pmuctl matches at once and whose reply writer it meets only
// after a slow discovery (3 s), and which never answers: pmuctl sends its request with part of
// its --timeout used up. The request's expires_at (interface.md 2.3) is the end of pmuctl's
// wait, whatever the finding cost, so the service sends nothing of it once pmuctl has given up
// (docs/safety.md H9); a resend keeps it.
template <class RequestType, class ReplyType, class Request>
void expect_expiry_at_the_end_of_the_wait(const char* request_topic, const char* reply_topic,
                                          const std::vector<std::string>& verb) {
  using namespace eprosima::fastdds::dds;
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::dds::DdsContext service(domain, PMU_QOS_FILE, "late-service");
  DataReader& requests =
      service.reader(service.topic(request_topic, TypeSupport(new RequestType())), pmu::qos_profiles::kCommand);
  std::vector<std::string> argv{PMUCTL_PATH, "--domain", std::to_string(domain), "--timeout", "15", "--json"};
  argv.insert(argv.end(), verb.begin(), verb.end());
  pmu::test::ChildOptions o;
  o.stdout_path = o.stderr_path = "/dev/null";
  const auto started = std::chrono::system_clock::now();
  pmu::test::Child pmuctl(argv, o);
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        SubscriptionMatchedStatus st;
        requests.get_subscription_matched_status(st);
        return st.current_count > 0;
      },
      15s))
      << "pmuctl's request writer never matched";
  std::this_thread::sleep_for(3s);  // the slow part of the discovery: pmuctl's wait goes on
  (void)service.writer(service.topic(reply_topic, TypeSupport(new ReplyType())), pmu::qos_profiles::kCommand);
  // Taken while pmuctl runs: what its writer sent goes with it.
  std::vector<std::uint64_t> expiries;
  const auto take = [&] {
    Request r;
    SampleInfo info;
    while (requests.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) expiries.push_back(r.expires_at());
  };
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        take();
        return !pmuctl.running();
      },
      60s))
      << "pmuctl did not end";
  const auto gave_up = std::chrono::system_clock::now();
  const auto status = pmuctl.status();
  ASSERT_TRUE(status && WIFEXITED(*status));
  EXPECT_EQ(WEXITSTATUS(*status), 3) << "no reply";
  ASSERT_FALSE(expiries.empty()) << "pmuctl sent nothing";
  for (const auto e : expiries) {
    EXPECT_EQ(e, expiries.front()) << "a resend keeps the request's expiry";
    EXPECT_GT(e, epoch_ns(started));
    EXPECT_LE(e, epoch_ns(gave_up)) << "the request outlives pmuctl's wait by "
                                    << (static_cast<double>(e) - static_cast<double>(epoch_ns(gave_up))) / 1e9 << " s";
  }
}

TEST(PmuctlExpiry, ACommandExpiresWhenPmuctlStopsWaiting) {
  expect_expiry_at_the_end_of_the_wait<pmu::v5::CommandPubSubType, pmu::v5::CommandReplyPubSubType, pmu::v5::Command>(
      pmu::topics::kCommand, pmu::topics::kCommandReply, {"--bus", "can0", "--address", "1", "outputs", "get"});
}

TEST(PmuctlExpiry, AnAlarmAcknowledgementExpiresWhenPmuctlStopsWaiting) {
  expect_expiry_at_the_end_of_the_wait<pmu::v5::AlarmAckPubSubType, pmu::v5::AlarmAckReplyPubSubType, pmu::v5::AlarmAck>(
      pmu::topics::kAlarmAck, pmu::topics::kAlarmAckReply,
      {"--bus", "can0", "alarms", "ack", "bus_off", "--kind", "bus"});
}

}  // namespace
