// SocketCanBus driven through one end of a socketpair (SocketCanBus::adopt), the way the
// tests here reach the SocketCAN receive/send code on a kernel without CAN. Failures a CAN
// interface produces (ENETDOWN, ENOBUFS, kernel drops) come from FakeSocketOps.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>

#include "fake_socket_ops.hpp"
#include "pmu/transport/event_loop.hpp"
#include "pmu/transport/socketcan_bus.hpp"
#include "test_support.hpp"

namespace pmu::transport::test {
namespace {

using codec::PacketId;
using std::chrono::milliseconds;

class AdoptedBus : public ::testing::Test {
 protected:
  std::unique_ptr<SocketCanBus> adopt(SocketOps& ops, SocketCanOptions options = {}) {
    auto pair = make_socket_pair();
    peer_ = std::move(pair.test_end);
    return SocketCanBus::adopt(std::move(pair.bus_end), "test0", options, clock_, ops);
  }
  int peer() const { return peer_.get(); }

  ManualClock clock_;
  FakeSocketOps fake_{&clock_};
  UniqueFd peer_;
  RecordingHandler handler_;
};

TEST_F(AdoptedBus, OneDrainDeliversEveryPendingFrameAndLeavesTheFdQuiet) {
  auto bus = adopt(system_socket_ops());
  // Registered once, as the service's loop does; a turn of it counts the bus's wake-ups.
  EventLoop loop{clock_, "test"};
  int wakeups = 0;
  ASSERT_EQ(loop.watch(bus->fd(), EventLoop::kReadable, [&](std::uint32_t) { ++wakeups; }), 0);
  loop.run_once(milliseconds{0});
  EXPECT_EQ(wakeups, 0) << "nothing pending yet";

  constexpr int kFrames = 1000;
  for (int i = 0; i < kFrames; ++i) {
    const auto address = static_cast<std::uint16_t>(i);
    write_frame(peer(), pmu_raw(PacketId::Voltages, address,
                                {static_cast<std::uint8_t>(i & 0xFF), static_cast<std::uint8_t>(i >> 8)}));
  }
  loop.run_once(milliseconds{0});
  ASSERT_EQ(wakeups, 1);

  const DrainResult result = bus->drain(handler_);
  EXPECT_EQ(result.frames, static_cast<std::size_t>(kFrames));
  ASSERT_EQ(handler_.frames.size(), static_cast<std::size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    const auto address = static_cast<std::uint16_t>(i);
    EXPECT_EQ(handler_.frames[static_cast<std::size_t>(i)].frame,
              pmu_frame(PacketId::Voltages, address,
                        {static_cast<std::uint8_t>(i & 0xFF), static_cast<std::uint8_t>(i >> 8)}))
        << "frame " << i << " out of order or altered";
  }
  loop.run_once(milliseconds{0});
  EXPECT_EQ(wakeups, 1) << "drain must leave nothing behind";
  EXPECT_EQ(bus->counters().rx_frames, static_cast<std::uint64_t>(kFrames));
}

TEST_F(AdoptedBus, FramesOfForeignIdsAreDroppedInUserspace) {
  // A socketpair has no kernel filter: the userspace check is all that stands between
  // foreign traffic and the service.
  auto bus = adopt(system_socket_ops());
  EXPECT_FALSE(bus->report().kernel_filters);
  write_frame(peer(), pmu_raw(PacketId::Voltages, 1, {0xFA, 0x0A}));
  write_frame(peer(), standard_raw(0x1F000001 | CAN_EFF_FLAG));  // 29-bit, group 0x1F
  write_frame(peer(), standard_raw(0x202));                      // CANopen, not asked for
  write_frame(peer(), standard_raw(0x01E));                      // 11-bit: never a PMU frame
  write_frame(peer(), pmu_raw(PacketId::Status, 0xFFFF));

  bus->drain(handler_);
  ASSERT_EQ(handler_.frames.size(), 2u);
  EXPECT_EQ(handler_.frames[0].frame, pmu_frame(PacketId::Voltages, 1, {0xFA, 0x0A}));
  EXPECT_EQ(handler_.frames[1].frame, pmu_frame(PacketId::Status, 0xFFFF));
  EXPECT_EQ(bus->counters().rx_filtered, 3u);
  EXPECT_EQ(bus->counters().rx_frames, 2u);
}

TEST_F(AdoptedBus, CanopenIdsPassWhenAskedFor) {
  SocketCanOptions options;
  options.filters = default_filters(true);
  auto bus = adopt(system_socket_ops(), options);
  write_frame(peer(), standard_raw(0x202, {1, 2}));
  write_frame(peer(), standard_raw(0x4E5));  // just below the MPPT blocks
  bus->drain(handler_);
  ASSERT_EQ(handler_.frames.size(), 1u);
  EXPECT_EQ(handler_.frames[0].frame.id, 0x202u);
  EXPECT_FALSE(handler_.frames[0].frame.extended);
  EXPECT_EQ(bus->counters().rx_filtered, 1u);
}

// linux/can/error.h: which error frames move the bus to which state.
struct ErrorFrameCase {
  const char* what;
  canid_t error_class;
  std::uint8_t controller_status;
  BusState expected;
};

TEST_F(AdoptedBus, ErrorFramesSetTheBusState) {
  auto bus = adopt(system_socket_ops());
  const ErrorFrameCase cases[] = {
      {"tx warning", CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING, BusState::ErrorWarning},
      {"rx passive", CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE, BusState::ErrorPassive},
      {"rx overflow only: no state news", CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW, BusState::ErrorPassive},
      {"bus off", CAN_ERR_BUSOFF, 0, BusState::BusOff},
      {"tx timeout: no state news", CAN_ERR_TX_TIMEOUT, 0, BusState::BusOff},
      {"restarted", CAN_ERR_RESTARTED, 0, BusState::Up},
      {"rx warning", CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING, BusState::ErrorWarning},
      {"back to error active", CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE, BusState::Up},
  };
  std::uint64_t expected_error_frames = 0;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const BusState before = bus->state();
    handler_.clear();
    write_frame(peer(), error_raw(c.error_class, c.controller_status));
    bus->drain(handler_);
    EXPECT_EQ(bus->state(), c.expected);
    EXPECT_TRUE(handler_.frames.empty()) << "error frames are not data";
    ASSERT_FALSE(handler_.events.empty());
    EXPECT_EQ(handler_.events[0].kind, BusEventKind::ErrorFrame);
    EXPECT_EQ(handler_.events[0].error_class, c.error_class);
    EXPECT_EQ(handler_.events[0].error_data[1], c.controller_status);
    if (before != c.expected) {
      ASSERT_EQ(handler_.events.size(), 2u);
      EXPECT_EQ(handler_.events[1].kind, BusEventKind::StateChanged);
      EXPECT_EQ(handler_.events[1].previous, before);
      EXPECT_EQ(handler_.events[1].state, c.expected);
    } else {
      EXPECT_EQ(handler_.events.size(), 1u);
    }
    EXPECT_EQ(bus->counters().error_frames, ++expected_error_frames);
  }
}

TEST_F(AdoptedBus, EnetdownReportsDownKeepsTheSocketAndResumesOnTraffic) {
  auto bus = adopt(fake_);
  fake_.receive_errors.push_back(ENETDOWN);
  write_frame(peer(), pmu_raw(PacketId::Voltages, 1));  // makes the fd readable

  bus->drain(handler_);
  EXPECT_EQ(bus->state(), BusState::Down);
  EXPECT_TRUE(bus->has_socket()) << "ENETDOWN keeps the socket: it works again on link up";
  ASSERT_EQ(handler_.kinds(), (std::vector<BusEventKind>{BusEventKind::SocketError, BusEventKind::StateChanged}));
  EXPECT_EQ(handler_.events[0].error, ENETDOWN);
  EXPECT_EQ(handler_.events[1].state, BusState::Down);
  EXPECT_TRUE(handler_.frames.empty());

  // The frame that was already queued is the sign that traffic flows again.
  handler_.clear();
  bus->drain(handler_);
  EXPECT_EQ(bus->state(), BusState::Up);
  ASSERT_EQ(handler_.kinds(), (std::vector<BusEventKind>{BusEventKind::StateChanged}));
  EXPECT_EQ(handler_.events[0].previous, BusState::Down);
  ASSERT_EQ(handler_.frames.size(), 1u);
}

TEST_F(AdoptedBus, SendOnADownLinkFailsFastAndASuccessfulSendBringsItBack) {
  auto bus = adopt(fake_);
  fake_.send_errors.push_back(ENETDOWN);
  const SendResult failed = bus->send(pmu_frame(PacketId::Reset, 1), milliseconds{100});
  EXPECT_EQ(failed.status, SendStatus::Down);
  EXPECT_EQ(failed.error, ENETDOWN);
  EXPECT_TRUE(fake_.poll_timeouts.empty()) << "a down link is not waited for";
  EXPECT_EQ(bus->state(), BusState::Down);
  // Raised outside drain(): the fd must wake the loop to deliver it.
  EXPECT_TRUE(readable(bus->fd()));
  bus->drain(handler_);
  ASSERT_EQ(handler_.kinds(), (std::vector<BusEventKind>{BusEventKind::StateChanged}));
  EXPECT_EQ(handler_.events[0].state, BusState::Down);
  EXPECT_FALSE(readable(bus->fd()));

  EXPECT_TRUE(bus->send(pmu_frame(PacketId::Reset, 1), milliseconds{0}).ok());
  EXPECT_EQ(bus->state(), BusState::Up);
  EXPECT_EQ(bus->counters().tx_frames, 1u);
  EXPECT_EQ(bus->counters().tx_failures, 1u);
}

TEST_F(AdoptedBus, EnobufsWaitsForRoomUntilTheDeadlineThenFails) {
  auto bus = adopt(fake_);
  fake_.send_error_forever = ENOBUFS;
  const auto start = clock_.steady_now();

  const SendResult result = bus->send(pmu_frame(PacketId::EngineStop, 1), milliseconds{50});
  EXPECT_EQ(result.status, SendStatus::Timeout);
  EXPECT_EQ(result.error, ENOBUFS);
  // The fake poll moves the clock by each timeout it is given: the bus waited, in bounded
  // steps, until the deadline and no longer.
  EXPECT_EQ(clock_.steady_now() - start, milliseconds{50});
  ASSERT_FALSE(fake_.poll_timeouts.empty());
  for (const int timeout : fake_.poll_timeouts) {
    EXPECT_GT(timeout, 0);
    EXPECT_LE(timeout, 50);
  }
  EXPECT_EQ(bus->counters().tx_failures, 1u);
  EXPECT_EQ(bus->counters().tx_frames, 0u);
  EXPECT_FALSE(read_frame(peer()).has_value());
}

TEST_F(AdoptedBus, EnobufsThatClearsBeforeTheDeadlineSends) {
  auto bus = adopt(fake_);
  fake_.send_errors = {ENOBUFS, ENOBUFS};
  // POLLOUT reports room at once each time (it tracks the socket buffer, not the device
  // queue ENOBUFS is about), so the bus pauses 1 ms before each retry instead of spinning.
  fake_.poll_results = {1, 1};
  const auto start = clock_.steady_now();
  const SendResult result = bus->send(pmu_frame(PacketId::EngineStop, 7), milliseconds{100});
  EXPECT_EQ(result.status, SendStatus::Sent);
  EXPECT_EQ(fake_.poll_timeouts, (std::vector<int>{100, 1, 99, 1}));
  EXPECT_EQ(clock_.steady_now() - start, milliseconds{2});
  const auto sent = read_frame(peer());
  ASSERT_TRUE(sent.has_value());
  EXPECT_EQ(sent->can_id, codec::make_id(PacketId::EngineStop, 7) | CAN_EFF_FLAG);
  EXPECT_EQ(bus->counters().tx_failures, 0u);
}

TEST_F(AdoptedBus, FullQueueWithNoWaitFailsAtOnce) {
  // A real EAGAIN: nobody reads the peer, so its queue fills.
  auto bus = adopt(system_socket_ops());
  SendResult result;
  int sent = 0;
  while ((result = bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0})).ok()) ++sent;
  EXPECT_GT(sent, 0);
  EXPECT_EQ(result.status, SendStatus::Timeout);
  EXPECT_EQ(result.error, EAGAIN);
  EXPECT_EQ(bus->counters().tx_frames, static_cast<std::uint64_t>(sent));
  EXPECT_EQ(bus->counters().tx_failures, 1u);
}

