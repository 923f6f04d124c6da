// The command path over real Fast DDS: two ground stations burst 1000 commands at an
// in-process service (real clock, simulated PMUs), and pmuctl / the example client across
// processes get the contract's results, messages and exit statuses.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <map>
#include <set>
#include <thread>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_commands.hpp"
#include "pmu/endpoints/dds_publisher.hpp"
#include "pmu/idl/command.h"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/statePubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/session/bus_worker.hpp"
#include "pmu/sim/bus_runner.hpp"
#include "pmu/transport/sim_bus.hpp"
#include "support/answered.hpp"
#include "support/domain.hpp"
#include "support/process.hpp"
#include "support/wait.hpp"

namespace pmu::service {
namespace {

using namespace eprosima::fastdds::dds;
using namespace std::chrono_literals;

struct Sender {
  Sender(int domain, const std::string& name)
      : dds(domain, "", name),
        writer(dds.writer(dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                          qos_profiles::kCommand)),
        replies(dds.reader(dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                           qos_profiles::kCommand)) {}
  bool matched() {
    PublicationMatchedStatus p;
    SubscriptionMatchedStatus s;
    writer.get_publication_matched_status(p);
    replies.get_subscription_matched_status(s);
    return p.current_count > 0 && s.current_count > 0;
  }
  // Until the service has answered a probe (support/answered.hpp says why matching on this
  // side is not enough). The probe's replies have the id `probe_id`, which no burst id starts
  // with.
  bool until_answered(const std::string& probe_id) {
    pmu::v5::Command probe;
    probe.request_id(probe_id);
    probe.bus("sim0");
    probe.address(1);
    probe.kind(pmu::v5::GET_SERIAL);
    return pmu::test::until_answered([&] { writer.write(&probe); },
                                     [&] {
                                       pmu::v5::CommandReply r;
                                       SampleInfo info;
                                       bool got = false;
                                       while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
                                         got = got || (info.valid_data && r.request_id().to_string() == probe_id);
                                       return got;
                                     },
                                     30s);
  }
  dds::DdsContext dds;
  DataWriter& writer;
  DataReader& replies;
};

TEST(CommandsOverDds, TwoSendersBurst1000CommandsAndGetExactly1000Replies) {
  const int domain = pmu::test::exclusive_dds_domain();
  transport::SystemClock clock;
  transport::SimulatedNetwork network(clock);
  sim::BusRunner pmus(network.attach("pmu-sim"), clock);
  for (std::uint16_t a : {std::uint16_t{1}, std::uint16_t{2}}) {
    sim::DeviceConfig d;
    d.address = a;
    pmus.add(d);
  }
  BusConfig bus;
  bus.name = "sim0";
  bus.interface = "sim";
  for (std::uint16_t a : {std::uint16_t{1}, std::uint16_t{2}}) {
    DeviceConfig d;
    d.address = a;
    bus.devices.push_back(d);
  }
  dds::DdsContext service_dds(domain, "", "pmu-service-burst");
  DdsPublisher publisher(service_dds, 3s);
  BusWorker worker(bus, network.attach("sim0"), clock, Timeouts{}, publisher);
  DdsCommandEndpoint endpoint(service_dds);
  PolicyConfig policy;
  policy.rate_per_second = 0;
  CommandService service({&worker}, policy, Timeouts{}, clock, [&](const CommandReplyData& r) { endpoint.publish(r); });
  pmus.start();
  std::thread worker_thread([&] { worker.run(); });
  endpoint.start(service);

  Sender a(domain, "ground-a"), b(domain, "ground-b");
  pmu::test::wait_until([&] { return a.matched() && b.matched(); }, 5s);
  ASSERT_TRUE(a.matched() && b.matched());
  // The devices' start-up reading: over when each has published its configuration (a
  // session publishes pmu/config as it enters its running phase).
  DataReader& configs =
      a.dds.reader(a.dds.topic(topics::kConfig, TypeSupport(new pmu::v5::ConfigPubSubType())), qos_profiles::kState);
  std::set<unsigned> configured;
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        pmu::v5::Config c;
        SampleInfo i;
        while (configs.take_next_sample(&c, &i) == ReturnCode_t::RETCODE_OK)
          if (i.valid_data) configured.insert(c.address());
        return configured.size() == 2;
      },
      30s))
      << "the devices' start-up reading did not finish";
  ASSERT_TRUE(a.until_answered("probe-a")) << "ground-a's probe was never answered";
  ASSERT_TRUE(b.until_answered("probe-b")) << "ground-b's probe was never answered";
  const auto before = service.counters();  // the probes and their resends are not the burst's

  std::map<std::string, int> replies_a, replies_b;
  std::atomic<bool> done{false};
  auto collect = [&](Sender& s, std::map<std::string, int>& out, const std::string& prefix) {
    pmu::v5::CommandReply r;
    SampleInfo info;
    while (s.replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data && r.request_id().to_string().rfind(prefix, 0) == 0) ++out[r.request_id().to_string()];
  };
  auto send = [&](Sender& s, const std::string& prefix) {
    for (int i = 0; i < 500; ++i) {
      pmu::v5::Command c;
      c.request_id(prefix + std::to_string(i));
      c.bus("sim0");
      c.address(static_cast<unsigned short>(1 + i % 2));
      switch (i % 4) {
        case 0:
          c.kind(pmu::v5::SET_PARAMETER);
          c.parameter("payload_voltage");
          c.value(i % 8 == 0 ? 30.0 : 12.0 + (i % 100) / 10.0);  // some out of range
          break;
        case 1: c.kind(pmu::v5::GET_SERIAL); break;
        case 2:
          c.kind(pmu::v5::ENABLE_OUTPUTS);
          c.outputs(0x02);
          break;
        default: c.kind(pmu::v5::GET); c.parameter("outputs");
      }
      s.writer.write(&c);
      // A well-behaved client sends bursts the command QoS depth (1024) holds, and lets
      // them be acknowledged before the next.
      if (i % 100 == 99) s.writer.wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5, 0));
    }
  };
  std::thread ta([&] { send(a, "a-"); });
  std::thread tb([&] { send(b, "b-"); });
  pmu::test::wait_until(
      [&] {
        collect(a, replies_a, "a-");
        collect(b, replies_b, "b-");
        return replies_a.size() >= 500 && replies_b.size() >= 500;
      },
      60s, 2ms);
  ta.join();
  tb.join();
  // Meant to let time pass: a duplicate reply is an event that must NOT happen, so there is
  // no condition to wait for; 300 ms is ample for one already sent to arrive.
  std::this_thread::sleep_for(300ms);
  collect(a, replies_a, "a-");
  collect(b, replies_b, "b-");
  done = true;
  endpoint.stop();
  worker.stop();
  worker_thread.join();
  pmus.stop();

  EXPECT_EQ(replies_a.size(), 500u);
  EXPECT_EQ(replies_b.size(), 500u);
  for (const auto* m : {&replies_a, &replies_b})
    for (const auto& [id, n] : *m) EXPECT_EQ(n, 1) << id << " answered " << n << " times";
  const auto counters = service.counters();
  EXPECT_EQ(counters.received - before.received, 1000u);
  EXPECT_EQ(counters.duplicates - before.duplicates, 0u);
  for (std::uint16_t addr : {std::uint16_t{1}, std::uint16_t{2}})
    pmus.with_model(addr, [](sim::PmuModel& m) {
      EXPECT_EQ(m.counters().rejected_sets, 0u) << "an out-of-range set reached a unit";
    });
}

