// A hot standby reads the bus owner's replies on pmu/command_reply over real Fast DDS
// (DdsCommandEndpoint::follow_peer_replies, design.md "Commands across a failover"): the
// owner's reply settles the request it recorded, so after taking over a resend is answered with
// that reply and nothing runs; its own reply writer's samples are no peer's.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <vector>

#include "pmu/dds/dds_context.hpp"
#include "pmu/dds_settings/vehicle.hpp"
#include "pmu/dispatch/command_service.hpp"
#include "pmu/endpoints/dds_commands.hpp"
#include "pmu/transport/clock.hpp"
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

}  // namespace
}  // namespace pmu::service::test
