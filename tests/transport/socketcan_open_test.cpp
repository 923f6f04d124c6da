// SocketCanBus::open: the AF_CAN path. FakeSocketOps stands a socketpair in for the CAN_RAW
// socket, so set-up, ENODEV and reopen are tested on this kernel, which has no CAN. The
// tests that need real SocketCAN skip here and run in the system-test VM.

#include <gtest/gtest.h>
#include <linux/can/raw.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
#include <system_error>

#include "fake_socket_ops.hpp"
#include "pmu/transport/socketcan_bus.hpp"
#include "test_support.hpp"

namespace pmu::transport::test {
namespace {

using codec::PacketId;
using std::chrono::milliseconds;

// Whether this kernel can make a CAN_RAW socket at all.
bool kernel_has_can() {
  UniqueFd probe{::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW)};
  return static_cast<bool>(probe);
}

class OpenedBus : public ::testing::Test {
 protected:
  OpenedBus() { fake_.interfaces["can0"] = 7; }
  // open() enables the receive timestamps and drop counting on the fake's real socket.
  void SetUp() override {
    if (const auto why = socket_options_missing()) GTEST_SKIP() << *why;
  }
  std::unique_ptr<SocketCanBus> open(SocketCanOptions options = {}) {
    return SocketCanBus::open("can0", options, clock_, fake_);
  }
  // The test's end of the socket the bus holds now.
  int peer() const { return fake_.peers.back().get(); }

  ManualClock clock_;
  FakeSocketOps fake_{&clock_};
  RecordingHandler handler_;
};

TEST_F(OpenedBus, InstallsFiltersErrorMaskAndBindsToTheInterface) {
  auto bus = open();
  ASSERT_EQ(fake_.kernel_filters.size(), 1u);
  // The PMU's group in bits 28..24 of an extended id; CAN_EFF_FLAG in both so 11-bit
  // frames never match.
  EXPECT_EQ(fake_.kernel_filters[0].can_id, 0x1E000000u | CAN_EFF_FLAG);
  EXPECT_EQ(fake_.kernel_filters[0].can_mask, 0x1F000000u | CAN_EFF_FLAG);
  EXPECT_EQ(fake_.error_mask,
            static_cast<can_err_mask_t>(CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED | CAN_ERR_TX_TIMEOUT));
  EXPECT_EQ(fake_.bound_ifindex, 7);
  const SocketCanReport& report = bus->report();
  EXPECT_TRUE(report.kernel_filters);
  EXPECT_TRUE(report.kernel_timestamps);
  EXPECT_TRUE(report.drop_counting);
  EXPECT_TRUE(report.receive_buffer_forced);
  EXPECT_GE(report.receive_buffer_bytes, 1 << 20);
  EXPECT_EQ(bus->state(), BusState::Up);
  EXPECT_EQ(bus->name(), "can0");
}

TEST_F(OpenedBus, CanopenFiltersAreInstalledWhenAskedFor) {
  SocketCanOptions options;
  options.filters = default_filters(true);
  auto bus = open(options);
  ASSERT_EQ(fake_.kernel_filters.size(), 9u);
  EXPECT_EQ(fake_.kernel_filters[1].can_id, 0x202u);
  EXPECT_EQ(fake_.kernel_filters[1].can_mask, 0x7FFu | CAN_EFF_FLAG);
}

TEST_F(OpenedBus, ReceiveBufferFallsBackWhenForcingIsNotPermitted) {
  fake_.allow_receive_buffer_force = false;
  auto bus = open();
  EXPECT_FALSE(bus->report().receive_buffer_forced);
  const auto& options = fake_.socket_options;
  const auto forced = std::find(options.begin(), options.end(), SO_RCVBUFFORCE);
  ASSERT_NE(forced, options.end());
  EXPECT_NE(std::find(forced, options.end(), SO_RCVBUF), options.end())
      << "SO_RCVBUF must follow a refused SO_RCVBUFFORCE";
  EXPECT_GT(bus->report().receive_buffer_bytes, 0) << "what was obtained is reported";
}

// The unit needs no device ordering and another interface is a config change only: a bus
// whose interface is not there yet starts DOWN and binds by name when it appears.
TEST_F(OpenedBus, MissingInterfaceStartsDownAndBindsWhenItAppears) {
  auto bus = SocketCanBus::open("can9", {}, clock_, fake_);
  ASSERT_NE(bus, nullptr);
  EXPECT_EQ(bus->state(), BusState::Down);
  EXPECT_FALSE(bus->has_socket());
  EXPECT_EQ(bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{10}).status, SendStatus::NoDevice);
  EXPECT_TRUE(fake_.poll_timeouts.empty()) << "a missing device is not waited for";
  const int loop_fd = bus->fd();

  const auto t0 = clock_.steady_now();
  const int opens_before = fake_.opens;
  bus->maintain(t0);
  EXPECT_EQ(fake_.opens, opens_before + 1) << "the first maintain() tries at once";
  EXPECT_FALSE(bus->has_socket());
  bus->drain(handler_);
  EXPECT_TRUE(handler_.events.empty()) << "absence is the expected answer, not an error event";

