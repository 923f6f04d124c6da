#include "schedule/rate_scheduler.hpp"

#include <gtest/gtest.h>

#include "pmu/mavlink/constants.hpp"
#include "program/settings.hpp"

namespace pmu::mavlink_bridge {
namespace {

using namespace std::chrono_literals;
using Ids = std::vector<std::uint32_t>;
namespace result = pmu::mavlink::mav_result;

const RateScheduler::Clock::time_point t0{};

RateScheduler two_streams() { return RateScheduler({{0, 1s}, {147, 2s}, {376, 0s}}); }

TEST(RateScheduler, DueAtStartThenEveryInterval) {
  auto s = two_streams();
  EXPECT_EQ(s.due(t0), (Ids{0, 147})) << "a disabled stream (0 s) is never due";
  EXPECT_EQ(s.due(t0 + 500ms), Ids{});
  EXPECT_EQ(s.due(t0 + 1s), (Ids{0}));
  EXPECT_EQ(s.due(t0 + 2s), (Ids{0, 147}));
  EXPECT_EQ(s.due(t0 + 2s), Ids{}) << "each once";
}

TEST(RateScheduler, LateLoopKeepsTheRateWithoutBurst) {
  auto s = two_streams();
  s.due(t0);
  EXPECT_EQ(s.due(t0 + 1100ms), (Ids{0}));
  EXPECT_EQ(s.due(t0 + 2s), (Ids{0, 147})) << "due at 2 s, not 2.1 s";
  EXPECT_EQ(s.due(t0 + 10s), (Ids{0, 147})) << "far behind: once";
  EXPECT_EQ(s.due(t0 + 10500ms), Ids{});
  EXPECT_EQ(s.due(t0 + 11s), (Ids{0}));
}

// The program's streams are its settings' intervals: RELAY_STATUS at 1 Hz by default, and
// SET_MESSAGE_INTERVAL reaches it as any other stream.
TEST(RateScheduler, RelayStatusStreamedByDefault) {
  RateScheduler s(Settings{}.intervals);
  EXPECT_EQ(s.interval_us(376), 1000000);
  EXPECT_EQ(s.set_interval(376, 200000, t0), result::kAccepted);
  EXPECT_EQ(s.interval_us(376), 200000);
  EXPECT_EQ(s.set_interval(376, -1, t0), result::kAccepted);
  EXPECT_EQ(s.interval_us(376), 0) << "stopped";
  EXPECT_EQ(s.set_interval(376, 0, t0), result::kAccepted);
  EXPECT_EQ(s.interval_us(376), 1000000) << "the default again";
}

TEST(RateScheduler, SetMessageInterval) {
  auto s = two_streams();
  s.due(t0);
  EXPECT_EQ(s.set_interval(147, 500000, t0 + 100ms), result::kAccepted);
  EXPECT_EQ(s.interval_us(147), 500000);
  EXPECT_EQ(s.due(t0 + 100ms), (Ids{147})) << "the new rate starts at once";
  EXPECT_EQ(s.due(t0 + 600ms), (Ids{147}));
  EXPECT_EQ(s.set_interval(147, -1, t0 + 700ms), result::kAccepted);
  EXPECT_EQ(s.interval_us(147), 0);
  EXPECT_EQ(s.due(t0 + 5s), (Ids{0})) << "disabled";
  EXPECT_EQ(s.set_interval(147, 0, t0 + 5s), result::kAccepted);
  EXPECT_EQ(s.interval_us(147), 2000000) << "0 restores the default";
  EXPECT_EQ(s.set_interval(376, 1000000, t0 + 5s), result::kAccepted) << "a stream off by default can be enabled";
  EXPECT_EQ(s.due(t0 + 5s), (Ids{147, 376}));
}

TEST(RateScheduler, SetMessageIntervalRefusals) {
  auto s = two_streams();
  const struct {
    const char* name;
    float id;
    float interval;
    std::uint8_t result;
  } cases[] = {
      {"not streamed here", 33, 1000000, result::kUnsupported},
      {"negative id", -1, 1000000, result::kUnsupported},
      {"fractional id", 147.5F, 1000000, result::kUnsupported},
      {"NaN id", std::numeric_limits<float>::quiet_NaN(), 1000000, result::kUnsupported},
      {"interval below -1", 147, -2, result::kDenied},
      {"NaN interval", 147, std::numeric_limits<float>::quiet_NaN(), result::kDenied},
      {"fractional interval", 147, 0.5F, result::kDenied},
  };
  for (const auto& c : cases) EXPECT_EQ(s.set_interval(c.id, c.interval, t0), c.result) << c.name;
  EXPECT_EQ(s.interval_us(147), 2000000) << "a refused request changes nothing";
  EXPECT_EQ(s.interval_us(33), -1);
}

}  // namespace
}  // namespace pmu::mavlink_bridge
