// A hot standby reads the bus owner's replies on pmu/command_reply over real Fast DDS
// (DdsCommandEndpoint::follow_peer_replies, design.md "Commands across a failover"): the
// owner's reply settles the request it recorded, so after taking over a resend is answered with
// that reply and nothing runs; its own reply writer's samples are no peer's.
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_commands.hpp"
#include "pmu/idl/commandPubSubTypes.h"
#include "pmu/idl/topics.hpp"
#include "pmu/transport/clock.hpp"
#include "support/answered.hpp"
#include "support/domain.hpp"
#include "support/wait.hpp"

namespace pmu::service::test {
namespace {

using namespace std::chrono_literals;

CommandReplyData reply(const std::string& reason) {
  CommandReplyData d;
  d.request_id = "r-1";
  d.bus = "can0";
  d.address = 1;
  d.kind = CommandKind::Reset;
  d.result = CommandResult::Completed;
  d.reason = reason;
  return d;
}

TEST(PeerReplies, AStandbyAnswersAResendAfterTakingOverWithTheOwnersReply) {
  const std::string vehicle = "uav1";
  transport::SystemClock clock;
  dds::DdsContext standby_dds(pmu::test::exclusive_dds_domain(), "", "standby", {}, dds::Transport::Default, {},
                              {dds::vehicle_partitions(vehicle), dds::vehicle_partitions(vehicle)});
  dds::DdsContext owner_dds(pmu::test::exclusive_dds_domain(), "", "owner", {}, dds::Transport::Default, {},
                            {dds::vehicle_partitions(vehicle), dds::vehicle_partitions(vehicle)});
  std::mutex mutex;
  std::vector<CommandReplyData> answered;
  std::atomic<bool> owns{false};
  // No bus: anything it ran would be answered "not served", which the test would see.
  CommandService service({}, PolicyConfig{}, Timeouts{}, clock, [&](const CommandReplyData& r) {
    std::lock_guard<std::mutex> lock(mutex);
    answered.push_back(r);
  });
  service.set_role_gate([&] { return owns.load(); });
  // After the service: destroyed (and stopped) before it.
  DdsCommandEndpoint owner(owner_dds, nullptr, vehicle);
  DdsCommandEndpoint standby(standby_dds, nullptr, vehicle);
  standby.start(service);
  standby.follow_peer_replies();

  CommandSample s;
  s.request_id = "r-1";
  s.sender = "client";
  s.vehicle = vehicle;
  s.bus = "can0";
  s.address = 1;
  s.kind = static_cast<std::uint32_t>(CommandKind::Reset);
  service.submit(s);  // as the standby's reader would hand it over
  ASSERT_EQ(service.recorded(), 1u);

  // Its own writer's reply first, then the owner's, until the owner's reader has matched.
  standby.publish(reply("written by this instance"));
  ASSERT_TRUE(pmu::test::wait_until(
      [&] {
        owner.publish(reply("reset by the owner"));
        return service.counters().peer_replies > 0;
      },
      20s, 100ms))
      << "the owner's reply never reached the standby";

  owns = true;
  service.took_over(clock.steady_now());
  service.submit(s);  // the client's resend
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(answered.size(), 1u) << "only the resend is answered, and not run";
  EXPECT_EQ(answered[0].reason, "reset by the owner");
  EXPECT_EQ(answered[0].result, CommandResult::Completed);
}

// Fast DDS's in-process delivery on, as pmu-service runs (this program's main turns it off,
// gtest_main_through_transport.cpp), for one test: restored when it ends.
class InProcessDelivery {
 public:
  InProcessDelivery() : before_(eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings()) {
    auto on = before_;
    on.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_FULL;
    eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(on);
  }
  ~InProcessDelivery() { eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(before_); }
  InProcessDelivery(const InProcessDelivery&) = delete;
  InProcessDelivery& operator=(const InProcessDelivery&) = delete;

 private:
  eprosima::fastrtps::LibrarySettingsAttributes before_;
};

// A reply written on the command listener's thread (a request refused at once, a resend
// answered again) also reaches this participant's own reply reader. With in-process delivery
// (pmu-service's) Fast DDS hands it over on the writing thread, inside the write, so a
// reply listener that waited there for the command listener's lock would never return: the
// reply never leaves, and the process cannot be stopped.
TEST(PeerReplies, AReplyWrittenFromTheCommandListenerReachesTheClient) {
  using namespace eprosima::fastdds::dds;
  InProcessDelivery in_process;
  const int domain = pmu::test::exclusive_dds_domain();
  transport::SystemClock clock;
  dds::DdsContext service_dds(domain, "", "pmu-service-pair");
  dds::DdsContext client_dds(domain, "", "client");
  auto& writer = client_dds.writer(client_dds.topic(topics::kCommand, TypeSupport(new pmu::v5::CommandPubSubType())),
                                   qos_profiles::kCommand);
  auto& replies =
      client_dds.reader(client_dds.topic(topics::kCommandReply, TypeSupport(new pmu::v5::CommandReplyPubSubType())),
                        qos_profiles::kCommand);
  DdsCommandEndpoint* endpoint_ptr = nullptr;
  // No bus: every request is refused on the listener's thread, and its reply written there.
  CommandService service({}, PolicyConfig{}, Timeouts{}, clock,
                         [&](const CommandReplyData& r) { endpoint_ptr->publish(r); });
  service.set_role_gate([] { return true; });
  DdsCommandEndpoint endpoint(service_dds);
  endpoint_ptr = &endpoint;
  endpoint.start(service);
  endpoint.follow_peer_replies();

  pmu::v5::Command c;
  c.request_id("listener-1");
  c.bus("can0");
  c.address(1);
  c.kind(pmu::v5::RESET);
  // Each write on a thread of its own: in process, a write runs the service's command listener
  // on the writing thread, and a listener stuck there must not keep the test from saying so.
  std::vector<std::future<void>> sends;
  const auto send = [&] { sends.push_back(std::async(std::launch::async, [&] { writer.write(&c); })); };
  const bool answered = pmu::test::until_answered(
      send,
      [&] {
        pmu::v5::CommandReply r;
        SampleInfo info;
        bool got = false;
        while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
          got = got || (info.valid_data && r.request_id() == "listener-1");
        return got;
      },
      20s);
  if (!answered) {
    // The listener is stuck inside the write: tearing the endpoint down would wait for it.
    ADD_FAILURE() << "the reply written on the command listener's thread never came (its write is stuck)";
    std::fflush(stdout);
    std::_Exit(1);
  }
  // Once the service's own reply reader has matched its writer too: the same request again is
  // answered again, on the listener's thread, and so is the one after it.
  std::this_thread::sleep_for(1s);
  for (int again = 0; again < 2; ++again) {
    send();
    bool got = false;
    const bool answered_again = pmu::test::wait_until(
        [&] {
          pmu::v5::CommandReply r;
          SampleInfo info;
          while (replies.take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK)
            got = got || (info.valid_data && r.request_id() == "listener-1");
          return got;
        },
        10s, 10ms);
    if (!answered_again) {
      ADD_FAILURE() << "resend " << again << ": no reply (the listener's write is stuck)";
      std::fflush(stdout);
      std::_Exit(1);  // as above: the endpoint cannot stop
    }
  }
  for (auto& f : sends) f.wait();
  endpoint.stop();
}

}  // namespace
}  // namespace pmu::service::test