  fake_.interfaces["can9"] = 4;  // the controller was probed, or the vcan made
  bus->maintain(t0 + milliseconds{1000});
  ASSERT_TRUE(bus->has_socket());
  EXPECT_EQ(fake_.bound_ifindex, 4);
  EXPECT_EQ(bus->fd(), loop_fd);
  EXPECT_EQ(bus->state(), BusState::Up);
  write_frame(peer(), pmu_raw(PacketId::Currents, 4));
  ASSERT_TRUE(readable(bus->fd()));
  bus->drain(handler_);
  ASSERT_EQ(handler_.kinds(), (std::vector<BusEventKind>{BusEventKind::Reopened, BusEventKind::StateChanged}));
  EXPECT_EQ(handler_.events[1].previous, BusState::Down);
  EXPECT_EQ(handler_.events[1].state, BusState::Up);
  ASSERT_EQ(handler_.frames.size(), 1u);
  EXPECT_EQ(handler_.frames[0].frame.id, codec::make_id(PacketId::Currents, 4));
}

TEST_F(OpenedBus, KernelWithoutCanIsAStartupErrorNamingTheInterface) {
  fake_.can_supported = false;
  try {
    open();
    FAIL() << "expected std::system_error";
  } catch (const std::system_error& e) {
    EXPECT_EQ(e.code().value(), EAFNOSUPPORT);
    EXPECT_EQ(std::string(e.what()),
              std::string("can0: socket(PF_CAN, SOCK_RAW, CAN_RAW): ") + std::strerror(EAFNOSUPPORT));
  }
}

TEST_F(OpenedBus, OverlongInterfaceNameIsRefused) {
  EXPECT_THROW(SocketCanBus::open("a-name-longer-than-ifnamsiz", {}, clock_, fake_), std::system_error);
  EXPECT_EQ(fake_.opens, 0);
}

TEST_F(OpenedBus, AdministrativelyDownInterfaceIsReportedDownAtOnce) {
  fake_.link_up = false;
  auto bus = open();
  EXPECT_EQ(bus->state(), BusState::Down);
}

TEST_F(OpenedBus, EnodevClosesTheSocketAndMaintainReopensWhenTheInterfaceReturns) {
  auto bus = open();
  const int loop_fd = bus->fd();
  const int first_peer = peer();

  fake_.receive_errors.push_back(ENODEV);
  fake_.interfaces.erase("can0");  // the USB adapter was unplugged
  write_frame(first_peer, pmu_raw(PacketId::Voltages, 1));
  bus->drain(handler_);
  EXPECT_EQ(bus->state(), BusState::Down);
  EXPECT_FALSE(bus->has_socket());
  ASSERT_EQ(handler_.kinds(), (std::vector<BusEventKind>{BusEventKind::SocketError, BusEventKind::StateChanged}));
  EXPECT_EQ(handler_.events[0].error, ENODEV);
  EXPECT_EQ(bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{10}).status, SendStatus::NoDevice);
  EXPECT_TRUE(fake_.poll_timeouts.empty()) << "a missing device is not waited for";

  // Still absent: one attempt now, then none until reopen_interval (1 s) has passed.
  const auto t0 = clock_.steady_now();
  const int opens_before = fake_.opens;
  bus->maintain(t0);
  EXPECT_EQ(fake_.opens, opens_before + 1);
  EXPECT_FALSE(bus->has_socket());
  fake_.interfaces["can0"] = 9;  // back, with a new index
  bus->maintain(t0 + milliseconds{999});
  EXPECT_EQ(fake_.opens, opens_before + 1) << "attempts are spaced by reopen_interval";
  EXPECT_FALSE(bus->has_socket());

  bus->maintain(t0 + milliseconds{1000});
  ASSERT_TRUE(bus->has_socket());
  EXPECT_EQ(fake_.bound_ifindex, 9) << "rebound by name, not by the old index";
  EXPECT_EQ(bus->counters().reopens, 1u);
  EXPECT_EQ(bus->fd(), loop_fd) << "the loop's registration must survive a reopen";
  EXPECT_EQ(bus->state(), BusState::Up);

  handler_.clear();
  write_frame(peer(), pmu_raw(PacketId::Currents, 4));
  ASSERT_TRUE(readable(bus->fd()));
  bus->drain(handler_);
  ASSERT_EQ(handler_.kinds(), (std::vector<BusEventKind>{BusEventKind::Reopened, BusEventKind::StateChanged}));
  EXPECT_EQ(handler_.events[1].state, BusState::Up);
  ASSERT_EQ(handler_.frames.size(), 1u);
  EXPECT_EQ(handler_.frames[0].frame.id, codec::make_id(PacketId::Currents, 4));
}