TEST_F(AdoptedBus, KernelDropTotalsBecomeTheDropCounter) {
  auto bus = adopt(fake_);
  // SO_RXQ_OVFL carries the socket's running total, not a per-message count.
  const std::uint32_t totals[] = {5, 12, 12, 0xFFFFFFFEu, 1};
  const std::uint64_t expected[] = {5, 12, 12, 0xFFFFFFFEu, std::uint64_t{0xFFFFFFFEu} + 3};
  for (std::size_t i = 0; i < std::size(totals); ++i) {
    fake_.next_drop_total = totals[i];
    write_frame(peer(), pmu_raw(PacketId::Voltages, 1));
    bus->drain(handler_);
    EXPECT_EQ(bus->counters().rx_drops, expected[i]) << "after total " << totals[i];
  }
  EXPECT_EQ(handler_.frames.size(), std::size(totals)) << "drop news does not cost the frame";
}

TEST_F(AdoptedBus, FramesCarryKernelReceiveTimestamps) {
  if (const auto why = socket_options_missing()) GTEST_SKIP() << *why;
  auto bus = adopt(system_socket_ops());
  EXPECT_TRUE(bus->report().kernel_timestamps);
  EXPECT_TRUE(bus->report().drop_counting);
  EXPECT_GE(bus->report().receive_buffer_bytes, 1 << 20);

  const auto before = std::chrono::system_clock::now();
  write_frame(peer(), pmu_raw(PacketId::Voltages, 1));
  bus->drain(handler_);
  const auto after = std::chrono::system_clock::now();
  ASSERT_EQ(handler_.frames.size(), 1u);
  const ReceivedFrame& got = handler_.frames[0];
  EXPECT_TRUE(got.kernel_timestamp);
  // The kernel's clock, not the ManualClock the bus was given (which reads 2023).
  EXPECT_GE(got.timestamp, before);
  EXPECT_LE(got.timestamp, after);
  EXPECT_NE(got.timestamp, clock_.system_now());
}

