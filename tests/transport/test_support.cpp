#include "test_support.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace pmu::transport::test {

SocketPair make_socket_pair() {
  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, ends) != 0)
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
  SocketPair pair{UniqueFd{ends[0]}, UniqueFd{ends[1]}};
  const int bytes = 8 << 20;
  // FORCE needs CAP_NET_ADMIN; plain SO_SNDBUF is capped by wmem_max (4 MiB here), which
  // still holds several thousand small records.
  if (::setsockopt(pair.test_end.get(), SOL_SOCKET, SO_SNDBUFFORCE, &bytes, sizeof(bytes)) != 0)
    ::setsockopt(pair.test_end.get(), SOL_SOCKET, SO_SNDBUF, &bytes, sizeof(bytes));
  return pair;
}

namespace {
struct can_frame with_data(canid_t id, const std::vector<std::uint8_t>& data) {
  struct can_frame raw {};
  raw.can_id = id;
  raw.len = static_cast<__u8>(std::min<std::size_t>(data.size(), CAN_MAX_DLEN));
  std::copy_n(data.begin(), raw.len, raw.data);
  return raw;
}
}  // namespace

codec::CanFrame pmu_frame(codec::PacketId packet, std::uint16_t address, std::vector<std::uint8_t> data) {
  codec::CanFrame frame;
  frame.id = codec::make_id(packet, address);
  frame.extended = true;
  frame.length = static_cast<std::uint8_t>(std::min<std::size_t>(data.size(), codec::kMaxDataLength));
  std::copy_n(data.begin(), frame.length, frame.data.begin());
  return frame;
}

struct can_frame pmu_raw(codec::PacketId packet, std::uint16_t address, std::vector<std::uint8_t> data) {
  return with_data(codec::make_id(packet, address) | CAN_EFF_FLAG, data);
}

struct can_frame standard_raw(canid_t id, std::vector<std::uint8_t> data) {
  return with_data(id, data);
}

struct can_frame error_raw(canid_t error_class, std::uint8_t controller_status) {
  struct can_frame raw {};
  raw.can_id = CAN_ERR_FLAG | error_class;
  raw.len = CAN_ERR_DLC;
  raw.data[1] = controller_status;
  return raw;
}

void write_record(int fd, const void* data, std::size_t size) {
  const ssize_t written = ::send(fd, data, size, MSG_DONTWAIT | MSG_NOSIGNAL);
  if (written != static_cast<ssize_t>(size))
    throw std::runtime_error(std::string("write_record: ") + std::strerror(errno));
}

std::optional<struct can_frame> read_frame(int fd) {
  struct can_frame raw {};
  const ssize_t got = ::recv(fd, &raw, sizeof(raw), MSG_DONTWAIT);
  if (got != static_cast<ssize_t>(sizeof(raw))) return std::nullopt;
  return raw;
}

bool readable(int fd) {
  struct pollfd p {
    fd, POLLIN, 0
  };
  return ::poll(&p, 1, 0) == 1 && (p.revents & POLLIN) != 0;
}

std::optional<std::string> socket_options_missing() {
  const SocketPair pair = make_socket_pair();
  const int on = 1;
  for (const auto& [option, name] :
       {std::pair{SO_TIMESTAMPNS, "SO_TIMESTAMPNS"}, std::pair{SO_RXQ_OVFL, "SO_RXQ_OVFL"}}) {
    if (::setsockopt(pair.bus_end.get(), SOL_SOCKET, option, &on, sizeof(on)) != 0)
      return std::string("setsockopt(") + name + "): " + std::strerror(errno) +
             " (qemu-user does not translate it; the native builds run this test)";
  }
  return std::nullopt;
}

}  // namespace pmu::transport::test
