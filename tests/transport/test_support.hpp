#pragma once
// Helpers shared by the transport tests: socketpairs standing in for CAN sockets, raw
// struct can_frame records, and a handler that records what drain() delivers.

#include <linux/can.h>
#include <linux/can/error.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pmu/codec/ids.hpp"
#include "pmu/transport/can_bus.hpp"
#include "pmu/transport/unique_fd.hpp"

namespace pmu::transport::test {

struct RecordingHandler final : BusHandler {
  std::vector<ReceivedFrame> frames;
  std::vector<BusEvent> events;
  void on_frame(const ReceivedFrame& frame) override { frames.push_back(frame); }
  void on_event(const BusEvent& event) override { events.push_back(event); }

  std::vector<BusEventKind> kinds() const {
    std::vector<BusEventKind> out;
    for (const auto& e : events) out.push_back(e.kind);
    return out;
  }
  void clear() {
    frames.clear();
    events.clear();
  }
};

struct SocketPair {
  UniqueFd bus_end;   // handed to SocketCanBus::adopt
  UniqueFd test_end;  // the test writes "received" frames here and reads what was sent
};

// SOCK_SEQPACKET keeps record boundaries as CAN_RAW does. The test end's send buffer is
// raised so that a few thousand frames can wait unread (the default holds ~280).
SocketPair make_socket_pair();

// A PMU frame as the codec sees it.
codec::CanFrame pmu_frame(codec::PacketId packet, std::uint16_t address, std::vector<std::uint8_t> data = {});

// A PMU frame as the kernel would deliver it: extended id, flag set.
struct can_frame pmu_raw(codec::PacketId packet, std::uint16_t address, std::vector<std::uint8_t> data = {});
struct can_frame standard_raw(canid_t id, std::vector<std::uint8_t> data = {});
// A controller error frame: CAN_ERR_FLAG | error_class, data[1] = controller status.
struct can_frame error_raw(canid_t error_class, std::uint8_t controller_status = 0);

void write_record(int fd, const void* data, std::size_t size);
inline void write_frame(int fd, const struct can_frame& frame) { write_record(fd, &frame, sizeof(frame)); }
// The next record on `fd`, or nullopt when none is waiting.
std::optional<struct can_frame> read_frame(int fd);

// Whether `fd` is readable right now (poll with timeout 0).
bool readable(int fd);

// Why SO_TIMESTAMPNS and SO_RXQ_OVFL cannot be enabled on a socket here, or nullopt when
// they can. A Linux kernel accepts both on any socket; qemu-user, under which the arm64
// package build runs these tests, does not translate them (ENOPROTOOPT), so the tests of
// the code that requires them skip there and run in the native builds.
std::optional<std::string> socket_options_missing();

}  // namespace pmu::transport::test