TEST_F(AdoptedBus, RecordsThatAreNotCanFramesAreCountedAndSkipped) {
  auto bus = adopt(system_socket_ops());
  const unsigned char short_record[5] = {1, 2, 3, 4, 5};
  write_record(peer(), short_record, sizeof(short_record));
  struct can_frame too_long = pmu_raw(PacketId::Voltages, 1);
  too_long.len = 12;
  write_frame(peer(), too_long);
  write_frame(peer(), pmu_raw(PacketId::Voltages, 2));

  bus->drain(handler_);
  EXPECT_EQ(bus->counters().rx_invalid, 2u);
  ASSERT_EQ(handler_.frames.size(), 1u);
  EXPECT_EQ(handler_.frames[0].frame.id, codec::make_id(PacketId::Voltages, 2));
}

TEST_F(AdoptedBus, PeerClosingEndsTheBusInsteadOfSpinning) {
  auto bus = adopt(system_socket_ops());
  peer_.reset();
  ASSERT_TRUE(readable(bus->fd()));
  bus->drain(handler_);
  EXPECT_EQ(bus->state(), BusState::Down);
  EXPECT_FALSE(bus->has_socket());
  EXPECT_FALSE(readable(bus->fd())) << "a dead fd left registered would wake the loop forever";
  EXPECT_EQ(bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0}).status, SendStatus::NoDevice);
  // An adopted fd has no interface to reopen.
  bus->maintain(clock_.steady_now() + std::chrono::hours{1});
  EXPECT_FALSE(bus->has_socket());
  EXPECT_EQ(bus->counters().reopens, 0u);
}

