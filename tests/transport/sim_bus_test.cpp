// SimulatedNetwork / SimBus: delivery to every other endpoint, injected-clock timestamps,
// the fault knobs, and use from an event loop on another thread.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "pmu/transport/event_loop.hpp"
#include "pmu/transport/sim_bus.hpp"
#include "test_support.hpp"

namespace pmu::transport::test {
namespace {

using codec::PacketId;
using std::chrono::milliseconds;

class Sim : public ::testing::Test {
 protected:
  ManualClock clock_;
  SimulatedNetwork network_{clock_};
};

TEST_F(Sim, AFrameReachesEveryOtherEndpointButNotTheSender) {
  auto a = network_.attach("a");
  auto b = network_.attach("b");
  auto c = network_.attach("c");
  EXPECT_FALSE(readable(b->fd()));

  const auto frame = pmu_frame(PacketId::Voltages, 1, {0xFA, 0x0A});
  ASSERT_TRUE(a->send(frame, milliseconds{0}).ok());
  EXPECT_FALSE(readable(a->fd())) << "no echo to the sender";
  EXPECT_TRUE(readable(b->fd()));
  EXPECT_TRUE(readable(c->fd()));

  for (auto* receiver : {b.get(), c.get()}) {
    RecordingHandler handler;
    EXPECT_EQ(receiver->drain(handler).frames, 1u);
    ASSERT_EQ(handler.frames.size(), 1u);
    EXPECT_EQ(handler.frames[0].frame, frame);
    EXPECT_FALSE(readable(receiver->fd())) << "drained: the eventfd is reset";
    EXPECT_EQ(receiver->counters().rx_frames, 1u);
  }
  RecordingHandler sender_side;
  EXPECT_EQ(a->drain(sender_side).frames, 0u);
  EXPECT_EQ(a->counters().tx_frames, 1u);
  EXPECT_EQ(a->counters().rx_frames, 0u);
}

TEST_F(Sim, TimestampsComeFromTheInjectedClockAtSendTime) {
  auto a = network_.attach("a");
  auto b = network_.attach("b");
  const auto t0 = clock_.system_now();
  a->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0});
  clock_.advance(milliseconds{250});
  a->send(pmu_frame(PacketId::Currents, 1), milliseconds{0});
  clock_.advance(milliseconds{999});  // draining late does not change when frames arrived

  RecordingHandler handler;
  b->drain(handler);
  ASSERT_EQ(handler.frames.size(), 2u);
  EXPECT_EQ(handler.frames[0].timestamp, t0);
  EXPECT_EQ(handler.frames[1].timestamp, t0 + milliseconds{250});
  EXPECT_FALSE(handler.frames[0].kernel_timestamp);
}

TEST_F(Sim, DownStopsTrafficAndEveryEndpointHearsOfIt) {
  auto a = network_.attach("a");
  auto b = network_.attach("b");
  network_.set_state(BusState::Down);
  EXPECT_EQ(a->state(), BusState::Down);
  EXPECT_TRUE(readable(a->fd()));
  EXPECT_TRUE(readable(b->fd()));

  const SendResult refused = a->send(pmu_frame(PacketId::Reset, 1), milliseconds{100});
  EXPECT_EQ(refused.status, SendStatus::Down);
  EXPECT_EQ(a->counters().tx_failures, 1u);

  for (auto* endpoint : {a.get(), b.get()}) {
    RecordingHandler handler;
    endpoint->drain(handler);
    EXPECT_TRUE(handler.frames.empty());
    ASSERT_EQ(handler.events.size(), 1u);
    EXPECT_EQ(handler.events[0].kind, BusEventKind::StateChanged);
    EXPECT_EQ(handler.events[0].previous, BusState::Up);
    EXPECT_EQ(handler.events[0].state, BusState::Down);
  }

  network_.set_state(BusState::Up);
  ASSERT_TRUE(a->send(pmu_frame(PacketId::Reset, 1), milliseconds{0}).ok());
  RecordingHandler handler;
  b->drain(handler);
  ASSERT_EQ(handler.events.size(), 1u);
  EXPECT_EQ(handler.events[0].state, BusState::Up);
  ASSERT_EQ(handler.frames.size(), 1u) << "the frame follows the Up event, in order";
}

TEST_F(Sim, BusOffRefusesSendsWhileErrorPassiveOnlyReports) {
  auto a = network_.attach("a");
  auto b = network_.attach("b");
  network_.set_state(BusState::ErrorPassive);
  EXPECT_TRUE(a->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0}).ok());
  network_.set_state(BusState::BusOff);
  EXPECT_EQ(a->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0}).status, SendStatus::BusOff);

  RecordingHandler handler;
  b->drain(handler);
  EXPECT_EQ(handler.frames.size(), 1u);
  ASSERT_EQ(handler.events.size(), 2u);
  EXPECT_EQ(handler.events[0].state, BusState::ErrorPassive);
  EXPECT_EQ(handler.events[1].state, BusState::BusOff);
}

