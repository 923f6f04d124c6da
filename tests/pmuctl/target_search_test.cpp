// A command without --bus and --address goes to the vehicle's one PMU. A PMU whose address
// changed while the command looked for it is one PMU, not two: its old key's OFFLINE sample
// and disposal come 250 ms apart (DeviceSession::kGoneDelay), and the search waits for it.
#include <gtest/gtest.h>

#include <chrono>
#include <set>
#include <vector>

#include "pmuctl/call/target_search.hpp"

namespace pmu::tools::target_search_test {

using namespace std::chrono_literals;
using Clock = TargetSearch::Clock;
using Pmu = TargetSearch::Pmu;

enum class Event { Online, Offline, Gone, Poll };

struct Step {
  int at_ms;
  Event event;
  std::uint16_t address;  // of sim/ADDRESS; ignored for Poll
  bool settled;           // settled() right after this step
};

struct Case {
  const char* what;
  std::vector<Step> steps;
  std::set<Pmu> pmus;  // what the search holds at the end
};

const Pmu kAt1{"sim", 1}, kAt7{"sim", 7};

const Case kCases[] = {
    {"one PMU: settled 300 ms after the burst",
     {{0, Event::Online, 1, false}, {299, Event::Poll, 0, false}, {300, Event::Poll, 0, true}},
     {kAt1}},
    {"moved during the quiet time: the old key's disposal is waited for, the new key is meant",
     {{0, Event::Online, 1, false},
      {200, Event::Offline, 1, false},
      {200, Event::Online, 7, false},
      {300, Event::Poll, 0, false},
      {450, Event::Gone, 1, true}},
     {kAt7}},
    {"moved before the search was matched: the old key's report and the new one in one burst",
     {{0, Event::Offline, 1, false},
      {0, Event::Online, 7, false},
      {250, Event::Gone, 1, false},
      {300, Event::Poll, 0, true}},
     {kAt7}},
    {"two PMUs, one of them offline and not disposed: ambiguous once its wait is over",
     {{0, Event::Online, 1, false},
      {0, Event::Offline, 7, false},
      {300, Event::Poll, 0, false},
      {999, Event::Poll, 0, false},
      {1000, Event::Poll, 0, true}},
     {kAt1, kAt7}},
    {"two PMUs online: ambiguous after the quiet time",
     {{0, Event::Online, 1, false}, {0, Event::Online, 7, false}, {300, Event::Poll, 0, true}},
     {kAt1, kAt7}},
    {"one PMU, offline: it is the one meant (a stop goes to a silent unit too)",
     {{0, Event::Offline, 1, false}, {300, Event::Poll, 0, true}},
     {kAt1}},
    {"an offline PMU back online: no wait for a disposal that will not come",
     {{0, Event::Offline, 7, false},
      {0, Event::Online, 1, false},
      {100, Event::Online, 7, false},
      {300, Event::Poll, 0, true}},
     {kAt1, kAt7}},
    {"an OFFLINE repeated later keeps the first one's time",
     {{0, Event::Online, 1, false},
      {0, Event::Offline, 7, false},
      {900, Event::Offline, 7, false},
      {1000, Event::Poll, 0, true}},
     {kAt1, kAt7}},
};

TEST(TargetSearch, AMovedPmuIsOnePmuAndTwoAreAmbiguous) {
  for (const auto& c : kCases) {
    SCOPED_TRACE(c.what);
    TargetSearch s(300ms, 1s);
    const auto t0 = Clock::time_point{} + 1h;
    for (const auto& st : c.steps) {
      const auto t = t0 + std::chrono::milliseconds(st.at_ms);
      const Pmu pmu{"sim", st.address};
      switch (st.event) {
        case Event::Online: s.seen(pmu, false, t); break;
        case Event::Offline: s.seen(pmu, true, t); break;
        case Event::Gone: s.gone(pmu); break;
        case Event::Poll: break;
      }
      if (st.event != Event::Gone) s.start(t0);
      EXPECT_EQ(s.settled(t), st.settled) << "at " << st.at_ms << " ms";
    }
    EXPECT_EQ(s.pmus(), c.pmus);
  }
}

TEST(TargetSearch, NothingHeardIsNeverSettled) {
  TargetSearch s(300ms, 1s);
  const auto t0 = Clock::time_point{} + 1h;
  EXPECT_FALSE(s.settled(t0 + 10s));
  s.start(t0 + 10s);
  EXPECT_FALSE(s.settled(t0 + 10s + 299ms));
  EXPECT_TRUE(s.settled(t0 + 10s + 300ms));
  EXPECT_TRUE(s.pmus().empty());
}

}  // namespace pmu::tools::target_search_test
