// LogThrottle: one report per interval, and the count of those held back in between.
#include <gtest/gtest.h>

#include "pmu/session/log_throttle.hpp"

namespace pmu::service {
namespace {

using namespace std::chrono_literals;

TEST(LogThrottle, OneReportPerIntervalWithTheCountHeldBack) {
  LogThrottle limit(5s);
  const LogThrottle::Clock::time_point t0{};
  ASSERT_EQ(limit.allow(t0), 0u) << "the first event is reported";
  EXPECT_EQ(limit.allow(t0 + 1s), std::nullopt);
  EXPECT_EQ(limit.allow(t0 + 4999ms), std::nullopt);
  EXPECT_EQ(limit.allow(t0 + 5s), 2u) << "reported again after the interval, saying 2 were held back";
  EXPECT_EQ(limit.allow(t0 + 11s), 0u);
}

}  // namespace
}  // namespace pmu::service
