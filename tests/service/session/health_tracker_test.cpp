// Health from frame age (health_tracker.hpp) with a fake clock: the thresholds, a device
// never heard from, recovery, and when the report is due.
#include <gtest/gtest.h>

#include "pmu/session/health_tracker.hpp"

namespace pmu::service::health_tracker_test {
namespace {

using namespace std::chrono_literals;
using Time = std::chrono::steady_clock::time_point;

const Time t0 = Time{} + 1h;

Timeouts thresholds() {
  Timeouts t;
  t.stale_periods = 3;
  t.offline_periods = 10;
  return t;
}

TEST(HealthTracker, TheAgeOfTheLastFrameGivesTheState) {
  struct Case {
    std::chrono::milliseconds age;
    std::chrono::milliseconds period;
    HealthState state;
  };
  const Case cases[] = {
      {0ms, 1000ms, HealthState::Online},      {3000ms, 1000ms, HealthState::Online},
      {3001ms, 1000ms, HealthState::Stale},    {10000ms, 1000ms, HealthState::Stale},
      {10001ms, 1000ms, HealthState::Offline}, {1600ms, 500ms, HealthState::Stale},
      {5001ms, 500ms, HealthState::Offline},   {29000ms, 3000ms, HealthState::Stale},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(testing::Message() << c.age.count() << " ms at period " << c.period.count() << " ms");
    HealthTracker h(t0, thresholds());
    h.on_frame(t0);
    h.update(t0 + c.age, c.period, false);
    EXPECT_EQ(h.report().state, c.state);
    EXPECT_DOUBLE_EQ(h.report().last_frame_age, std::chrono::duration<double>(c.age).count());
  }
}

TEST(HealthTracker, ADeviceNeverHeardFromIsUnknownThenOffline) {
  HealthTracker h(t0, thresholds());
  h.update(t0 + 10s, 1000ms, false);
  EXPECT_EQ(h.report().state, HealthState::Unknown);
  EXPECT_EQ(h.report().last_frame_age, -1);
  h.update(t0 + 10001ms, 1000ms, false);
  EXPECT_EQ(h.report().state, HealthState::Offline);
}

TEST(HealthTracker, OnlineStaleOfflineAndBackOnline) {
  HealthTracker h(t0, thresholds());
  h.on_frame(t0);
  EXPECT_TRUE(h.update(t0, 1000ms, false).changed);
  EXPECT_EQ(h.report().state, HealthState::Online);
  EXPECT_TRUE(h.update(t0 + 4s, 1000ms, false).changed);
  EXPECT_EQ(h.report().state, HealthState::Stale);
  EXPECT_TRUE(h.update(t0 + 11s, 1000ms, false).changed);
  EXPECT_TRUE(h.offline());
  h.on_frame(t0 + 12s);
  EXPECT_TRUE(h.offline()) << "until the next update: the caller counts the reconnect";
  h.on_reconnect();
  EXPECT_TRUE(h.update(t0 + 12s, 1000ms, false).changed);
  EXPECT_EQ(h.report().state, HealthState::Online);
  EXPECT_EQ(h.report().reconnects, 1u);
  EXPECT_EQ(h.report().frames_received, 2u);
}

TEST(HealthTracker, TheReportIsDueOnChangeOnForceAndOnceASecond) {
  HealthTracker h(t0, thresholds());
  h.on_frame(t0);
  EXPECT_TRUE(h.update(t0, 1000ms, false).publish) << "first update: a change (UNKNOWN -> ONLINE)";
  EXPECT_FALSE(h.update(t0 + 500ms, 1000ms, false).publish);
  EXPECT_TRUE(h.update(t0 + 500ms, 1000ms, true).publish) << "forced";
  EXPECT_FALSE(h.update(t0 + 1400ms, 1000ms, false).publish);
  EXPECT_TRUE(h.update(t0 + 1500ms, 1000ms, false).publish) << "a second after the last";
}

TEST(HealthTracker, CountersAndBusStateTravelInTheReport) {
  HealthTracker h(t0, thresholds());
  h.on_sent();
  h.on_sent();
  h.on_timeout();
  h.on_decode_error();
  transport::BusCounters c;
  c.error_frames = 4;
  c.rx_drops = 5;
  h.on_bus_counters(c);
  EXPECT_FALSE(h.on_bus_state(transport::BusState::Up)) << "already up";
  EXPECT_TRUE(h.on_bus_state(transport::BusState::Down));
  const auto& r = h.report();
  EXPECT_EQ(r.frames_sent, 2u);
  EXPECT_EQ(r.timeouts, 1u);
  EXPECT_EQ(r.decode_errors, 1u);
  EXPECT_EQ(r.bus_errors, 4u);
  EXPECT_EQ(r.rx_dropped, 5u);
  EXPECT_EQ(r.bus_state, transport::BusState::Down);
}

// The log's words for the age: a device never heard (age -1) has none to print.
TEST(HealthTracker, TheLastFrameInWords) {
  const std::pair<double, const char*> cases[] = {{-1, "no frame yet"},
                                                  {0.04, "last frame 0.0 s ago"},
                                                  {3.5, "last frame 3.5 s ago"},
                                                  {61.26, "last frame 61.3 s ago"}};
  for (const auto& [age, text] : cases) EXPECT_EQ(last_frame_text(age), text) << age;
}

}  // namespace
}  // namespace pmu::service::health_tracker_test
