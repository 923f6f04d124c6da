// pmuctl's state verbs settle only when every expected service (matched, or discovered and its
// endpoints still coming) has sent its state and the quiet time passed: a fleet's second
// service, found late over a slow link, is waited for.
#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "pmuctl/call/state_settle.hpp"

namespace pmu::tools::state_settle_test {

using namespace std::chrono_literals;
using Clock = StateSettle::Clock;

struct Step {
  int at_ms;
  std::size_t expected;  // writers matched + services whose writer is still being discovered
  std::size_t heard;
  bool settled;  // settled() right after this observation
};

struct Case {
  const char* what;
  std::vector<Step> steps;
};

const Case kCases[] = {
    {"one service: settled 300 ms after its burst",
     {{0, 1, 0, false}, {100, 1, 1, false}, {399, 1, 1, false}, {400, 1, 1, true}}},
    {"two services, the second heard 700 ms after the first: not settled in between",
     {{0, 2, 0, false},
      {50, 2, 1, false},
      {350, 2, 1, false},
      {700, 2, 1, false},
      {750, 2, 2, false},
      {1050, 2, 2, true}}},
    {"a second service discovered after the first was heard: the quiet time starts again",
     {{0, 1, 1, false}, {250, 2, 1, false}, {560, 2, 1, false}, {600, 2, 2, false}, {900, 2, 2, true}}},
    {"expected but silent (no state yet): never settled", {{0, 1, 0, false}, {1000, 1, 0, false}, {5000, 1, 0, false}}},
    {"nothing expected: never settled", {{0, 0, 0, false}, {5000, 0, 0, false}}},
    {"a heard service left: the rest suffices",
     {{0, 2, 2, false}, {300, 2, 2, true}, {400, 1, 2, false}, {700, 1, 2, true}}},
};

TEST(StateSettle, WaitsForEveryMatchedServiceAndAQuietTime) {
  for (const auto& c : kCases) {
    SCOPED_TRACE(c.what);
    StateSettle s(300ms);
    const auto t0 = Clock::time_point{} + 1h;
    for (const auto& st : c.steps) {
      const auto t = t0 + std::chrono::milliseconds(st.at_ms);
      s.observe(t, st.expected, st.heard);
      EXPECT_EQ(s.settled(t), st.settled)
          << "at " << st.at_ms << " ms, expected " << st.expected << ", heard " << st.heard;
    }
  }
}

}  // namespace pmu::tools::state_settle_test