TEST_F(AdoptedBus, SentFramesReachThePeerAsLinuxRecords) {
  auto bus = adopt(system_socket_ops());
  ASSERT_TRUE(bus->send(pmu_frame(PacketId::Outputs, 3, {0x05}), milliseconds{0}).ok());
  codec::CanFrame standard;
  standard.id = 0x123;
  standard.length = 2;
  standard.data = {0xAB, 0xCD};
  ASSERT_TRUE(bus->send(standard, milliseconds{0}).ok());

  const auto first = read_frame(peer());
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->can_id, 0x1E200003u | CAN_EFF_FLAG);
  EXPECT_EQ(first->len, 1);
  EXPECT_EQ(first->data[0], 0x05);
  const auto second = read_frame(peer());
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->can_id, 0x123u);
  EXPECT_EQ(second->len, 2);
  EXPECT_EQ(bus->counters().tx_frames, 2u);
}

TEST_F(AdoptedBus, InvalidFramesAreRefusedBeforeTheSocket) {
  auto bus = adopt(system_socket_ops());
  codec::CanFrame too_big_id;
  too_big_id.id = 0x800;  // 12 bits in an 11-bit frame
  codec::CanFrame too_long = pmu_frame(PacketId::Voltages, 1);
  too_long.length = 9;
  EXPECT_EQ(bus->send(too_big_id, milliseconds{0}).status, SendStatus::InvalidFrame);
  EXPECT_EQ(bus->send(too_long, milliseconds{0}).status, SendStatus::InvalidFrame);
  EXPECT_FALSE(read_frame(peer()).has_value());
  EXPECT_EQ(bus->counters().tx_failures, 2u);
}

TEST(AdoptBus, RefusesSomethingThatIsNotASocket) {
  int ends[2];
  ASSERT_EQ(::pipe(ends), 0);
  UniqueFd write_end{ends[1]};
  ManualClock clock;
  EXPECT_THROW(SocketCanBus::adopt(UniqueFd{ends[0]}, "pipe0", {}, clock), std::system_error);
  EXPECT_THROW(SocketCanBus::adopt(UniqueFd{}, "none0", {}, clock), std::system_error);
}

}  // namespace
}  // namespace pmu::transport::test
