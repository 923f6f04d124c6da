// codec::CanFrame <-> struct can_frame: the worked examples of linux_frame.hpp.

#include <gtest/gtest.h>

#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/clock.hpp"
#include "pmu/transport/linux_frame.hpp"

namespace pmu::transport {
namespace {

TEST(LinuxFrame, ExtendedPmuFrame) {
  codec::CanFrame frame;
  frame.id = 0x1E000001;
  frame.extended = true;
  frame.length = 2;
  frame.data = {0xFA, 0x0A};
  const struct can_frame raw = to_linux(frame);
  EXPECT_EQ(raw.can_id, 0x9E000001u);
  EXPECT_EQ(raw.len, 2);
  EXPECT_EQ(raw.data[0], 0xFA);
  EXPECT_EQ(raw.data[1], 0x0A);
  const auto back = from_linux(raw);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, frame);
}

TEST(LinuxFrame, StandardEmptyFrame) {
  codec::CanFrame frame;
  frame.id = 0x202;
  const struct can_frame raw = to_linux(frame);
  EXPECT_EQ(raw.can_id, 0x202u);
  EXPECT_EQ(raw.len, 0);
  const auto back = from_linux(raw);
  ASSERT_TRUE(back.has_value());
  EXPECT_FALSE(back->extended);
  EXPECT_EQ(back->id, 0x202u);
}

TEST(LinuxFrame, RemoteFlagRoundTrips) {
  codec::CanFrame frame;
  frame.id = 0x1E310001;
  frame.extended = true;
  frame.remote = true;
  EXPECT_EQ(to_linux(frame).can_id, 0x1E310001u | CAN_EFF_FLAG | CAN_RTR_FLAG);
  const auto back = from_linux(to_linux(frame));
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(back->remote);
  EXPECT_EQ(back->id, 0x1E310001u);
}

TEST(LinuxFrame, ErrorFramesAndOverlongRecordsAreNotDataFrames) {
  struct can_frame error {};
  error.can_id = CAN_ERR_FLAG | 0x40;
  EXPECT_FALSE(from_linux(error).has_value());
  struct can_frame overlong {};
  overlong.can_id = 0x123;
  overlong.len = 9;
  EXPECT_FALSE(from_linux(overlong).has_value());
}

TEST(CanBusTypes, NamesMatchTheContract) {
  // interface.md, Health.bus_state.
  EXPECT_EQ(to_string(BusState::Up), "UP");
  EXPECT_EQ(to_string(BusState::ErrorWarning), "ERROR_WARNING");
  EXPECT_EQ(to_string(BusState::ErrorPassive), "ERROR_PASSIVE");
  EXPECT_EQ(to_string(BusState::BusOff), "BUS_OFF");
  EXPECT_EQ(to_string(BusState::Down), "DOWN");
}

TEST(CanBusTypes, SendableFrames) {
  codec::CanFrame frame;
  frame.id = 0x7FF;
  EXPECT_TRUE(is_sendable(frame));
  frame.id = 0x800;
  EXPECT_FALSE(is_sendable(frame));
  frame.extended = true;
  EXPECT_TRUE(is_sendable(frame));
  frame.id = 0x20000000;
  EXPECT_FALSE(is_sendable(frame));
  frame.id = 1;
  frame.length = 9;
  EXPECT_FALSE(is_sendable(frame));
}

TEST(ManualClockTest, BothReadingsMoveTogetherAndOnlyWhenTold) {
  ManualClock manual;
  const auto steady = manual.steady_now();
  const auto wall = manual.system_now();
  EXPECT_EQ(manual.steady_now(), steady);
  manual.advance(std::chrono::milliseconds{1500});
  EXPECT_EQ(manual.steady_now() - steady, std::chrono::milliseconds{1500});
  EXPECT_EQ(manual.system_now() - wall, std::chrono::milliseconds{1500});
}

}  // namespace
}  // namespace pmu::transport
