// The routes of the program's service requests under a fake clock: each reply to its owner
// by request id, whatever the owners' tags; unknown ids counted; resends until a reply.
#include <gtest/gtest.h>

#include "pmu/mavlink_commands/request_routes.hpp"

namespace pmu::mavlink_commands {
namespace request_routes_test {  // named: the unity build joins this file with others of its target
namespace {

using namespace std::chrono_literals;

const Time t0 = Time{} + 1h;

TEST(RequestRoutes, RepliesGoToTheOwnerOfTheIdWhenBothOwnersUseTheSameTag) {
  RequestRoutes r("pmu-mavlink-h-7-", 100);
  const auto set = r.open({Owner::Params, 1}, t0 + 10s, t0 + 12s, t0);
  const auto start = r.open({Owner::Commands, 1}, t0 + 10s, t0 + 40s, t0);
  EXPECT_EQ(set, "pmu-mavlink-h-7-100");
  EXPECT_EQ(start, "pmu-mavlink-h-7-101");
  // IN_PROGRESS keeps the route; the final reply closes it.
  auto got = r.on_reply(start, false);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->owner, Owner::Commands);
  EXPECT_EQ(got->tag, 1U);
  got = r.on_reply(set, true);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->owner, Owner::Params);
  EXPECT_FALSE(r.on_reply(set, true)) << "a second final reply (a resend's) has no route";
  got = r.on_reply(start, true);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->owner, Owner::Commands);
  EXPECT_EQ(r.open_count(), 0U);
  EXPECT_EQ(r.counters().replies_routed, 3U);
  EXPECT_EQ(r.counters().replies_unknown, 1U);
}

TEST(RequestRoutes, AnotherClientsReplyIsCountedApartAndOursUnknownIsCounted) {
  RequestRoutes r("pmu-mavlink-h-7-", 1);
  EXPECT_FALSE(r.on_reply("pmuctl-h-9-123", true));
  EXPECT_FALSE(r.on_reply("pmu-mavlink-h-7-55", true));
  EXPECT_EQ(r.counters().replies_others, 1U);
  EXPECT_EQ(r.counters().replies_unknown, 1U);
}

TEST(RequestRoutes, UnansweredRequestsAreWrittenAgainEachSecondUntilTheyExpire) {
  RequestRoutes r("p-", 1);
  const auto a = r.open({Owner::Commands, 1}, t0 + 2500ms, t0 + 12s, t0);
  const auto b = r.open({Owner::Params, 1}, t0 + 10s, t0 + 12s, t0);
  EXPECT_TRUE(r.due(t0 + 999ms).empty());
  EXPECT_EQ(r.due(t0 + 1s), (std::vector<std::string>{a, b}));
  EXPECT_TRUE(r.due(t0 + 1500ms).empty());
  (void)r.on_reply(b, false);  // IN_PROGRESS: matched, no more resends
  EXPECT_EQ(r.due(t0 + 2s), (std::vector<std::string>{a}));
  EXPECT_TRUE(r.due(t0 + 3s).empty()) << "a expired: nothing of it is written after its expiry";
  EXPECT_EQ(r.counters().resends, 3U);
  EXPECT_EQ(r.open_count(), 2U);
  (void)r.due(t0 + 12s);
  EXPECT_EQ(r.open_count(), 0U) << "forgotten once their owners gave up";
  EXPECT_FALSE(r.on_reply(a, true));
  EXPECT_EQ(r.counters().replies_unknown, 1U);
}

}  // namespace
}  // namespace request_routes_test
}  // namespace pmu::mavlink_commands