// ---- pmuctl and the example client against pmu-service ----------------------------------

pmu::test::RunResult sh(const std::string& cmd) { return pmu::test::run_capture(cmd, true); }

TEST(PmuctlCommands, ResultsMessagesAndExitStatus) {
  const int domain = pmu::test::exclusive_dds_domain();
  pmu::test::Child service(
      {PMU_SERVICE_PATH, "--bus", "sim", "--domain", std::to_string(domain), "--log-level", "warn"});
  const std::string p = std::string(PMUCTL_PATH) + " --domain " + std::to_string(domain) + " ";
  // The first call waits for the service as long as a loaded (or ThreadSanitizer) run needs:
  // it returns as soon as the device is seen.
  auto r = sh(p + "--timeout 30 config set avionics_voltage 24");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("COMPLETED"), std::string::npos) << r.out;
  r = sh(p + "--timeout 20 config get avionics_voltage");  // a state verb: 3 s by default, returns once seen
  EXPECT_NE(r.out.find("avionics_voltage = 24.0"), std::string::npos) << r.out;
  // A value out of the spec's range is bad usage, refused before anything is sent (interface.md
  // 3.2's exit statuses); the service's own refusal of it is the boundary tests'.
  r = sh(p + "config set avionics_voltage 30.0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("pmuctl: value 30.0 V out of range 12.0..24.0 V for avionics_voltage"), std::string::npos)
      << r.out;
  r = sh(p + "outputs disable avionics_servo");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("DENIED"), std::string::npos) << r.out;
  r = sh(p + "--confirm outputs disable avionics_servo");
  EXPECT_EQ(r.status, 0) << r.out;
  r = sh(p + "outputs get");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.find("avionics_servo"), std::string::npos) << r.out;
  r = sh(p + "--address 7 engine stop");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("PMU 7 not seen"), std::string::npos) << r.out;
  r = sh(p + "--json generation off");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("\"result\":\"COMPLETED\""), std::string::npos) << r.out;
  r = sh("PMU_QOS_FILE=" PMU_QOS_FILE " " GROUND_STATION_PATH " --domain " + std::to_string(domain));
  EXPECT_EQ(r.status, 0) << r.out;
}

TEST(PmuctlCommands, NoServiceIsSaid) {
  // This process's own domain: no service runs on it (this test starts none).
  const std::string domain = std::to_string(pmu::test::exclusive_dds_domain());
  const auto r = sh(std::string(PMUCTL_PATH) + " --domain " + domain + " --timeout 1 config set avionics_voltage 24");
  EXPECT_EQ(r.status, 3);  // nothing answered
  EXPECT_NE(r.out.find("no pmu-service on domain " + domain), std::string::npos) << r.out;
}

}  // namespace
}  // namespace pmu::service