TEST_F(OpenedBus, EnodevOnSendAlsoLeadsToReopen) {
  auto bus = open();
  fake_.send_errors.push_back(ENODEV);
  EXPECT_EQ(bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0}).status, SendStatus::NoDevice);
  EXPECT_FALSE(bus->has_socket());
  bus->maintain(clock_.steady_now());
  EXPECT_TRUE(bus->has_socket());
  EXPECT_TRUE(bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0}).ok());
  EXPECT_TRUE(read_frame(peer()).has_value());
}

TEST_F(OpenedBus, ReopenFailuresOtherThanAbsenceAreReportedOnce) {
  auto bus = open();
  fake_.send_errors.push_back(ENODEV);
  bus->send(pmu_frame(PacketId::Voltages, 1), milliseconds{0});
  fake_.can_supported = false;  // e.g. the can module was unloaded
  auto now = clock_.steady_now();
  for (int i = 0; i < 3; ++i, now += std::chrono::seconds{1}) bus->maintain(now);
  bus->drain(handler_);
  std::size_t socket_errors = 0;
  for (const auto& e : handler_.events)
    if (e.kind == BusEventKind::SocketError && e.error == EAFNOSUPPORT) ++socket_errors;
  EXPECT_EQ(socket_errors, 1u);
  EXPECT_FALSE(bus->has_socket());
}

TEST_F(OpenedBus, LinkComingBackUpAfterEnetdownIsNoticedByMaintain) {
  auto bus = open();
  fake_.receive_errors.push_back(ENETDOWN);
  write_frame(peer(), error_raw(CAN_ERR_CRTL, 0));  // anything to wake the loop
  bus->drain(handler_);
  ASSERT_EQ(bus->state(), BusState::Down);

  fake_.link_up = false;
  bus->maintain(clock_.steady_now());
  EXPECT_EQ(bus->state(), BusState::Down);
  fake_.link_up = true;  // `ip link set can0 up`, and the PMU happens to be silent
  bus->maintain(clock_.steady_now());
  EXPECT_EQ(bus->state(), BusState::Up);
  EXPECT_EQ(bus->counters().reopens, 0u) << "ENETDOWN never closes the socket";

  handler_.clear();
  bus->drain(handler_);
  // maintain()'s news comes first: it was raised before drain() read the socket.
  ASSERT_FALSE(handler_.events.empty());
  EXPECT_EQ(handler_.events[0].kind, BusEventKind::StateChanged);
  EXPECT_EQ(handler_.events[0].previous, BusState::Down);
  EXPECT_EQ(handler_.events[0].state, BusState::Up);
}

// --- the real kernel ---

TEST(RealSocketCan, MissingInterfaceIsDownOrAClearStartupError) {
  ManualClock clock;
  if (kernel_has_can()) {
    // With CAN, the made-up interface does not exist: the bus waits for it, DOWN.
    auto bus = SocketCanBus::open("pmunosuch0", {}, clock);
    EXPECT_EQ(bus->state(), BusState::Down);
    EXPECT_FALSE(bus->has_socket());
    return;
  }
  try {
    SocketCanBus::open("pmunosuch0", {}, clock);
    FAIL() << "expected std::system_error";
  } catch (const std::system_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("pmunosuch0"), std::string::npos) << what;
    EXPECT_EQ(e.code().value(), EAFNOSUPPORT) << what;
    EXPECT_NE(what.find(std::strerror(EAFNOSUPPORT)), std::string::npos) << what;
  }
}

TEST(RealSocketCan, FramesCrossAVirtualCanInterface) {
  if (!kernel_has_can())
    GTEST_SKIP() << "this kernel has no CAN support (socket(PF_CAN) fails); "
                    "runs in the system-test VM";
  SystemClock clock;
  std::unique_ptr<SocketCanBus> sender;
  std::unique_ptr<SocketCanBus> receiver;
  try {
    sender = SocketCanBus::open("vcan0", {}, clock);
    receiver = SocketCanBus::open("vcan0", {}, clock);
  } catch (const std::system_error& e) {
    GTEST_SKIP() << "needs a vcan0 interface that is up (" << e.what() << ")";
  }
  EXPECT_TRUE(receiver->report().kernel_filters);
  EXPECT_GE(receiver->report().receive_buffer_bytes, 1 << 20);
  codec::CanFrame foreign;
  foreign.id = 0x1F000001;
  foreign.extended = true;
  ASSERT_TRUE(sender->send(foreign, milliseconds{100}).ok());
  ASSERT_TRUE(sender->send(pmu_frame(PacketId::Voltages, 1), milliseconds{100}).ok());

  struct pollfd ready {
    receiver->fd(), POLLIN, 0
  };
  ASSERT_EQ(::poll(&ready, 1, 1000), 1);
  RecordingHandler handler;
  receiver->drain(handler);
  ASSERT_EQ(handler.frames.size(), 1u) << "the kernel filter keeps group 0x1F out";
  EXPECT_EQ(handler.frames[0].frame, pmu_frame(PacketId::Voltages, 1));
  EXPECT_TRUE(handler.frames[0].kernel_timestamp);
  EXPECT_EQ(receiver->counters().rx_filtered, 0u) << "filtered in the kernel, not here";
}

}  // namespace
}  // namespace pmu::transport::test