TEST_F(Sim, DropNextLosesFramesSilently) {
  auto a = network_.attach("a");
  auto b = network_.attach("b");
  network_.drop_next(2);
  for (std::uint16_t address = 1; address <= 3; ++address)
    EXPECT_TRUE(a->send(pmu_frame(PacketId::Voltages, address), milliseconds{0}).ok());
  RecordingHandler handler;
  b->drain(handler);
  ASSERT_EQ(handler.frames.size(), 1u);
  EXPECT_EQ(handler.frames[0].frame.id, codec::make_id(PacketId::Voltages, 3));
  EXPECT_EQ(a->counters().tx_frames, 3u);
}

TEST_F(Sim, AFullEndpointQueueDropsAndCounts) {
  auto a = network_.attach("a");
  SimBusOptions small;
  small.queue_limit = 3;
  auto b = network_.attach("b", small);
  for (std::uint16_t address = 1; address <= 5; ++address)
    a->send(pmu_frame(PacketId::Voltages, address), milliseconds{0});
  RecordingHandler handler;
  b->drain(handler);
  EXPECT_EQ(handler.frames.size(), 3u);
  EXPECT_EQ(b->counters().rx_drops, 2u);
  // Room again after a drain.
  a->send(pmu_frame(PacketId::Voltages, 6), milliseconds{0});
  EXPECT_EQ(b->drain(handler).frames, 1u);
}

TEST_F(Sim, EndpointFiltersApply) {
  auto a = network_.attach("a");
  SimBusOptions pmu_only;
  pmu_only.filters = default_filters(false);
  auto b = network_.attach("b", pmu_only);
  codec::CanFrame battery;
  battery.id = 0x202;
  a->send(battery, milliseconds{0});
  a->send(pmu_frame(PacketId::Status, 1), milliseconds{0});
  RecordingHandler handler;
  b->drain(handler);
  ASSERT_EQ(handler.frames.size(), 1u);
  EXPECT_EQ(handler.frames[0].frame.id, codec::make_id(PacketId::Status, 1));
  EXPECT_EQ(b->counters().rx_filtered, 1u);
}

TEST_F(Sim, DestroyedEndpointsLeaveTheNetwork) {
  auto a = network_.attach("a");
  {
    auto b = network_.attach("b");
    EXPECT_EQ(network_.endpoint_count(), 2u);
  }
  EXPECT_EQ(network_.endpoint_count(), 1u);
  EXPECT_TRUE(a->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0}).ok());
}

TEST_F(Sim, InvalidFramesAreRefused) {
  auto a = network_.attach("a");
  auto b = network_.attach("b");
  codec::CanFrame bad;
  bad.id = 0x800;
  EXPECT_EQ(a->send(bad, milliseconds{0}).status, SendStatus::InvalidFrame);
  EXPECT_FALSE(readable(b->fd()));
}

// A device on one thread answering from inside its drain() handler, the service on another
// waiting in its event loop: the shape pmu-sim and the integration tests use.
TEST(SimThreads, EchoAcrossThreadsThroughEventLoops) {
  SystemClock clock;
  SimulatedNetwork network{clock};
  auto service = network.attach("service");
  auto device = network.attach("device");
  constexpr int kFrames = 200;

  struct Echo final : BusHandler {
    CanBus* bus = nullptr;
    void on_frame(const ReceivedFrame& f) override { bus->send(f.frame, milliseconds{0}); }
    void on_event(const BusEvent&) override {}
  };
  Echo echo;
  echo.bus = device.get();
  EventLoop device_loop{clock, "device"};
  ASSERT_EQ(device_loop.watch(device->fd(), EventLoop::kReadable, [&](std::uint32_t) { device->drain(echo); }), 0);
  RecordingHandler replies;
  EventLoop service_loop{clock, "service"};
  ASSERT_EQ(service_loop.watch(service->fd(), EventLoop::kReadable, [&](std::uint32_t) { service->drain(replies); }),
            0);
  std::thread device_thread([&] { device_loop.run(); });

  for (int i = 0; i < kFrames; ++i)
    service->send(pmu_frame(PacketId::Voltages, static_cast<std::uint16_t>(i)), milliseconds{0});

  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds{10};
  while (replies.frames.size() < kFrames && std::chrono::steady_clock::now() < give_up)
    service_loop.run_once(milliseconds{100});
  device_loop.stop();
  device_thread.join();

  ASSERT_EQ(replies.frames.size(), static_cast<std::size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i)
    EXPECT_EQ(replies.frames[static_cast<std::size_t>(i)].frame.id,
              codec::make_id(PacketId::Voltages, static_cast<std::uint16_t>(i)));
  EXPECT_EQ(device->counters().tx_frames, static_cast<std::uint64_t>(kFrames));
}

}  // namespace
}  // namespace pmu::transport::test
