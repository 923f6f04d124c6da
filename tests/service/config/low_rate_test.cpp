// LowRateGate: which samples also go to pmu/low_rate/* (one per device, packet and period).
#include <gtest/gtest.h>

#include "pmu/config/low_rate.hpp"

namespace pmu::service {
namespace {

using namespace std::chrono_literals;
using TimePoint = LowRateGate::TimePoint;

const TimePoint t0 = TimePoint{} + 1700000000s;

TEST(LowRateGate, AStreamEvery100msWithJitterGivesOneSamplePerSecond) {
  LowRateGate gate(1000ms);
  int passed = 0;
  // 100 s of a PMU streaming every 0.1 s, each frame up to 30 ms late.
  for (int i = 0; i < 1000; ++i) {
    const auto jitter = std::chrono::milliseconds((i * 37) % 31);
    if (gate.due("can0", 1, 0, t0 + i * 100ms + jitter)) ++passed;
  }
  // "A period after the last one" would give one per 1.1 s (91); on schedule it is 100.
  EXPECT_EQ(passed, 100);
}

TEST(LowRateGate, TheFirstSampleOfEachDeviceAndPacketPasses) {
  LowRateGate gate(1000ms);
  EXPECT_TRUE(gate.due("can0", 1, 0, t0));
  EXPECT_FALSE(gate.due("can0", 1, 0, t0 + 100ms));
  EXPECT_TRUE(gate.due("can0", 1, 1, t0 + 100ms));  // another packet
  EXPECT_TRUE(gate.due("can0", 2, 0, t0 + 100ms));  // another address
  EXPECT_TRUE(gate.due("can1", 1, 0, t0 + 100ms));  // another bus
  EXPECT_FALSE(gate.due("can0", 1, 0, t0 + 999ms));
  EXPECT_TRUE(gate.due("can0", 1, 0, t0 + 1000ms));
}

TEST(LowRateGate, AfterASilenceTheNextSamplePassesAtOnce) {
  LowRateGate gate(1000ms);
  EXPECT_TRUE(gate.due("can0", 1, 0, t0));
  EXPECT_TRUE(gate.due("can0", 1, 0, t0 + 5300ms));   // the PMU was silent for 5 s
  EXPECT_FALSE(gate.due("can0", 1, 0, t0 + 5400ms));  // and the schedule restarts from here
  EXPECT_TRUE(gate.due("can0", 1, 0, t0 + 6300ms));
}

TEST(LowRateGate, PeriodZeroIsOffAndAnUnknownPacketNeverPasses) {
  LowRateGate off(0ms);
  EXPECT_FALSE(off.enabled());
  EXPECT_FALSE(off.due("can0", 1, 0, t0));
  LowRateGate on(1000ms);
  EXPECT_FALSE(on.due("can0", 1, LowRateGate::kPackets, t0));
}

}  // namespace
}  // namespace pmu::service
