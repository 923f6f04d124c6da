// SlowLinkHint (slow_link_hint.hpp, interface.md 7.3): said once, after resends from two
// senders that came SlowLinkHint::kReplyOut or longer after their reply; never when quiet.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "pmu/dispatch/slow_link_hint.hpp"

namespace pmu::service::test {
namespace {

using std::chrono::milliseconds;

struct Resend {
  const char* sender;
  milliseconds since_reply;
  bool hint;  // what resend() returns
};

struct Case {
  const char* what;
  bool quiet;
  std::vector<Resend> resends;
};

TEST(SlowLinkHint, SaysItOnceAfterLateResendsOfTwoSenders) {
  const Case cases[] = {
      {"two senders, each a reply out for most of a second",
       false,
       {{"a", milliseconds(900), false}, {"b", milliseconds(800), true}}},
      {"at the threshold counts", false, {{"a", milliseconds(300), false}, {"b", milliseconds(300), true}}},
      {"once only",
       false,
       {{"a", milliseconds(900), false}, {"b", milliseconds(900), true}, {"c", milliseconds(900), false}}},
      {"one sender's late resends are one client's late match",
       false,
       {{"a", milliseconds(900), false}, {"a", milliseconds(900), false}, {"a", milliseconds(2000), false}}},
      {"a resend soon after its reply: the service was slow, not the link",
       false,
       {{"a", milliseconds(299), false}, {"b", milliseconds(100), false}, {"c", milliseconds(0), false}}},
      {"the early ones do not count towards the two",
       false,
       {{"a", milliseconds(100), false}, {"b", milliseconds(900), false}, {"a", milliseconds(900), true}}},
      {"a configured link never hints", true, {{"a", milliseconds(900), false}, {"b", milliseconds(900), false}}},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.what);
    SlowLinkHint hint;
    if (k.quiet) hint.quiet();
    for (const auto& r : k.resends) EXPECT_EQ(hint.resend(r.sender, r.since_reply), r.hint) << r.sender;
  }
}

}  // namespace
}  // namespace pmu::service::test
