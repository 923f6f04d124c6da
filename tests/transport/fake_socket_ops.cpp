#include "fake_socket_ops.hpp"

#include <linux/can/raw.h>
#include <sys/socket.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace pmu::transport::test {

int FakeSocketOps::open_can_raw() {
  ++opens;
  if (!can_supported) return -EAFNOSUPPORT;
  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, ends) != 0) return -errno;
  peers.emplace_back(ends[1]);
  return ends[0];
}

int FakeSocketOps::set_option(int fd, int level, int name, const void* value, socklen_t size) {
  if (level == SOL_CAN_RAW) {
    if (name == CAN_RAW_FILTER) {
      kernel_filters.resize(size / sizeof(struct can_filter));
      std::memcpy(kernel_filters.data(), value, kernel_filters.size() * sizeof(struct can_filter));
    } else if (name == CAN_RAW_ERR_FILTER) {
      std::memcpy(&error_mask, value, sizeof(error_mask));
    }
    return 0;
  }
  if (level == SOL_SOCKET) {
    socket_options.push_back(name);
    if (name == SO_RCVBUFFORCE && !allow_receive_buffer_force) return -EPERM;
  }
  return real_.set_option(fd, level, name, value, size);
}

int FakeSocketOps::get_option(int fd, int level, int name, void* value, socklen_t* size) {
  return real_.get_option(fd, level, name, value, size);
}

int FakeSocketOps::interface_index(const std::string& name) {
  const auto found = interfaces.find(name);
  return found == interfaces.end() ? -ENODEV : found->second;
}

int FakeSocketOps::interface_up(int /*fd*/, const std::string& name) {
  if (interfaces.count(name) == 0) return -ENODEV;
  return link_up ? 1 : 0;
}

int FakeSocketOps::bind_can(int /*fd*/, int ifindex) {
  bound_ifindex = ifindex;
  return 0;
}

int FakeSocketOps::receive(int fd, struct mmsghdr* messages, unsigned int count) {
  if (!receive_errors.empty()) {
    const int error = receive_errors.front();
    receive_errors.pop_front();
    return -error;
  }
  const std::size_t capacity = count > 0 ? messages[0].msg_hdr.msg_controllen : 0;
  const int received = real_.receive(fd, messages, count);
  if (received <= 0 || !next_drop_total) return received;

  // Append the control message after whatever the kernel wrote, as the kernel would.
  struct msghdr& header = messages[0].msg_hdr;
  const std::size_t used = CMSG_ALIGN(header.msg_controllen);
  if (used + CMSG_SPACE(sizeof(std::uint32_t)) > capacity) return -EMSGSIZE;
  unsigned char* base = static_cast<unsigned char*>(header.msg_control) + used;
  struct cmsghdr control {};
  control.cmsg_len = CMSG_LEN(sizeof(std::uint32_t));
  control.cmsg_level = SOL_SOCKET;
  control.cmsg_type = SO_RXQ_OVFL;
  std::memcpy(base, &control, sizeof(control));
  std::memcpy(base + CMSG_LEN(0), &*next_drop_total, sizeof(std::uint32_t));
  header.msg_controllen = used + CMSG_SPACE(sizeof(std::uint32_t));
  next_drop_total.reset();
  return received;
}

ssize_t FakeSocketOps::send(int fd, const void* data, size_t size) {
  if (send_error_forever != 0) return -send_error_forever;
  if (!send_errors.empty()) {
    const int error = send_errors.front();
    send_errors.pop_front();
    return -error;
  }
  return real_.send(fd, data, size);
}

int FakeSocketOps::poll(struct pollfd* fds, nfds_t count, int timeout_ms) {
  poll_timeouts.push_back(timeout_ms);
  if (clock_ == nullptr) return real_.poll(fds, count, timeout_ms);
  if (count > 0 && !poll_results.empty()) {
    const int ready = poll_results.front();
    poll_results.pop_front();
    for (nfds_t i = 0; i < count; ++i) fds[i].revents = fds[i].events;
    return ready;
  }
  clock_->advance(std::chrono::milliseconds{timeout_ms});
  return 0;
}

}  // namespace pmu::transport::test
